//! `tofprobe bench pixel`: speed of the bit-true pixel at the configuration's `[pixel]`
//! (default B = 16): the transaction model on one 10^7-pulse frame with a ROM read per
//! pulse (target: ≤ 0.1 s, i.e. ≥ 10× real time at 10 MHz), and the cycle model's clock
//! edges per second under the reference sequencer.
//!
//! `pass` compares the frame's CPU time on its thread (Linux; wall time elsewhere) with the
//! target: on a shared machine wall time also counts the time spent waiting for a core.
//! Both are printed.
//!
//! The ROM is synthetic (4096 entries of distinct square-wave sign patterns): the speed
//! does not depend on which bits it holds, only on reading one entry per pulse.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use tofprobe_pixel::bench::{bench_cycle, bench_transaction, synthetic_rom};

use crate::error::CliError;

/// The target for one 10^7-pulse frame, seconds.
const TARGET_SECONDS: f64 = 0.1;
/// Depth of the synthetic ROM.
const ROM_DEPTH: usize = 4096;

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

#[derive(Debug, Serialize)]
struct Report {
    bins: usize,
    registers: usize,
    width_bits: u32,
    pulses: u64,
    transaction_seconds: f64,
    transaction_cpu_seconds: Option<f64>,
    cpu_realtime_factor: Option<f64>,
    transaction_pulses_per_s: f64,
    realtime_factor: f64,
    pulse_by_pulse_seconds: f64,
    target_seconds: f64,
    cycle_cycles: u64,
    cycle_seconds: f64,
    cycle_cycles_per_s: f64,
    cycle_realtime_factor: f64,
    pass: bool,
}

/// Runs the benchmark.
pub fn run(args: &PixelBenchArgs) -> Result<(), CliError> {
    for (option, value) in [("pulses", args.pulses), ("cycle-pulses", args.cycle_pulses)] {
        if !(1000..=1_000_000_000).contains(&value) {
            return Err(CliError::option(
                option,
                value.to_string(),
                "1000..=1000000000",
            ));
        }
    }
    // The configuration's pixel (W sized for its own frame), timed on `--pulses` pulses.
    let design = tofprobe_design::load(args.config.as_deref())?;
    let c = &design.document;
    let mut params = design.pixel.clone();
    params.frame_pulses = args.pulses;
    if params.mode != tofprobe_pixel::Mode::Fourier {
        return Err(CliError::option(
            "config",
            format!("pixel.mode = {}", params.mode),
            "a Fourier pixel (the benchmark times the I/Q data path)",
        ));
    }
    params.rom_depth = ROM_DEPTH;
    let rom = synthetic_rom(ROM_DEPTH, params.registers());
    let rate = c.sensor.laser_rate_hz;
    let t = bench_transaction(&params, args.pulses as usize, &rom, rate)
        .map_err(|e| tofprobe_design::DesignError::pixel("bench pixel", e))?;
    let mut pc = params.clone();
    pc.frame_pulses = args.cycle_pulses;
    let cy = bench_cycle(&pc, &rom, 1)
        .map_err(|e| tofprobe_design::DesignError::pixel("bench pixel", e))?;
    let cycle_rate = rate * params.cycles_per_pulse as f64;
    let report = Report {
        bins: params.bins,
        registers: params.registers(),
        width_bits: params.width,
        pulses: t.pulses,
        transaction_seconds: t.seconds,
        transaction_cpu_seconds: t.cpu_seconds,
        cpu_realtime_factor: t
            .cpu_seconds
            .map(|cpu| t.pulses as f64 / rate / cpu.max(1e-9)),
        transaction_pulses_per_s: t.pulses_per_s,
        realtime_factor: t.realtime_factor,
        pulse_by_pulse_seconds: t.per_pulse_seconds,
        target_seconds: TARGET_SECONDS * args.pulses as f64 / 1e7,
        cycle_cycles: cy.cycles,
        cycle_seconds: cy.seconds,
        cycle_cycles_per_s: cy.cycles_per_s,
        cycle_realtime_factor: cy.cycles_per_s / cycle_rate,
        pass: t.cpu_seconds.unwrap_or(t.seconds) <= TARGET_SECONDS * args.pulses as f64 / 1e7,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "bit-true pixel, B = {} ({} registers, W = {} bits), one thread",
            report.bins, report.registers, report.width_bits
        );
        println!(
            "transaction model  {} pulses in {:.4} s = {:.1} M pulses/s, {:.1}x real time (target <= {:.3} s)",
            report.pulses,
            report.transaction_seconds,
            report.transaction_pulses_per_s / 1e6,
            report.realtime_factor,
            report.target_seconds
        );
        if let (Some(cpu), Some(f)) = (report.transaction_cpu_seconds, report.cpu_realtime_factor) {
            println!(
                "  on its core      {cpu:.4} s of CPU time ({f:.1}x real time; wall time includes waiting for a shared core)"
            );
        }
        println!(
            "  pulse by pulse   {:.4} s (the per-pulse reference path)",
            report.pulse_by_pulse_seconds
        );
        println!(
            "cycle model        {} cycles in {:.4} s = {:.1} M cycles/s ({:.3}x real time at {} cycles/pulse)",
            report.cycle_cycles,
            report.cycle_seconds,
            report.cycle_cycles_per_s / 1e6,
            report.cycle_realtime_factor,
            params.cycles_per_pulse
        );
        println!("pass               {}", report.pass);
    }
    Ok(())
}
