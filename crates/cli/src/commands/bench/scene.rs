//! `tofprobe bench scene`: single-thread throughput of the photon/TDC Monte Carlo on the
//! configuration's scene (`tofprobe_bench::scene` measures; this prints).

use std::path::PathBuf;

use clap::Args;
use tofprobe_bench::scene::{SceneReport, TARGET_MIXED, TARGET_SIGNAL_ONLY, TARGET_SPEEDUP};

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
    /// Instruction set of the vector kernels: scalar, avx2 or avx512 (default: every one
    /// this CPU runs, side by side, or the one TOFPROBE_ISA names).
    #[arg(long)]
    isa: Option<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the benchmark.
pub fn run(args: &SceneBenchArgs) -> Result<(), CliError> {
    let design = crate::commands::load_design(args.config.as_deref())?;
    design.single_pixel("bench scene")?;
    let isas = tofprobe_bench::isa::isas_to_measure(args.isa.as_deref())?;
    let report = tofprobe_bench::scene::measure_isas(&design.document, args.pulses, &isas)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        report.isas.iter().for_each(print_text);
    }
    Ok(())
}

fn print_text(r: &SceneReport) {
    println!(
        "scene Monte Carlo, one thread, {} pulses per case: batched kernel (ISA {}) beside the per-pulse reference",
        r.pulses, r.isa
    );
    let cpu = |c: Option<f64>| match c {
        Some(c) => format!("{:7.1} M/CPU-s", c / 1e6),
        None => "(no thread CPU time)".to_string(),
    };
    println!(
        "case                     batched (wall, CPU)             reference (wall, CPU)          ratio"
    );
    for (name, w, c, rw, rc, x, target) in [
        (
            "rho_s = 1.0, rho_b = 0.0",
            r.signal_only_pulses_per_s,
            r.signal_only_pulses_per_cpu_s,
            r.signal_only_reference_pulses_per_s,
            r.signal_only_reference_pulses_per_cpu_s,
            r.signal_only_speedup_vs_reference,
            TARGET_SIGNAL_ONLY,
        ),
        (
            "rho_s = 0.3, rho_b = 0.3",
            r.mixed_pulses_per_s,
            r.mixed_pulses_per_cpu_s,
            r.mixed_reference_pulses_per_s,
            r.mixed_reference_pulses_per_cpu_s,
            r.mixed_speedup_vs_reference,
            TARGET_MIXED,
        ),
    ] {
        println!(
            "{name}  {:7.1} M/s, {}   {:7.1} M/s, {}   {x:5.2}x (target {:.0} M/s, {TARGET_SPEEDUP}x)",
            w / 1e6,
            cpu(c),
            rw / 1e6,
            cpu(rc),
            target / 1e6
        );
    }
    println!("pass (absolute targets)  {}", r.pass);
    println!("speed-up >= {TARGET_SPEEDUP}x         {}", r.speedup_pass);
}
