//! The speed/accuracy trade (issue 8): one configuration measured at every fidelity level
//! on the same photon record — closed form, float full DFT, float selected-bin DFT, float
//! ΣΔ probing, bit-true transaction model, cycle-accurate model (shortened frame,
//! extrapolated) — each with its wall time per simulated second and its accuracy: the
//! tone amplitude and the noise floor (mean amplitude over the noise bins) against the
//! float full DFT and against the scene's true amplitude.

pub mod array;
pub mod haar;
pub mod imputation;
pub mod imputation_cost;
pub mod knobs;
pub mod overrides;
pub mod plot;
pub mod skips;
pub mod study;
pub mod timing;

use std::time::Instant;

use serde::Serialize;
use tofprobe_dsp::closed_form::{
    hold_response_sq, mixture_gain, noise_floor_hold_mm, noise_floor_mm,
};
use tofprobe_dsp::dft::amplitude_spectrum;
use tofprobe_dsp::sd::{amplitudes_um, normalise, probe_detections};
use tofprobe_dsp::selected_bins::SelectedBins;
use tofprobe_io::markdown::Table;
use tofprobe_pixel::autobins::choose_bins;
use tofprobe_pixel::spectrum::bit_true_spectrum;
use tofprobe_pixel::speed::bench_cycle;

use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_scene::PhotonSource;

use crate::error::ExperimentError;
use crate::level::Level;
use crate::records::{detection_record, held_record};
use crate::references::dft_bins;
use crate::spectrum::{BitTrueSetup, setup};

/// Pulses of the shortened frame the cycle-accurate model is timed on.
pub const CYCLE_FRAME: u64 = 1 << 14;

/// One fidelity level's measurement.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct LevelResult {
    /// Level name.
    pub level: String,
    /// Wall seconds per simulated second of sensor time (f_s pulses).
    pub seconds_per_sim_second: f64,
    /// True when the time was measured on a shortened frame and scaled up.
    pub extrapolated: bool,
    /// Tone amplitude read, µm (`None` for a scene without an in-band tone).
    pub amplitude_um: Option<f64>,
    /// Noise floor: mean amplitude over the noise bins, µm.
    pub noise_um: f64,
    /// |amplitude − float DFT amplitude|, µm.
    pub amplitude_err_vs_dft_um: Option<f64>,
    /// |amplitude − true amplitude|, µm.
    pub amplitude_err_vs_true_um: Option<f64>,
    /// Noise floor relative to the float DFT's, minus 1.
    pub noise_rel_err_vs_dft: f64,
}

impl SceneResult {
    /// The row of `level`, if it was measured.
    pub fn level(&self, level: Level) -> Option<&LevelResult> {
        self.levels.iter().find(|l| l.level == level.name())
    }
}

/// All levels of one configuration.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SceneResult {
    /// Where the configuration came from.
    pub origin: String,
    /// Pulses N.
    pub pulses: u64,
    /// True amplitude of the scene's strongest in-band tone, µm.
    pub true_amplitude_um: Option<f64>,
    /// One row per level.
    pub levels: Vec<LevelResult>,
}

/// One level's raw reading before scoring.
#[derive(Debug, Clone, Copy)]
struct Reading {
    level: Level,
    /// Wall seconds for the frame (measured, or scaled up from a shortened frame).
    seconds: f64,
    extrapolated: bool,
    /// Tone amplitude, µm.
    amplitude: Option<f64>,
    /// Mean amplitude over the noise bins, µm.
    noise: f64,
}

/// Measures every level of the Fourier ladder on `design` (Fourier pixel; the float
/// levels use its ROM's bins); with `verilator`, also the Verilator RTL on a shortened
/// frame (builds the harness).
pub fn measure(design: &ResolvedDesign, verilator: bool) -> Result<SceneResult, ExperimentError> {
    let su: BitTrueSetup = setup(design)?;
    measure_setup(design, &su, verilator)
}

/// [`measure`] with the ROM already generated (`su` from [`setup`] on the same `design`),
/// so a caller that also times the bit-true model on its own generates the ROM once.
pub fn measure_setup(
    design: &ResolvedDesign,
    su: &BitTrueSetup,
    verilator: bool,
) -> Result<SceneResult, ExperimentError> {
    measure_levels(design, su, &Level::fourier_ladder(verilator))
}

