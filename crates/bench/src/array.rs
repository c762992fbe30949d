//! The array model's speed: a rows × cols array (default 64 × 64) of the configuration's
//! pixel over frames of N pulses (default 10^6 and 10^7), run on all the current pool's
//! threads, in pixel-pulses per second of wall time and per CPU-second, beside the
//! single-pixel Monte Carlo alone (the photon source filling the same N pulses on one
//! thread) measured in the same run: the Monte Carlo is the physical floor of this
//! simulation, and `model_share` says how much of the array's CPU time is not Monte Carlo.
//! Peak memory is the process's high-water mark (VmHWM), for the memory bound linear in
//! R·C·2B and independent of N. Each ISA of the vector kernels (`tofprobe_io::isa`: the
//! Monte Carlo and the pixel's lanes) is its own row ([`measure_isas`]). Each `[array]
//! level` is measured beside the bit-true run of the last frame length
//! ([`crate::array_levels`]).

use std::time::Instant;

use serde::Serialize;
use tofprobe_design::{ArrayConfig, Document, ResolvedDesign, resolve};

use crate::BenchError;
use crate::array_levels::{LevelRun, measure_levels};
use crate::cpu::{process_cpu_seconds, thread_cpu_ns};
use crate::isa::{IsaRows, rows};
use tofprobe_io::isa::Isa;

/// Fewest pulses the Monte Carlo alone is timed over (≈ 0.1 CPU-s).
const MC_MIN_PULSES: u64 = 1 << 25;

/// The target: a 64 × 64 array, N = 10^7, on 2 cores in ≤ 60 s.
pub const TARGET_SECONDS: f64 = 60.0;

/// One frame length's figures.
#[derive(Debug, Clone, Serialize)]
pub struct ArrayRun {
    pub pulses: u64,
    pub pixel_pulses: f64,
    pub seconds: f64,
    pub cpu_seconds: Option<f64>,
    pub pixel_pulses_per_s: f64,
    pub pixel_pulses_per_cpu_s: Option<f64>,
    /// The single-pixel Monte Carlo alone on one thread, pulses per CPU-second (wall where
    /// CPU time is not measured).
    pub monte_carlo_pulses_per_cpu_s: f64,
    /// The share of the array's CPU time spent outside the Monte Carlo (the model, the
    /// ROM reads, the scheduling): 1 − (array pixel-pulses per CPU-s ÷ Monte Carlo pulses
    /// per CPU-s).
    pub model_share: f64,
    /// A 64 × 64 array at this N on 2 idle cores at this run's CPU-time rate, s.
    pub seconds_on_2_idle_cores: Option<f64>,
    pub peak_memory_bytes: Option<u64>,
}

/// The benchmark's report.
#[derive(Debug, Clone, Serialize)]
pub struct ArrayReport {
    /// The instruction set the vector kernels ran on ("scalar", "avx2", "avx512").
    pub isa: &'static str,
    pub configuration: String,
    pub rows: usize,
    pub cols: usize,
    pub threads: usize,
    pub runs: Vec<ArrayRun>,
    /// A 64 × 64 array at N = 10^7 on 2 idle cores at the best CPU-time rate measured, s.
    pub projected_64x64_1e7_seconds: Option<f64>,
    pub target_seconds: f64,
    pub pass: bool,
    /// Each `[array] level` at the last frame length, side by side with its bit-true run
    /// (`array_levels`): CPU-s, rate, speed-up and the 256 × 256 × 10^7 projection. Measured
    /// on the widest ISA only (the top level's; the narrower rows leave it out).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub levels: Vec<LevelRun>,
}

/// The process's peak resident memory (VmHWM), bytes (Linux; `None` elsewhere).
pub fn peak_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The design's pixel as a rows × cols array (1 mm per pixel, the scene's motions applied
/// alike where they are temporal; a configuration's own `[array]` kept but its shape, at
/// the bit-true level) over frames of `pulses`.
fn array_design(
    base: &ResolvedDesign,
    rows: u32,
    cols: u32,
    pulses: u64,
) -> Result<ResolvedDesign, BenchError> {
    let mut doc: Document = base.document.clone();
    doc.acquisition.pulses = Some(pulses);
    doc.acquisition.duration_s = None;
    doc.pixel.frame_pulses = None;
    let a = doc
        .array
        .get_or_insert(ArrayConfig::new(rows, cols, 30.0, 1.0));
    (a.rows, a.cols) = (rows, cols);
    // The timed runs are bit-true; the other levels are set by `array_levels`.
    a.level = tofprobe_design::ArrayLevel::BitTrue;
    Ok(resolve(doc, &base.origin)?)
}

