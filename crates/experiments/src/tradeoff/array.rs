//! The speed/accuracy trade of an `[array]` design (issue 48): the array run at each
//! `[array] level` on the same scene and seeds, each timed, and scored against the
//! bit-true array at the dominant bin (the mode): per-pixel amplitude and phase error
//! against the bit-true spread (the RMS difference of two bit-true runs of different
//! seeds, so a faithful statistical level scores 1 and the noise-free closed-form level
//! ≈ 1/√2), the noise floor (mean amplitude over the other bins) against bit-true's,
//! the MAC of the mode shape, and the two-sample Kolmogorov–Smirnov test of the per-pixel
//! noise (the other bins' phasors, real and imaginary parts, pooled over the pixels).
//! The auto level mixes bit-true pixels with statistical ones: it runs at the second
//! bit-true seed (as the bit-true row does), so its bit-true pixels carry their own noise
//! against the reference rather than copying it, and its row counts them.

use std::time::Instant;

use serde::Serialize;
use tofprobe_array::maps::{VibrationMaps, fourier_maps, mac};
use tofprobe_array::model::run_array;
use tofprobe_array::statistical::auto::level_map;
use tofprobe_design::{ArrayLevel, DesignError, ResolvedDesign};
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_dsp::stats::ks_two_sample;
use tofprobe_io::markdown::Table;

use crate::error::ExperimentError;

/// One level's time and accuracy against the bit-true array.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ArrayLevelResult {
    pub level: String,
    /// Pixels that ran bit-true (all at bit-true, none at the statistical and closed-form
    /// levels, auto's moving pixels).
    pub bit_true_pixels: usize,
    /// Wall time of the array's registers, s.
    pub seconds: f64,
    /// Pixel-pulses per second of wall time.
    pub pixel_pulses_per_s: f64,
    /// RMS over the pixels of the amplitude minus bit-true's at the mode's bin, µm.
    pub amplitude_rms_error_um: f64,
    /// Mean over the pixels of the same difference, µm.
    pub amplitude_bias_um: f64,
    /// `amplitude_rms_error_um` / the RMS difference of two bit-true seeds (1: as close to
    /// bit-true as bit-true's own spread).
    pub amplitude_error_ratio: f64,
    /// RMS phase difference to bit-true over the pixels whose bit-true amplitude is above
    /// 3 noise floors, degrees.
    pub phase_rms_error_deg: f64,
    /// `phase_rms_error_deg` / the same of two bit-true seeds.
    pub phase_error_ratio: f64,
    /// Mean amplitude over the pixels and the bins other than the mode's, µm.
    pub noise_floor_um: f64,
    /// `noise_floor_um` / bit-true's.
    pub noise_floor_ratio: f64,
    /// MAC of the mode shape against bit-true's.
    pub mac: f64,
    /// Two-sample KS statistic D of the per-pixel noise against bit-true's.
    pub noise_ks_statistic: f64,
    /// Its p-value.
    pub noise_ks_p_value: f64,
}

/// The levels of one array configuration.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ArrayTradeoff {
    pub origin: String,
    pub rows: usize,
    pub cols: usize,
    pub pulses: u64,
    /// The mode's bin (bit-true's dominant) and its frequency, Hz.
    pub mode_bin: usize,
    pub mode_frequency_hz: f64,
    /// Per-pixel sd of bit-true's amplitude at the mode (two seeds' RMS difference / √2), µm.
    pub bit_true_spread_um: f64,
    /// The same for the phase, degrees.
    pub bit_true_phase_spread_deg: f64,
    /// MAC of two bit-true seeds' mode shapes (the best a level can match).
    pub bit_true_mac: f64,
    pub levels: Vec<ArrayLevelResult>,
}

