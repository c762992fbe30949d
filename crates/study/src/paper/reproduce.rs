//! One run of the paper reproduction (`tofprobe reproduce`): the shared ΣΔ probe ROM
//! generated once and passed to every Table 2 row, then every family's rows and the plots.

use std::path::Path;
use std::time::Instant;

use super::sigma_delta::ProbeSetup;
use super::{Row, bandwidth, fig4, plots, table2, transients};
use crate::StudyError;

/// The rows, plots and timings of one run.
#[derive(Debug, Clone)]
pub struct Reproduction {
    /// Every row, in table order.
    pub rows: Vec<Row>,
    /// The plot files written.
    pub plots: Vec<String>,
    /// Pulses of the Table 2 records.
    pub table2_pulses: u64,
    /// Generating the shared ΣΔ probe ROM (design sweep included), s.
    pub rom_seconds: f64,
    /// All Table 2 rows (every column, every seed), s.
    pub table2_seconds: f64,
}

/// Runs the reproduction (`quick`: short records) and writes the plots into `out`.
pub fn reproduce(quick: bool, out: &Path) -> Result<Reproduction, StudyError> {
    let (n_t2, n_f4, n_bw) = if quick {
        (1 << 20, 1 << 17, 1 << 21)
    } else {
        (10_000_000, fig4::N, bandwidth::N)
    };
    let t_rom = Instant::now();
    // Generated once here; every row's ΣΔ columns read it.
    let probe = ProbeSetup::new(n_t2)?;
    let rom_seconds = t_rom.elapsed().as_secs_f64();
    let t_rows = Instant::now();
    let results = table2::run_all(&probe)?;
    let table2_seconds = t_rows.elapsed().as_secs_f64();
    drop(probe);
    let mut rows: Vec<Row> = results
        .iter()
        .flat_map(|r| table2::rows_of(r, quick))
        .collect();
    rows.extend(table2::eq12_row(&results, n_t2, quick));
    rows.extend(fig4::rows(n_f4)?);
    rows.extend(bandwidth::rows(n_bw)?);
    let figs = transients::figures()?;
    rows.extend(transients::rows(&figs));
    let mut plots = plots::write_all(out, &results)?;
    plots.extend(transients::write_svgs(out, &figs)?);
    Ok(Reproduction {
        rows,
        plots,
        table2_pulses: n_t2,
        rom_seconds,
        table2_seconds,
    })
}
