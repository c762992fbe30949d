//! The array's fidelity levels side by side (`[array] level`, docs/tradeoff.md "Array
//! levels"): the same array and frame as `bench array`'s bit-true run, at the
//! statistical, closed-form and auto levels, measured in the same run, each in CPU-s
//! (its model's build included: the shared model is cleared before each level) with its
//! speed-up over bit-true and its projection to the 256 × 256 × 10^7 frame on 2
//! idle cores, judged against the targets (bit-true ≤ 8 min, statistical ≤ 10 s).
//!
//! The projection: bit-true's cost is per pixel-pulse, so it scales by R·C·N. A drawn
//! level's cost is its model — the probe ROM and the probe's band powers (fixed: they
//! depend on L, not on N or R·C) and the float twin run over N pulses (∝ N) — plus a
//! cost per pixel independent of N (its mean, its draw); each part is timed on its own
//! and scaled by its own factor. Auto runs its bit-true pixels at bit-true's rate and the rest drawn:
//! its projection is the bit-true share of bit-true's plus the statistical level's.

use serde::Serialize;
use tofprobe_array::statistical::spectra::ProbeBands;
use tofprobe_array::statistical::{auto::level_map, clear_shared_models, shared_model};
use tofprobe_design::{ArrayLevel, ResolvedDesign};

use crate::BenchError;
use crate::cpu::process_cpu_seconds;

/// The targets on 2 cores for a 256 × 256 frame of 10^7 pulses, s.
pub const BIT_TRUE_TARGET_SECONDS: f64 = 480.0;
pub const STATISTICAL_TARGET_SECONDS: f64 = 10.0;
/// The projected frame: 256 × 256 pixels of 10^7 pulses on 2 cores.
const PROJECTED_PIXELS: f64 = 256.0 * 256.0;
const PROJECTED_PULSES: f64 = 1e7;
const PROJECTED_CORES: f64 = 2.0;

/// One level's figures.
#[derive(Debug, Clone, Serialize)]
pub struct LevelRun {
    pub level: &'static str,
    pub pulses: u64,
    /// Pixels that ran bit-true (auto: the moving ones).
    pub bit_true_pixels: usize,
    pub seconds: f64,
    /// CPU time of the level's whole run (wall × threads where not measured), its model's
    /// build included.
    pub cpu_seconds: f64,
    /// The part of it that built the level's model (the ROM, the bands, the twin; 0 at
    /// bit-true).
    pub model_cpu_seconds: f64,
    /// R·C·N over `cpu_seconds`.
    pub pixel_pulses_per_cpu_second: f64,
    /// Bit-true's CPU-s over this level's.
    pub speedup_over_bit_true: f64,
    /// 256 × 256 × 10^7 on 2 idle cores at this run's costs, s (module header).
    pub projected_256x256_1e7_seconds: f64,
    /// The target for the level (bit-true, statistical), s.
    pub target_seconds: Option<f64>,
    pub pass: Option<bool>,
}

/// CPU-s since `c0`, or (not measured, or below the clock's 10 ms tick) wall × threads.
fn cpu_since(c0: Option<f64>, wall: f64, threads: usize) -> f64 {
    c0.zip(process_cpu_seconds())
        .map(|(a, b)| b - a)
        .filter(|&c| c > 0.0)
        .unwrap_or(wall * threads as f64)
}