/// `design` at `level` (checked like the resolution checks `[array] level`) and seed.
fn at(
    design: &ResolvedDesign,
    level: ArrayLevel,
    seed: u64,
) -> Result<ResolvedDesign, ExperimentError> {
    let mut d = design.clone();
    d.document.acquisition.seed = seed;
    let a = d.array.as_mut().ok_or_else(|| {
        ExperimentError::option("config", &design.origin, "an [array] configuration")
    })?;
    a.level = level;
    tofprobe_design::array::check_level(
        level,
        &d.pixel,
        &d.document.scene,
        a.superpixel as u32,
        &a.background_rate,
    )
    .map_err(|m| ExperimentError::from(DesignError::array(&design.origin, m)))?;
    Ok(d)
}

/// The maps of `design` at `level` and its seconds.
fn run(
    design: &ResolvedDesign,
    rom: &ProbeRom,
    level: ArrayLevel,
    seed: u64,
) -> Result<(VibrationMaps, f64), ExperimentError> {
    let d = at(design, level, seed)?;
    let t = Instant::now();
    let frame = run_array(&d, Some(&rom.image)).map_err(Box::new)?;
    let secs = t.elapsed().as_secs_f64();
    Ok((fourier_maps(&d, rom, &frame).map_err(Box::new)?, secs))
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    (s / n.max(1) as f64).sqrt()
}

