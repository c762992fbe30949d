//! `tofprobe bench pixel`: speed of the bit-true pixel at the configuration's `[pixel]`
//! (`tofprobe_bench::pixel` measures; this prints).

use std::path::PathBuf;

use clap::Args;
use tofprobe_bench::pixel::PixelReport;

use crate::error::CliError;

/// Arguments of `tofprobe bench pixel`.
#[derive(Debug, Args)]
pub struct PixelBenchArgs {
    /// Configuration whose `[pixel]` and sensor are used (default: the embedded default).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Pulses in the transaction-model frame.
    #[arg(long, default_value_t = 10_000_000)]
    pulses: u64,
    /// Pulses through the cycle model (one frame under the reference sequencer).
    #[arg(long, default_value_t = 200_000)]
    cycle_pulses: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the benchmark.
pub fn run(args: &PixelBenchArgs) -> Result<(), CliError> {
    let design = tofprobe_design::load(args.config.as_deref())?;
    design.single_pixel("bench pixel")?;
    let report = tofprobe_bench::pixel::measure(&design, args.pulses, args.cycle_pulses)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_text(r: &PixelReport) {
    println!(
        "bit-true pixel, B = {} ({} registers, W = {} bits), one thread",
        r.bins, r.registers, r.width_bits
    );
    println!(
        "transaction model  {} pulses in {:.4} s = {:.1} M pulses/s, {:.1}x real time (target <= {:.3} s)",
        r.pulses,
        r.transaction_seconds,
        r.transaction_pulses_per_s / 1e6,
        r.realtime_factor,
        r.target_seconds
    );
    if let (Some(cpu), Some(f)) = (r.transaction_cpu_seconds, r.cpu_realtime_factor) {
        println!(
            "  on its core      {cpu:.4} s of CPU time ({f:.1}x real time; wall time includes waiting for a shared core)"
        );
    }
    println!(
        "  pulse by pulse   {:.4} s (the per-pulse reference path)",
        r.pulse_by_pulse_seconds
    );
    println!(
        "folded driver      {:.4} s = {:.1} M pulses/s, {:.1}x real time{}; {:.2}x the transaction driver (L = {}, {})",
        r.fold_seconds,
        r.fold_pulses_per_s / 1e6,
        r.fold_realtime_factor,
        r.fold_cpu_realtime_factor
            .map(|f| format!(" ({f:.1}x on CPU time)"))
            .unwrap_or_default(),
        r.fold_speedup_vs_transaction,
        r.rom_depth,
        if r.fold_chosen {
            "chosen for this frame"
        } else {
            "not chosen: the transaction driver runs"
        }
    );
    println!(
        "cycle model        {} cycles in {:.4} s = {:.1} M cycles/s ({:.3}x real time at {} cycles/pulse)",
        r.cycle_cycles,
        r.cycle_seconds,
        r.cycle_cycles_per_s / 1e6,
        r.cycle_realtime_factor,
        r.cycles_per_pulse
    );
    println!("pass               {}", r.pass);
}
