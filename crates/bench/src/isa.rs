//! The ISA rows of `bench pixel`, `scene` and `array`: every instruction-set path of the
//! vector kernels this CPU runs, measured side by side in one run (or the one `--isa` or
//! `TOFPROBE_ISA` names), each under `tofprobe_io::isa::with_isa`, each row naming its ISA
//! and judging the targets itself.

use serde::Serialize;
use tofprobe_io::isa::{Isa, to_measure, with_isa};

use crate::BenchError;

/// A benchmark's rows, one per ISA (narrowest first), and the widest one's figures at the
/// top level (the path this CPU runs by default; the keys of a one-ISA report).
#[derive(Debug, Clone, Serialize)]
pub struct IsaRows<R> {
    #[serde(flatten)]
    pub widest: R,
    pub isas: Vec<R>,
}

/// The ISAs to measure: `forced` (an `--isa` value) if given, else `TOFPROBE_ISA`'s, else
/// every one this CPU runs; refused (naming the option or the variable, the value and the
/// allowed names) if unknown or missing on this CPU.
pub fn isas_to_measure(forced: Option<&str>) -> Result<Vec<Isa>, BenchError> {
    let forced = forced.map(|v| Isa::parse(v, "--isa")).transpose()?;
    Ok(to_measure(forced)?)
}

/// Runs `measure` once per ISA under that ISA, in order.
pub fn rows<R: Clone>(
    isas: &[Isa],
    mut measure: impl FnMut(Isa) -> Result<R, BenchError>,
) -> Result<IsaRows<R>, BenchError> {
    let mut rows = Vec::with_capacity(isas.len());
    for &isa in isas {
        rows.push(with_isa(isa, || measure(isa))?);
    }
    let widest = rows.last().cloned().ok_or_else(|| {
        BenchError::option("isa", "none", "at least one ISA (this CPU runs \"scalar\")")
    })?;
    Ok(IsaRows { widest, isas: rows })
}