/// The chosen Fourier `levels` of `design`, in the order given, each timed and scored
/// against the float full DFT (run for the scoring when it is not among them, but not
/// reported) and the scene's true amplitude. Only what the levels need is computed: the
/// held record for the float levels, the bit-true spectrum for the bit-exact ones.
pub fn measure_levels(
    design: &ResolvedDesign,
    su: &BitTrueSetup,
    levels: &[Level],
) -> Result<SceneResult, ExperimentError> {
    if let Some(l) = levels.iter().find(|l| !l.info().fourier) {
        return Err(ExperimentError::option(
            "level",
            l.name(),
            "a level of the Fourier ladder (tradeoff::haar measures the Haar one)",
        ));
    }
    let mut ladder = Ladder::new(design, su)?;
    let dft = ladder.reading(Level::FullDft)?;
    let mut readings = Vec::with_capacity(levels.len());
    for &level in levels {
        readings.push(ladder.reading(level)?);
    }
    let sim_seconds = ladder.n as f64 / ladder.fs;
    let true_amp = ladder.true_amp;
    let levels = readings
        .iter()
        .map(|r| LevelResult {
            level: r.level.name().to_string(),
            seconds_per_sim_second: r.seconds / sim_seconds,
            extrapolated: r.extrapolated,
            amplitude_um: r.amplitude,
            noise_um: r.noise,
            amplitude_err_vs_dft_um: r.amplitude.zip(dft.amplitude).map(|(x, d)| (x - d).abs()),
            amplitude_err_vs_true_um: r.amplitude.zip(true_amp).map(|(x, t)| (x - t).abs()),
            noise_rel_err_vs_dft: if dft.noise > 0.0 {
                r.noise / dft.noise - 1.0
            } else {
                0.0
            },
        })
        .collect();
    Ok(SceneResult {
        origin: design.origin.clone(),
        pulses: ladder.n,
        true_amplitude_um: true_amp,
        levels,
    })
}

/// The shared state of one ladder: the scene, the scoring bins and, once a level needs
/// them, the detection record, the held record and the bit-true spectrum.
struct Ladder<'a> {
    design: &'a ResolvedDesign,
    su: &'a BitTrueSetup,
    source: PhotonSource,
    n: u64,
    fs: f64,
    lsb_mm: f64,
    true_amp: Option<f64>,
    tone_idx: Option<usize>,
    noise_idx: Vec<usize>,
    /// (detections, held depths, seconds to build them).
    record: Option<(Vec<Option<u32>>, Vec<f64>, f64)>,
    done: Vec<Reading>,
}

impl<'a> Ladder<'a> {
    fn new(design: &'a ResolvedDesign, su: &'a BitTrueSetup) -> Result<Self, ExperimentError> {
        let (config, origin) = (&design.document, design.origin.as_str());
        let scene_err = |source| ExperimentError::from(DesignError::scene(origin, source));
        let source = config.photon_source().map_err(scene_err)?;
        let n = su.params.frame_pulses;
        let fs = config.sensor.laser_rate_hz;
        let ctx = &design.context;
        let choice = choose_bins(
            &ctx.tones,
            fs,
            su.params.rom_depth as u64,
            config.probe.osr,
            Some(su.params.bins),
        )
        .map_err(|source| ExperimentError::from(DesignError::pixel(origin, source)))?;
        let tone_bin = choice.tones.first().copied();
        let true_amp = tone_bin.and_then(|k| {
            ctx.tones
                .iter()
                .filter(|(f, _)| (f * su.params.rom_depth as f64 / fs).round() as u64 == k)
                .map(|(_, a)| a.abs() * 1000.0)
                .reduce(f64::max)
        });
        let noise_idx: Vec<usize> = (0..su.rom.bins.len())
            .filter(|&i| Some(su.rom.bin_indices[i]) != tone_bin)
            .collect();
        let tone_idx = tone_bin.and_then(|k| su.rom.bin_indices.iter().position(|&b| b == k));
        Ok(Ladder {
            design,
            su,
            source,
            n,
            fs,
            lsb_mm: config.sensor.tdc_lsb_mm(),
            true_amp,
            tone_idx,
            noise_idx,
            record: None,
            done: Vec::new(),
        })
    }

