//! The bit-true pixel's speed at a design's `[pixel]`: the transaction model on one frame
//! with a ROM read per pulse (target: a 10^7-pulse frame in ≤ 0.1 s, i.e. ≥ 10× real time
//! at 10 MHz), and the cycle model's clock edges per second under the reference sequencer.
//!
//! `pass` compares the frame's CPU time on its thread (Linux; wall time elsewhere) with the
//! target: on a shared machine wall time also counts the time spent waiting for a core.
//!
//! The folded driver (the periodic ROM's phase sums, `pixel::fold`) runs the same frame in
//! the same run, its readout checked equal to the transaction driver's, and its speed-up
//! over it is the CPU-time ratio. So does the segmented fold (`pixel::segments`: the frame
//! cut into eight time segments run in vector lanes and repaired exactly), the frame
//! driver's choice for a long frame; `pass` judges the driver the library picks.
//!
//! Each ISA of the lanes (`tofprobe_io::isa`) is its own row ([`measure_isas`]): the
//! segmented fold runs the lanes; the other drivers are scalar and are timed again per row.
//!
//! The ROM is synthetic (L entries of distinct square-wave sign patterns, L the design's
//! ROM depth when periodic, else 4096): the speed does not depend on which bits it holds,
//! only on reading one entry per pulse (and, for the fold, on L).

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::speed::{
    bench_cycle, bench_fold, bench_segmented, bench_transaction, synthetic_rom,
};

use crate::BenchError;
use crate::isa::{IsaRows, rows};
use tofprobe_io::isa::Isa;

/// The target for one 10^7-pulse frame, seconds.
pub const TARGET_SECONDS: f64 = 0.1;
/// Issue 28's real-time factor for the default pixel's frame on one core.
pub const REALTIME_TARGET: f64 = 100.0;
/// Depth of the synthetic ROM when the design's is not periodic.
const ROM_DEPTH: usize = 4096;
/// Allowed pulse counts of either run.
pub const PULSES: std::ops::RangeInclusive<u64> = 1000..=1_000_000_000;

/// The measured rates.
#[derive(Debug, Clone, Serialize)]
pub struct PixelReport {
    /// The instruction set the vector kernels ran on ("scalar", "avx2", "avx512").
    pub isa: &'static str,
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
    /// The segmented fold on the same frame, in the same chunks: seconds, CPU seconds,
    /// real-time factors, its speed-ups over the transaction driver and the plain fold
    /// (CPU-time ratios), the pulses its repairs stepped again (two chains each), and
    /// whether library paths pick it (`pixel::segments::segments_pay`).
    pub segmented_fold_seconds: f64,
    pub segmented_fold_cpu_seconds: Option<f64>,
    pub segmented_fold_pulses_per_s: f64,
    pub segmented_fold_realtime_factor: f64,
    pub segmented_fold_cpu_realtime_factor: Option<f64>,
    pub segmented_speedup_vs_transaction: f64,
    pub segmented_speedup_vs_fold: f64,
    pub segmented_repaired_pulses: u64,
    pub segmented_chosen: bool,
    /// The real-time target for the frame driver's choice (100×, on CPU time
    /// where measured) and whether that choice reaches it.
    pub realtime_target: f64,
    pub realtime_pass: bool,
    pub target_seconds: f64,
    pub cycle_cycles: u64,
    pub cycle_seconds: f64,
    pub cycle_cycles_per_s: f64,
    pub cycle_realtime_factor: f64,
    pub cycle_cpu_seconds: Option<f64>,
    pub cycle_cycles_per_cpu_s: Option<f64>,
    pub pass: bool,
}

/// [`measure`] once per ISA in `isas`, each under that ISA.
pub fn measure_isas(
    design: &ResolvedDesign,
    pulses: u64,
    cycle_pulses: u64,
    isas: &[Isa],
) -> Result<IsaRows<PixelReport>, BenchError> {
    rows(isas, |_| measure(design, pulses, cycle_pulses))
}

/// Times a `pulses`-pulse frame through the transaction model and a `cycle_pulses`-pulse
/// frame through the cycle model, on the calling thread, on the current ISA.
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
    let (sg, repaired) =
        bench_segmented(&params, pulses as usize, &rom, rate).map_err(pixel_err)?;
    let segmented_chosen = tofprobe_pixel::segments_pay(&params);
    let fold_chosen = tofprobe_pixel::fold::fold_pays(&params);
    // The driver the library picks for this frame, on CPU time where measured.
    let chosen_seconds = if segmented_chosen {
        sg.cpu_seconds.unwrap_or(sg.seconds)
    } else if fold_chosen {
        f.cpu_seconds.unwrap_or(f.seconds)
    } else {
        t.cpu_seconds.unwrap_or(t.seconds)
    };
    let chosen_factor = pulses as f64 / rate / chosen_seconds.max(1e-9);
    let segmented_speedup_vs_fold = match (f.cpu_seconds, sg.cpu_seconds) {
        (Some(a), Some(b)) => a / b.max(1e-9),
        _ => f.seconds / sg.seconds.max(1e-9),
    };
    let mut pc = params.clone();
    pc.frame_pulses = cycle_pulses;
    let cy = bench_cycle(&pc, &rom, 1).map_err(pixel_err)?;
    let cycle_rate = rate * params.cycles_per_pulse as f64;
    let target_seconds = TARGET_SECONDS * pulses as f64 / 1e7;
    Ok(PixelReport {
        isa: Isa::current().name(),
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
        fold_chosen,
        segmented_fold_seconds: sg.seconds,
        segmented_fold_cpu_seconds: sg.cpu_seconds,
        segmented_fold_pulses_per_s: sg.pulses_per_s,
        segmented_fold_realtime_factor: sg.realtime_factor,
        segmented_fold_cpu_realtime_factor: sg.cpu_realtime_factor,
        segmented_speedup_vs_transaction: sg.speedup_over(&t),
        segmented_speedup_vs_fold,
        segmented_repaired_pulses: repaired,
        segmented_chosen,
        realtime_target: REALTIME_TARGET,
        realtime_pass: chosen_factor >= REALTIME_TARGET,
        target_seconds,
        cycle_cycles: cy.cycles,
        cycle_seconds: cy.seconds,
        cycle_cycles_per_s: cy.cycles_per_s,
        cycle_realtime_factor: cy.cycles_per_s / cycle_rate,
        cycle_cpu_seconds: cy.cpu_seconds,
        cycle_cycles_per_cpu_s: cy.cpu_cycles_per_s,
        // The library's frame driver: judge what runs.
        pass: chosen_seconds <= target_seconds,
    })
}