/// Phase difference wrapped to ±180°.
fn dphase(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

/// Mean amplitude over the bins other than `mode`.
fn noise_floor(m: &VibrationMaps, mode: usize) -> f64 {
    let bins: Vec<usize> = (0..m.bins()).filter(|&b| b != mode).collect();
    bins.iter().map(|&b| m.mean_amplitude(b)).sum::<f64>() / bins.len().max(1) as f64
}

/// The other bins' phasors (re, im in µm) of every pixel.
fn noise_samples(m: &VibrationMaps, mode: usize) -> Vec<f64> {
    (0..m.bins())
        .filter(|&b| b != mode)
        .flat_map(|b| m.deflection(b).into_iter().flat_map(|(re, im)| [re, im]))
        .collect()
}

/// Measures `levels` of the `[array]` design (Fourier) against its bit-true array at
/// seeds `acquisition.seed` and `acquisition.seed + 1`.
pub fn measure_array(
    design: &ResolvedDesign,
    levels: &[ArrayLevel],
) -> Result<ArrayTradeoff, ExperimentError> {
    let a = design.array.as_ref().ok_or_else(|| {
        ExperimentError::option("config", &design.origin, "an [array] configuration")
    })?;
    let rom = design.probe_rom()?.ok_or_else(|| {
        ExperimentError::option(
            "config",
            &design.origin,
            "a Fourier pixel (the array trade-off reads the vibration maps)",
        )
    })?;
    let seed = design.document.acquisition.seed;
    let (bt, bt_secs) = run(design, &rom, ArrayLevel::BitTrue, seed)?;
    let (bt2, _) = run(design, &rom, ArrayLevel::BitTrue, seed.wrapping_add(1))?;
    let mode = bt.dominant_bin;
    let floor_bt = noise_floor(&bt, mode);
    let moving: Vec<usize> = (0..bt.rows * bt.cols)
        .filter(|&p| bt.amplitude(mode)[p] > 3.0 * floor_bt)
        .collect();
    let amp_rms = |m: &VibrationMaps| {
        rms(m
            .amplitude(mode)
            .iter()
            .zip(bt.amplitude(mode))
            .map(|(x, y)| x - y))
    };
    let phase_rms = |m: &VibrationMaps| {
        rms(moving
            .iter()
            .map(|&p| dphase(m.phase(mode)[p], bt.phase(mode)[p])))
    };
    let (amp_ref, phase_ref) = (amp_rms(&bt2), phase_rms(&bt2));
    let bt_noise = noise_samples(&bt, mode);
    let pixel_pulses = (bt.rows * bt.cols) as f64 * design.pixel.frame_pulses as f64;
    let mut out = Vec::with_capacity(levels.len());
    for &level in levels {
        let (m, secs) = match level {
            ArrayLevel::BitTrue => (bt2.clone(), bt_secs),
            ArrayLevel::Auto => run(design, &rom, level, seed.wrapping_add(1))?,
            _ => run(design, &rom, level, seed)?,
        };
        let bit_true_pixels = level_map(&at(design, level, seed)?)
            .map_err(Box::new)?
            .iter()
            .filter(|l| l.is_bit_true())
            .count();
        let n = (m.rows * m.cols) as f64;
        let floor = noise_floor(&m, mode);
        let (d, p) = ks_two_sample(&noise_samples(&m, mode), &bt_noise);
        let ratio = |x: f64, r: f64| if r > 0.0 { x / r } else { 0.0 };
        out.push(ArrayLevelResult {
            level: level.name().to_string(),
            bit_true_pixels,
            seconds: secs,
            pixel_pulses_per_s: pixel_pulses / secs.max(1e-9),
            amplitude_rms_error_um: amp_rms(&m),
            amplitude_bias_um: m
                .amplitude(mode)
                .iter()
                .zip(bt.amplitude(mode))
                .map(|(x, y)| x - y)
                .sum::<f64>()
                / n,
            amplitude_error_ratio: ratio(amp_rms(&m), amp_ref),
            phase_rms_error_deg: phase_rms(&m),
            phase_error_ratio: ratio(phase_rms(&m), phase_ref),
            noise_floor_um: floor,
            noise_floor_ratio: ratio(floor, floor_bt),
            mac: mac(&m.deflection(mode), &bt.deflection(mode)),
            noise_ks_statistic: d,
            noise_ks_p_value: p,
        });
    }
    Ok(ArrayTradeoff {
        origin: design.origin.clone(),
        rows: a.rows,
        cols: a.cols,
        pulses: design.pixel.frame_pulses,
        mode_bin: mode,
        mode_frequency_hz: bt.frequencies_hz[mode],
        bit_true_spread_um: amp_ref / 2f64.sqrt(),
        bit_true_phase_spread_deg: phase_ref / 2f64.sqrt(),
        bit_true_mac: mac(&bt2.deflection(mode), &bt.deflection(mode)),
        levels: out,
    })
}

/// The Markdown table of one array configuration.
pub fn markdown(r: &ArrayTradeoff) -> String {
    let mut t = Table::left([
        "level",
        "bit-true pixels",
        "s",
        "pixel-pulses/s",
        "amp. RMS err µm",
        "× bit-true spread",
        "amp. bias µm",
        "phase RMS err °",
        "× bit-true",
        "noise floor µm",
        "× bit-true",
        "MAC",
        "KS D",
        "KS p",
    ]);
    for l in &r.levels {
        t.row([
            l.level.to_string(),
            l.bit_true_pixels.to_string(),
            format!("{:.3}", l.seconds),
            format!("{:.3e}", l.pixel_pulses_per_s),
            format!("{:.3}", l.amplitude_rms_error_um),
            format!("{:.2}", l.amplitude_error_ratio),
            format!("{:+.3}", l.amplitude_bias_um),
            format!("{:.2}", l.phase_rms_error_deg),
            format!("{:.2}", l.phase_error_ratio),
            format!("{:.3}", l.noise_floor_um),
            format!("{:.3}", l.noise_floor_ratio),
            format!("{:.5}", l.mac),
            format!("{:.3}", l.noise_ks_statistic),
            format!("{:.2e}", l.noise_ks_p_value),
        ]);
    }
    format!(
        "### {} ({} × {} pixels, N = {}; mode at {:.1} Hz, bin {}; bit-true spread {:.3} µm, \
         {:.2}°; bit-true MAC between seeds {:.5})\n\n{t}",
        r.origin,
        r.rows,
        r.cols,
        r.pulses,
        r.mode_frequency_hz,
        r.mode_bin,
        r.bit_true_spread_um,
        r.bit_true_phase_spread_deg,
        r.bit_true_mac
    )
}