    fn origin(&self) -> &str {
        &self.design.origin
    }

    fn dsp_err(&self) -> impl Fn(tofprobe_dsp::DspError) -> ExperimentError + '_ {
        move |source| ExperimentError::from(DesignError::probe(self.origin(), source))
    }

    /// (tone amplitude, mean noise amplitude) of per-bin amplitudes in µm.
    fn score(&self, amps: &[f64]) -> (Option<f64>, f64) {
        let noise = if self.noise_idx.is_empty() {
            0.0
        } else {
            self.noise_idx.iter().map(|&i| amps[i]).sum::<f64>() / self.noise_idx.len() as f64
        };
        (self.tone_idx.map(|i| amps[i]), noise)
    }

    /// The detections (codes) and the held depth record (mm), as the pixel sees them: the
    /// one float front end's hold, nothing before the first detection; built once.
    fn ensure_record(&mut self) -> Result<(), ExperimentError> {
        if self.record.is_none() {
            let t0 = Instant::now();
            let detections = detection_record(&self.source, self.n);
            let depths = held_record(&self.source, &detections, 0.0)?;
            self.record = Some((detections, depths, t0.elapsed().as_secs_f64()));
        }
        Ok(())
    }

    /// The reading of `level` (measured once per ladder).
    fn reading(&mut self, level: Level) -> Result<Reading, ExperimentError> {
        if let Some(r) = self.done.iter().find(|r| r.level == level) {
            return Ok(*r);
        }
        let r = self.measure_level(level)?;
        self.done.push(r);
        Ok(r)
    }

    fn measure_level(&mut self, level: Level) -> Result<Reading, ExperimentError> {
        let reading = |seconds, extrapolated, (amplitude, noise): (Option<f64>, f64)| Reading {
            level,
            seconds,
            extrapolated,
            amplitude,
            noise,
        };
        let window = self.su.rom.window;
        match level {
            Level::ClosedForm => {
                let t = Instant::now();
                let score = self.closed_form()?;
                Ok(reading(t.elapsed().as_secs_f64(), false, score))
            }
            Level::FullDft => {
                self.ensure_record()?;
                let (_, depths, record_s) = self.record.as_ref().expect("built");
                let record_s = *record_s;
                let t = Instant::now();
                let spec = amplitude_spectrum(depths, window).map_err(|source| {
                    ExperimentError::from(DesignError::probe(&self.design.origin, source))
                })?;
                // ROM bin k is f = k·f_s/L; in the N-point DFT that is k·N/L (equal in
                // windowed mode, the nearest bin in periodic mode when L does not divide N).
                let amps: Vec<f64> =
                    dft_bins(&self.su.rom.bin_indices, self.n, self.su.params.rom_depth)
                        .iter()
                        .map(|&k| spec.get(k).copied().unwrap_or(0.0) * 1000.0)
                        .collect();
                let secs = record_s + t.elapsed().as_secs_f64();
                Ok(reading(secs, false, self.score(&amps)))
            }
            Level::SelectedDft => {
                self.ensure_record()?;
                let (_, depths, record_s) = self.record.as_ref().expect("built");
                let record_s = *record_s;
                let t = Instant::now();
                let bins = dft_bins(&self.su.rom.bin_indices, self.n, self.su.params.rom_depth);
                let dsp_err =
                    |source| ExperimentError::from(DesignError::probe(&self.design.origin, source));
                let mut sel = SelectedBins::new(self.n, &bins, window).map_err(dsp_err)?;
                for chunk in depths.chunks(1 << 16) {
                    sel.push(chunk).map_err(dsp_err)?;
                }
                let amps: Vec<f64> = sel
                    .amplitudes()
                    .map_err(dsp_err)?
                    .iter()
                    .map(|a| a * 1000.0)
                    .collect();
                let secs = record_s + t.elapsed().as_secs_f64();
                Ok(reading(secs, false, self.score(&amps)))
            }
            Level::FloatSd => {
                // The pixel's float twin: same ROM, the front end's hold, priming and
                // prefilter α = 2^−S on the same detections.
                self.ensure_record()?;
                let (detections, _, record_s) = self.record.as_ref().expect("built");
                let record_s = *record_s;
                let t = Instant::now();
                let p = &self.su.params;
                let alpha = 1.0 / f64::from(1u32 << p.shift);
                let zoom = f64::from(p.zoom);
                let lsb_mm = self.lsb_mm;
                let twin = detections
                    .iter()
                    .map(|c| c.map(|c| (f64::from(c) - zoom) * lsb_mm));
                let sums = probe_detections(&self.su.rom, twin, Some(alpha));
                let amps = amplitudes_um(&normalise(&self.su.rom, &sums, self.n, Some(alpha)));
                let secs = record_s + t.elapsed().as_secs_f64();
                Ok(reading(secs, false, self.score(&amps)))
            }
            Level::BitTrue => {
                // The bit-true transaction model streams the photon source itself.
                let t = Instant::now();
                let bt =
                    bit_true_spectrum(&self.su.params, &self.su.rom, &self.source, self.lsb_mm)
                        .map_err(|source| {
                            ExperimentError::from(DesignError::pixel(&self.design.origin, source))
                        })?;
                let amps: Vec<f64> = bt.bins.iter().map(|b| b.amplitude_um).collect();
                Ok(reading(t.elapsed().as_secs_f64(), false, self.score(&amps)))
            }
            Level::Cycle => {
                // Timed on a shortened frame (same registers, schedule and C cycles per
                // pulse) and scaled to N; its registers equal the transaction model's
                // after every pulse (crates/pixel/tests/it/equivalence.rs), so its
                // accuracy is the transaction model's.
                let bt = self.reading(Level::BitTrue)?;
                let short = self.short_frame();
                let rom = tofprobe_pixel::speed::synthetic_rom(short.rom_depth, short.registers());
                let cb = bench_cycle(&short, &rom, 1).map_err(|source| {
                    ExperimentError::from(DesignError::pixel(&self.design.origin, source))
                })?;
                let per_pulse = cb.seconds / short.frame_pulses as f64;
                Ok(reading(
                    per_pulse * self.n as f64,
                    true,
                    (bt.amplitude, bt.noise),
                ))
            }
            Level::Rtl => {
                let bt = self.reading(Level::BitTrue)?;
                let secs = self.verilator_seconds()?;
                Ok(reading(secs, true, (bt.amplitude, bt.noise)))
            }
            Level::FloatHaar => Err(ExperimentError::option(
                "level",
                level.name(),
                "a level of the Fourier ladder",
            )),
        }
    }

    /// The shortened frame the cycle-accurate and RTL levels are timed on.
    fn short_frame(&self) -> tofprobe_pixel::PixelParams {
        let mut short = self.su.params.clone();
        short.frame_pulses = CYCLE_FRAME.min(self.n);
        short.rom_depth = short.rom_depth.min(short.frame_pulses as usize);
        short
    }

    /// Closed form: eq. 12 with the window's N_eff and the 1NN hold, on the first-arrival
    /// mixture of signal and background (dsp::closed_form): its variance plus a²/12 for
    /// the noise, its valid rate ρ_v (a detection of either kind in the window) for the
    /// hold, and the gain ∂μ/∂t_s by which its mean follows the signal for the tone
    /// (pile-up: with background the first arrival follows a motion only when the signal
    /// photon came first). Without background this is σ² = σ_I² + a²/12, ρ_v = ρ_s and
    /// gain 1. The hold's noise factor F(ρ_v, ω) is averaged over the noise bins; the tone
    /// is scaled by g·|H(ρ_v, ω)|.
    fn closed_form(&self) -> Result<(Option<f64>, f64), ExperimentError> {
        let config = &self.design.document;
        // The ROM's window (rectangular in periodic mode), so every level weighs alike.
        let window = self.su.rom.window;
        let dsp_err = self.dsp_err();
        // The mixture, σ (a²/12 included) and ρ_v: one computation with the references'.
        let noise = crate::references::detection_noise(self.design).map_err(&dsp_err)?;
        let (mixture, sigma, rho) = (noise.mixture, noise.sigma_mm, noise.valid_rate);
        let n_eff = self.n as f64 * window.effective_length_factor();
        let omega = |i: usize| 2.0 * std::f64::consts::PI * self.su.rom.bins[i] / self.fs;
        let cf_noise = if self.noise_idx.is_empty() {
            noise_floor_mm(sigma, n_eff) * 1000.0
        } else {
            self.noise_idx
                .iter()
                .map(|&i| noise_floor_hold_mm(sigma, rho, omega(i), n_eff) * 1000.0)
                .sum::<f64>()
                / self.noise_idx.len() as f64
        };
        let gain = if config.sensor.background_rate > 0.0 {
            mixture_gain(&mixture).map_err(&dsp_err)?
        } else {
            1.0
        };
        let cf_amp = self.true_amp.map(|a| {
            let w = self.tone_idx.map(omega).unwrap_or(0.0);
            a * gain * hold_response_sq(rho, w).sqrt()
        });
        Ok((cf_amp, cf_noise))
    }

    /// The generated RTL co-simulated against the cycle model on a shortened frame of the
    /// scene's own detections; the bare harness time (no checking) scaled to N. A passing
    /// co-simulation is bit-exact, so its accuracy is the model's.
    fn verilator_seconds(&self) -> Result<f64, ExperimentError> {
        let short = self.short_frame();
        let mut stim = vec![None; short.frame_pulses as usize];
        self.source.fill_counted(0, &mut stim);
        let work =
            std::env::temp_dir().join(format!("tofprobe-tradeoff-rtl-{}", std::process::id()));
        let mut o = tofprobe_cosim::CosimOptions::new(&work);
        o.frames = 1;
        o.measure_bare = true;
        o.profile = tofprobe_cosim::BuildProfile::Speed;
        o.stimulus = Some(stim);
        // A scratch directory: removed after the run, and by an interrupt during it
        // (tofprobe_io::live).
        let live = tofprobe_io::live::register(tofprobe_io::live::Kind::Temporary, &work);
        let rep = tofprobe_cosim::cosim(&short, &o);
        let _ = std::fs::remove_dir_all(&work);
        drop(live);
        let rep = rep?;
        if !rep.pass {
            return Err(ExperimentError::Output {
                path: work,
                message: "Verilator co-simulation mismatched the model; run `tofprobe cosim`"
                    .into(),
            });
        }
        let secs = rep.bare_seconds.unwrap_or(rep.verilator_seconds);
        let per_pulse = secs / rep.pulses.max(1) as f64;
        Ok(per_pulse * self.n as f64)
    }
}

