//! The bit-true pixel's speed at a design's `[pixel]`: the transaction model on one frame
//! with a ROM read per pulse (target: a 10^7-pulse frame in ≤ 0.1 s, i.e. ≥ 10× real time
//! at 10 MHz), and the cycle model's clock edges per second under the reference sequencer.
//!
//! `pass` compares the frame's CPU time on its thread (Linux; wall time elsewhere) with the
//! target: on a shared machine wall time also counts the time spent waiting for a core.
//!
//! The ROM is synthetic (4096 entries of distinct square-wave sign patterns): the speed
//! does not depend on which bits it holds, only on reading one entry per pulse.

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::bench::{bench_cycle, bench_transaction, synthetic_rom};

use crate::BenchError;

/// The target for one 10^7-pulse frame, seconds.
pub const TARGET_SECONDS: f64 = 0.1;
/// Depth of the synthetic ROM.
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
    pub target_seconds: f64,
    pub cycle_cycles: u64,
    pub cycle_seconds: f64,
    pub cycle_cycles_per_s: f64,
    pub cycle_realtime_factor: f64,
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
    params.rom_depth = ROM_DEPTH;
    let rom = synthetic_rom(ROM_DEPTH, params.registers());
    let rate = design.document.sensor.laser_rate_hz;
    let pixel_err = |e| BenchError::from(tofprobe_design::DesignError::pixel("bench pixel", e));
    let t = bench_transaction(&params, pulses as usize, &rom, rate).map_err(pixel_err)?;
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
        target_seconds,
        cycle_cycles: cy.cycles,
        cycle_seconds: cy.seconds,
        cycle_cycles_per_s: cy.cycles_per_s,
        cycle_realtime_factor: cy.cycles_per_s / cycle_rate,
        pass: t.cpu_seconds.unwrap_or(t.seconds) <= target_seconds,
    })
}
