//! One design point end to end: synthesise (cached), split the area, and time it with
//! OpenSTA when the liberty carries timing (cached next to the synthesis).

use crate::error::{EdaError, Result};
use crate::fsutil::cached_json;
use crate::liberty::Liberty;
use crate::split::{AreaSplit, BlockNames, split_area};
use crate::sta::{Timing, time_netlist};
use crate::synth::{SynthSpec, Synthesis, synthesise};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The pixel a size report (`crate::size_report`) and its corner options are about.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Design {
    /// Bins B (Fourier) — the sweep axis.
    pub bins: u64,
    /// Register width W (bits).
    pub width: u32,
    /// Registers R.
    pub registers: u64,
    /// Operations per pulse P.
    pub ops_per_pulse: u64,
    /// Adders A.
    pub adders: u64,
    /// Clock cycles per laser pulse C.
    pub cycles_per_pulse: u64,
    /// Laser pulse rate (Hz).
    pub laser_rate_hz: f64,
}

/// The Verilog of one pixel variant.
#[derive(Debug, Clone)]
pub struct RtlVariant {
    /// Sources to read.
    pub sources: Vec<PathBuf>,
    /// The pixel module (without the chip-level ROM).
    pub top: String,
    /// Verilog parameter overrides (empty for rendered RTL with literal sizes).
    pub params: Vec<(String, i64)>,
}

/// Something that can produce the pixel's Verilog for `bins` bins of `width`-bit registers:
/// rendered RTL (`tofprobe-rtlgen`) or a parameterised module.
pub trait RtlProvider: Sync {
    /// The RTL for (B, W); `dir` is a scratch directory the provider may write into.
    fn rtl(&self, bins: u64, width: u32, dir: &Path) -> Result<RtlVariant>;

    /// The same pixel with `adders` adders at `cycles_per_pulse` cycles per pulse, when this
    /// provider can vary them (`Ok(None)` otherwise, or when the contract refuses that
    /// schedule): the candidates of a missed corner (`crate::corner_option`).
    fn with_adders(
        &self,
        _adders: u64,
        _cycles_per_pulse: u64,
    ) -> Result<Option<Box<dyn RtlProvider>>> {
        Ok(None)
    }
}

/// A parameterised Verilog module: (B, W) are set with yosys `chparam`.
#[derive(Debug, Clone)]
pub struct ParamRtl {
    /// Sources.
    pub sources: Vec<PathBuf>,
    /// Top module.
    pub top: String,
    /// Name of the bins parameter.
    pub bins_param: String,
    /// Name of the width parameter.
    pub width_param: String,
}

impl RtlProvider for ParamRtl {
    fn rtl(&self, bins: u64, width: u32, _dir: &Path) -> Result<RtlVariant> {
        let b = i64::try_from(bins).map_err(|_| EdaError::OutOfRange {
            field: "bins",
            value: bins.to_string(),
            allowed: "< 2^63".into(),
        })?;
        Ok(RtlVariant {
            sources: self.sources.clone(),
            top: self.top.clone(),
            params: vec![
                (self.bins_param.clone(), b),
                (self.width_param.clone(), i64::from(width)),
            ],
        })
    }
}

/// Area, split and (optionally) timing of one (B, W) point on one liberty.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PointResult {
    /// Bins B.
    pub bins: u64,
    /// Register width W.
    pub width: u32,
    /// yosys figures.
    pub synthesis: Synthesis,
    /// Area split.
    pub split: AreaSplit,
    /// OpenSTA figures; None for a liberty without timing.
    pub timing: Option<Timing>,
}

/// Runs one point. `timing` asks for OpenSTA (only meaningful if `lib.has_timing`);
/// `delay_target_ps` is ABC's delay target (see [`SynthSpec::delay_target_ps`]).
#[allow(clippy::too_many_arguments)]
pub fn analyse_point(
    provider: &dyn RtlProvider,
    bins: u64,
    width: u32,
    lib: &Liberty,
    timing: bool,
    clock: &str,
    cache: &Path,
    delay_target_ps: Option<f64>,
) -> Result<PointResult> {
    let scratch = cache.join("rtl").join(format!("b{bins}_w{width}"));
    let variant = provider.rtl(bins, width, &scratch)?;
    let spec = SynthSpec {
        sources: variant.sources,
        top: variant.top.clone(),
        params: variant.params,
        liberty: lib.path.clone(),
        delay_target_ps,
        keep: vec![],
    };
    let synthesis = synthesise(&spec, &cache.join("synth"))?;
    // The split walks a multi-megabyte JSON netlist: cache it next to the synthesis
    // (the name rules are fixed per crate version and W, both in the file name).
    let split_path = synthesis
        .netlist_json
        .with_file_name(format!("split-v2-w{width}.json"));
    let split = cached_json(&split_path, || {
        split_area(
            &synthesis.netlist_json,
            &variant.top,
            lib,
            &BlockNames::contract(width),
        )
    })?;
    let timing = if timing && lib.has_timing {
        let dir = synthesis
            .netlist_json
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| cache.to_path_buf());
        let cached = dir.join("timing-v3.json");
        Some(cached_json(&cached, || {
            time_netlist(
                &lib.path,
                &synthesis.netlist_verilog,
                &variant.top,
                clock,
                &dir,
            )
        })?)
    } else {
        None
    };
    Ok(PointResult {
        bins,
        width,
        synthesis,
        split,
        timing,
    })
}

/// Runs several points on two worker threads (the machines this runs on have 2 cores).
/// Results come back in the order of `points`.
pub fn analyse_points(
    provider: &dyn RtlProvider,
    points: &[(u64, u32)],
    lib: &Liberty,
    timing: bool,
    clock: &str,
    cache: &Path,
    delay_target_ps: Option<f64>,
) -> Result<Vec<PointResult>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<Result<PointResult>>>> =
        points.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&(b, w)) = points.get(i) else { break };
                    let r =
                        analyse_point(provider, b, w, lib, timing, clock, cache, delay_target_ps);
                    if let Ok(mut slot) = results[i].lock() {
                        *slot = Some(r);
                    }
                }
            });
        }
    });
    results
        .into_iter()
        .map(|m| {
            m.into_inner().ok().flatten().unwrap_or_else(|| {
                Err(EdaError::ToolFailed {
                    tool: "yosys",
                    status: "worker thread panicked".into(),
                    log_tail: String::new(),
                })
            })
        })
        .collect()
}
