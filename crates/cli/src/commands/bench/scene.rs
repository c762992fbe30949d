//! `tofprobe bench scene`: single-thread throughput of the photon/TDC Monte Carlo on the
//! configuration's scene (`tofprobe_bench::scene` measures; this prints).

use std::path::PathBuf;

use clap::Args;
use tofprobe_bench::scene::{SceneReport, TARGET_MIXED, TARGET_SIGNAL_ONLY};

use crate::error::CliError;

/// Arguments of `tofprobe bench scene`.
#[derive(Debug, Args)]
pub struct SceneBenchArgs {
    /// Configuration whose sensor and scene are timed (default: the embedded default).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Pulses per case.
    #[arg(long, default_value_t = 20_000_000)]
    pulses: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the benchmark.
pub fn run(args: &SceneBenchArgs) -> Result<(), CliError> {
    let design = crate::commands::load_design(args.config.as_deref())?;
    design.single_pixel("bench scene")?;
    let report = tofprobe_bench::scene::measure(&design.document, args.pulses)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_text(r: &SceneReport) {
    println!(
        "scene Monte Carlo, one thread, {} pulses per case",
        r.pulses
    );
    let cpu = |c: Option<f64>| match c {
        Some(c) => format!("{:8.1} M pulses/CPU-s", c / 1e6),
        None => "(no thread CPU time on this OS)".to_string(),
    };
    println!(
        "rho_s = 1.0, rho_b = 0.0   {:8.1} M pulses/s wall, {} (target {:.0})",
        r.signal_only_pulses_per_s / 1e6,
        cpu(r.signal_only_pulses_per_cpu_s),
        TARGET_SIGNAL_ONLY / 1e6
    );
    println!(
        "rho_s = 0.3, rho_b = 0.3   {:8.1} M pulses/s wall, {} (target {:.0})",
        r.mixed_pulses_per_s / 1e6,
        cpu(r.mixed_pulses_per_cpu_s),
        TARGET_MIXED / 1e6
    );
    println!("pass                       {}", r.pass);
}
