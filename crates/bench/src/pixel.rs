//! The bit-true pixel's speed at a design's `[pixel]`: the transaction model on one frame
//! with a ROM read per pulse (target: a 10^7-pulse frame in ≤ 0.1 s, i.e. ≥ 10× real time
//! at 10 MHz), and the cycle model's clock edges per second under the reference sequencer.
//!
//! `pass` compares the frame's CPU time on its thread (Linux; wall time elsewhere) with the
//! target: on a shared machine wall time also counts the time spent waiting for a core.
//!
//! The folded driver (the periodic ROM's phase sums, `pixel::fold`) runs the same frame in
//! the same run, its readout checked equal to the transaction driver's, and its speed-up
//! over it is the CPU-time ratio.
//!
//! The ROM is synthetic (L entries of distinct square-wave sign patterns, L the design's
//! ROM depth when periodic, else 4096): the speed does not depend on which bits it holds,
//! only on reading one entry per pulse (and, for the fold, on L).

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::bench::{bench_cycle, bench_fold, bench_transaction, synthetic_rom};

use crate::BenchError;

/// The target for one 10^7-pulse frame, seconds.
pub const TARGET_SECONDS: f64 = 0.1;
/// Depth of the synthetic ROM when the design's is not periodic.
const ROM_DEPTH: usize = 4096;
/// Allowed pulse counts of either run.
pub const PULSES: std::ops::RangeInclusive<u64> = 1000..=1_000_000_000;

/// The measured rates.
#[derive(Debug, Clone, Serialize)]
pub struct PixelReport {
    pub bins: usize,
    pub registers: usize,
    pub width_bits: u32,
    pub cycles_per_pulse: usize,
    pub pulses: u64,
    pub transaction_seconds: f64,
    pub transaction_cpu_seconds: Option<f64>,
    pub cpu_realtime_factor: Option<f64>,
    pub transaction_pulses_per_s: f64,
    pub realtime_factor: f64,
    pub pulse_by_pulse_seconds: f64,
    /// ROM depth L of the timed frames.
    pub rom_depth: usize,
    /// The folded driver on the same frame: seconds, CPU seconds, pulses per second, its
    /// real-time factors, and its speed-up over the transaction driver (CPU-time ratio).
    pub fold_seconds: f64,
    pub fold_cpu_seconds: Option<f64>,
    pub fold_pulses_per_s: f64,
    pub fold_realtime_factor: f64,
    pub fold_cpu_realtime_factor: Option<f64>,
    pub fold_speedup_vs_transaction: f64,
    /// Whether library paths pick the fold for this frame (`pixel::fold::fold_pays`).
    pub fold_chosen: bool,
    pub target_seconds: f64,
    pub cycle_cycles: u64,
    pub cycle_seconds: f64,
    pub cycle_cycles_per_s: f64,
    pub cycle_realtime_factor: f64,
    pub cycle_cpu_seconds: Option<f64>,
    pub cycle_cycles_per_cpu_s: Option<f64>,
    pub pass: bool,
}

/// Times a `pulses`-pulse frame through the transaction model and a `cycle_pulses`-pulse
/// frame through the cycle model, on the calling thread.
pub fn measure(
    design: &ResolvedDesign,
    pulses: u64,
    cycle_pulses: u64,
) -> Result<PixelReport, BenchError> {
    for (option, value) in [("pulses", pulses), ("cycle-pulses", cycle_pulses)] {
        if !PULSES.contains(&value) {
            return Err(BenchError::option(option, value, "1000..=1000000000"));
        }
    }
    // The design's pixel (W sized for its own frame), timed on `pulses` pulses.
    let mut params = design.pixel.clone();
    params.frame_pulses = pulses;
    if params.mode != tofprobe_pixel::Mode::Fourier {
        return Err(BenchError::option(
            "config",
            format!("pixel.mode = {}", params.mode),
            "a Fourier pixel (the benchmark times the I/Q data path)",
        ));
    }
    let depth = if design.document.probe.rom_mode == tofprobe_dsp::sd::RomMode::Periodic {
        design.pixel.rom_depth
    } else {
        ROM_DEPTH
    };
    params.rom_depth = depth;
    let rom = synthetic_rom(depth, params.registers());
    let rate = design.document.sensor.laser_rate_hz;
    let pixel_err = |e| BenchError::from(tofprobe_design::DesignError::pixel("bench pixel", e));
    let t = bench_transaction(&params, pulses as usize, &rom, rate).map_err(pixel_err)?;
    let f = bench_fold(&params, pulses as usize, &rom, rate).map_err(pixel_err)?;
    let mut pc = params.clone();
    pc.frame_pulses = cycle_pulses;
    let cy = bench_cycle(&pc, &rom, 1).map_err(pixel_err)?;
    let cycle_rate = rate * params.cycles_per_pulse as f64;
    let target_seconds = TARGET_SECONDS * pulses as f64 / 1e7;
    Ok(PixelReport {
        bins: params.bins,
        registers: params.registers(),
        width_bits: params.width,
        cycles_per_pulse: params.cycles_per_pulse,
        pulses: t.pulses,
        transaction_seconds: t.seconds,
        transaction_cpu_seconds: t.cpu_seconds,
        cpu_realtime_factor: t
            .cpu_seconds
            .map(|cpu| t.pulses as f64 / rate / cpu.max(1e-9)),
        transaction_pulses_per_s: t.pulses_per_s,
        realtime_factor: t.realtime_factor,
        pulse_by_pulse_seconds: t.per_pulse_seconds,
        rom_depth: depth,
        fold_seconds: f.seconds,
        fold_cpu_seconds: f.cpu_seconds,
        fold_pulses_per_s: f.pulses_per_s,
        fold_realtime_factor: f.realtime_factor,
        fold_cpu_realtime_factor: f.cpu_realtime_factor,
        fold_speedup_vs_transaction: f.speedup_over(&t),
        fold_chosen: tofprobe_pixel::fold::fold_pays(&params),
        target_seconds,
        cycle_cycles: cy.cycles,
        cycle_seconds: cy.seconds,
        cycle_cycles_per_s: cy.cycles_per_s,
        cycle_realtime_factor: cy.cycles_per_s / cycle_rate,
        cycle_cpu_seconds: cy.cpu_seconds,
        cycle_cycles_per_cpu_s: cy.cpu_cycles_per_s,
        // The library's frame driver is the fold when it pays: judge what runs.
        pass: if tofprobe_pixel::fold::fold_pays(&params) {
            f.cpu_seconds.unwrap_or(f.seconds) <= target_seconds
        } else {
            t.cpu_seconds.unwrap_or(t.seconds) <= target_seconds
        },
    })
}