/// [`measure`] once per ISA in `isas`, each under that ISA.
pub fn measure_isas(
    base: &ResolvedDesign,
    (rows_, cols): (u32, u32),
    pulses: &[u64],
    isas: &[Isa],
) -> Result<IsaRows<ArrayReport>, BenchError> {
    let widest = isas.last().copied();
    rows(isas, |isa| {
        measure(base, rows_, cols, pulses, Some(isa) == widest)
    })
}

/// Runs the benchmark for each frame length in `pulses`, on the current ISA, and (if
/// `with_levels`) each `[array] level` at the last.
pub fn measure(
    base: &ResolvedDesign,
    rows: u32,
    cols: u32,
    pulses: &[u64],
    with_levels: bool,
) -> Result<ArrayReport, BenchError> {
    let threads = rayon::current_num_threads();
    let mut runs = Vec::new();
    let mut last = None;
    for &n in pulses {
        let d = array_design(base, rows, cols, n)?;
        let rom = d.probe_rom()?;
        let cpu0 = process_cpu_seconds();
        let t0 = Instant::now();
        let frame = tofprobe_array::run_array(&d, rom.as_ref().map(|r| &r.image))
            .map_err(|e| BenchError::internal("array", e))?;
        let seconds = t0.elapsed().as_secs_f64();
        let cpu = cpu0.zip(process_cpu_seconds()).map(|(a, b)| b - a);
        std::hint::black_box(&frame);
        drop(frame);
        let bit_true_cpu = cpu.filter(|&c| c > 0.0).unwrap_or(seconds * threads as f64);
        // The Monte Carlo alone: pixel (0, 0)'s source on this thread, over N pulses or
        // MC_MIN_PULSES if more (the thread's CPU clock may advance by scheduler ticks of
        // milliseconds: 10^6 pulses are a few of them).
        let src = d.pixel_source(0, 0)?;
        let mc_pulses = n.max(MC_MIN_PULSES);
        // The compact codes, the form the array streams (`PhotonSource::fill_codes`).
        let mut buf = vec![0u32; 1 << 16];
        let c0 = thread_cpu_ns();
        let t1 = Instant::now();
        let mut first = 0u64;
        while first < mc_pulses {
            let k = (mc_pulses - first).min(buf.len() as u64) as usize;
            src.fill_codes(first, &mut buf[..k]);
            first += k as u64;
        }
        let mc_wall = t1.elapsed().as_secs_f64();
        let mc_cpu = c0
            .zip(thread_cpu_ns())
            .map(|(a, b)| (b.saturating_sub(a)) as f64 * 1e-9);
        let mc_rate = mc_pulses as f64 / mc_cpu.unwrap_or(mc_wall).max(1e-9);
        let pixel_pulses = f64::from(rows) * f64::from(cols) * n as f64;
        let per_cpu = cpu.map(|c| pixel_pulses / c.max(1e-9));
        let array_rate = per_cpu.unwrap_or(pixel_pulses / seconds.max(1e-9) / threads as f64);
        runs.push(ArrayRun {
            pulses: n,
            pixel_pulses,
            seconds,
            cpu_seconds: cpu,
            pixel_pulses_per_s: pixel_pulses / seconds.max(1e-9),
            pixel_pulses_per_cpu_s: per_cpu,
            monte_carlo_pulses_per_cpu_s: mc_rate,
            model_share: (1.0 - array_rate / mc_rate).max(0.0),
            seconds_on_2_idle_cores: per_cpu.map(|r| 64.0 * 64.0 * n as f64 / (2.0 * r)),
            peak_memory_bytes: peak_memory_bytes(),
        });
        last = Some((d, seconds, bit_true_cpu));
    }
    let levels = match (&last, with_levels) {
        (Some((d, secs, cpu)), true) => measure_levels(d, *secs, *cpu)?,
        _ => Vec::new(),
    };
    let best = runs
        .iter()
        .filter_map(|r| r.pixel_pulses_per_cpu_s)
        .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))));
    let projected = best.map(|r| 64.0 * 64.0 * 1e7 / (2.0 * r));
    let pass = projected.is_some_and(|s| s <= TARGET_SECONDS);
    Ok(ArrayReport {
        isa: Isa::current().name(),
        configuration: base.origin.clone(),
        rows: rows as usize,
        cols: cols as usize,
        threads,
        runs,
        projected_64x64_1e7_seconds: projected,
        target_seconds: TARGET_SECONDS,
        pass,
        levels,
    })
}