/// A level's name in the tables, marked where its time was extrapolated from a shorter
/// frame (the Fourier and the Haar ladders alike).
fn level_label(level: &impl std::fmt::Display, extrapolated: bool) -> String {
    if extrapolated {
        format!("{level} (extrapolated)")
    } else {
        level.to_string()
    }
}

/// The Markdown table of one scene.
pub fn markdown(r: &SceneResult) -> String {
    let mut t = Table::left([
        "level",
        "wall s per simulated s",
        "amplitude µm",
        "err vs DFT µm",
        "err vs true µm",
        "noise µm",
        "noise vs DFT",
    ]);
    let f = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_else(|| "–".into());
    for l in &r.levels {
        t.row([
            level_label(&l.level, l.extrapolated),
            format!("{:.3e}", l.seconds_per_sim_second),
            f(l.amplitude_um),
            f(l.amplitude_err_vs_dft_um),
            f(l.amplitude_err_vs_true_um),
            format!("{:.3}", l.noise_um),
            format!("{:+.1}%", l.noise_rel_err_vs_dft * 100.0),
        ]);
    }
    format!(
        "### {} (N = {}, true amplitude {})\n\n{t}",
        r.origin,
        r.pulses,
        r.true_amplitude_um
            .map(|a| format!("{a:.2} µm"))
            .unwrap_or_else(|| "–".into())
    )
}