/// The levels of design `d` (its array and N), bit-true's row from the run just made
/// (`bit_true_cpu` CPU-s over `bit_true_seconds`).
pub fn measure_levels(
    d: &ResolvedDesign,
    bit_true_seconds: f64,
    bit_true_cpu: f64,
) -> Result<Vec<LevelRun>, BenchError> {
    let threads = rayon::current_num_threads();
    let n = d.pixel.frame_pulses;
    let (rows, cols) = d.array.as_ref().map_or((0, 0), |a| (a.rows, a.cols));
    let pixels = (rows * cols) as f64;
    let pixel_pulses = pixels * n as f64;
    let scale_pixels = PROJECTED_PIXELS / pixels.max(1.0);
    let scale_pulses = PROJECTED_PULSES / n.max(1) as f64;
    let bt_projected = bit_true_cpu * scale_pixels * scale_pulses / PROJECTED_CORES;
    let row = |level: ArrayLevel, bt_px, secs, cpu: f64, model: f64, projected| {
        let target = match level {
            ArrayLevel::BitTrue => Some(BIT_TRUE_TARGET_SECONDS),
            ArrayLevel::Statistical => Some(STATISTICAL_TARGET_SECONDS),
            _ => None,
        };
        LevelRun {
            level: level.name(),
            pulses: n,
            bit_true_pixels: bt_px,
            seconds: secs,
            cpu_seconds: cpu,
            model_cpu_seconds: model,
            pixel_pulses_per_cpu_second: pixel_pulses / cpu.max(1e-9),
            speedup_over_bit_true: bit_true_cpu / cpu.max(1e-9),
            projected_256x256_1e7_seconds: projected,
            target_seconds: target,
            pass: target.map(|t| projected <= t),
        }
    };
    let mut out = vec![row(
        ArrayLevel::BitTrue,
        rows * cols,
        bit_true_seconds,
        bit_true_cpu,
        0.0,
        bt_projected,
    )];
    // The statistical level's projection, auto's drawn part.
    let mut statistical_projected = 0.0;
    let Some(rom) = d.probe_rom()? else {
        return Ok(out); // Haar: bit-true only (the drawn levels are Fourier's).
    };
    // The model's fixed parts alone (the ROM, the bands), once: every level's are alike.
    let c0 = process_cpu_seconds();
    let t0 = std::time::Instant::now();
    let rom_again = d.probe_rom()?;
    std::hint::black_box(rom_again.map(|r| ProbeBands::new(&r)));
    let fixed = cpu_since(c0, t0.elapsed().as_secs_f64(), threads);
    for level in [
        ArrayLevel::Statistical,
        ArrayLevel::ClosedForm,
        ArrayLevel::Auto,
    ] {
        let mut dl = d.clone();
        if let Some(a) = dl.array.as_mut() {
            a.level = level;
        }
        let refused = tofprobe_design::array::check_level(
            level,
            &dl.pixel,
            &dl.document.scene,
            dl.array.as_ref().map_or(1, |a| a.superpixel as u32),
            dl.array.as_ref().map_or(&[][..], |a| &a.background_rate),
        );
        if refused.is_err() {
            continue; // outside the drawn levels' range: bit-true's row only
        }
        let model_level = match level {
            ArrayLevel::Auto => ArrayLevel::Statistical,
            l => l,
        };
        // The whole model (the ROM, the bands and the twin), then the pixels with it built.
        clear_shared_models();
        let c0 = process_cpu_seconds();
        let t0 = std::time::Instant::now();
        shared_model(&dl, model_level).map_err(|e| BenchError::internal("array", e))?;
        let model = cpu_since(c0, t0.elapsed().as_secs_f64(), threads);
        let frame = tofprobe_array::run_array(&dl, Some(&rom.image))
            .map_err(|e| BenchError::internal("array", e))?;
        let secs = t0.elapsed().as_secs_f64();
        let cpu = cpu_since(c0, secs, threads);
        std::hint::black_box(&frame);
        let bt_px = level_map(&dl)
            .map_err(|e| BenchError::internal("array", e))?
            .iter()
            .filter(|l| l.is_bit_true())
            .count();
        let twin = (model - fixed).max(0.0);
        let drawn =
            (fixed + twin * scale_pulses + (cpu - model).max(0.0) * scale_pixels) / PROJECTED_CORES;
        let projected = match level {
            ArrayLevel::Auto => {
                bt_px as f64 / pixels.max(1.0) * bt_projected + statistical_projected
            }
            _ => drawn,
        };
        if level == ArrayLevel::Statistical {
            statistical_projected = drawn;
        }
        out.push(row(level, bt_px, secs, cpu, model, projected));
    }
    Ok(out)
}
