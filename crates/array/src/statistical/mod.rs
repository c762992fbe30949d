//! The array's statistical and closed-form levels (`[array] level`, docs/tradeoff.md
//! "Array levels"): each pixel's registers from their predicted distribution instead of
//! its pulses. The mean is the pixel's noise-free response through the pixel's float twin
//! (`dsp::sd::ProbeAccumulator`: the same ROM, hold, priming and prefilter as the
//! datapath, whose registers equal it within the prefilter's floor residues,
//! crates/pixel/tests/it/float_sd.rs): the twin is run once per design on a constant code
//! and on sin/cos at each scene frequency, and a pixel's mean is their combination with
//! its static code and its sines moved by the 1NN hold's H(ρ_v, ω) and the mixture's
//! gain (`dsp::closed_form`). The noise is Gaussian with the covariance of the held,
//! prefiltered code noise (σ²·F(ρ_v, ω)·|H_pre(ω)|², `closed_form::hold_noise_factor`,
//! `preprocess::prefilter_response`) seen through the ROM's ±1 sequences
//! ([`spectra::ProbeBands`]). "closed-form" is the mean alone.
//!
//! Determinism: a pixel's draws come from its own SplitMix64 stream seeded by
//! (`acquisition.seed`, r, c) ([`tofprobe_design::pixel_seed`]), so any tiling, thread
//! count or process gives the same registers. Not modelled (below 0.1 % of the noise for
//! the designs of the scenes): the prefilter's and the operand's floor residues (a
//! constant offset times Σ s_n), and the hold of a moving signal (a·ω/ρ ≪ σ).

pub mod auto;
pub mod pixel;
pub mod spectra;

use std::collections::HashMap;
use std::f64::consts::TAU;
use std::ops::Range;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use tofprobe_design::{ArrayLevel, DesignError, ResolvedDesign};
use tofprobe_dsp::closed_form::{hold_noise_factor, hold_response};
use tofprobe_dsp::sd::{ProbeAccumulator, ProbeRom, prefilter_response};
use tofprobe_io::watch::Watch;
use tofprobe_scene::splitmix::{SplitMix64, mix};
use tofprobe_scene::{MotionConfig, Scene};

use crate::error::ArrayError;
use crate::frame::Tile;
use pixel::{CodeStats, NoiseKey, PixelScene, code_stats, pixel_scene};
use spectra::{ProbeBands, cholesky};

/// Salt of the statistical draws' seeds (apart from the photon streams').
const SALT: u64 = 0x57A7_15E1_CA10_0000;

/// The per-design part of the statistical levels: the twin's responses and the probe's
/// band powers.
#[derive(Debug, Clone)]
pub struct StatisticalModel {
    level: ArrayLevel,
    pulses: u64,
    fs: f64,
    lsb_mm: f64,
    alpha: f64,
    zoom: f64,
    /// 2^G: a register word per code.
    word_scale: f64,
    /// The twin's register sums (codes) for a constant code of 1.
    constant: Vec<f64>,
    /// Per scene frequency: (Hz, sums for sin(ωn), sums for cos(ωn)).
    tones: Vec<(f64, Vec<f64>, Vec<f64>)>,
    bands: ProbeBands,
    /// Factor on the noise's standard deviation (1; the tests' deliberately wrong model).
    noise_scale: f64,
}

/// One pixel's predicted registers: mean (codes) and the lower Cholesky factor of their
/// covariance (codes), with its valid rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Moments {
    pub mean: Vec<f64>,
    pub chol: Vec<f64>,
    pub valid_rate: f64,
}

/// The twin's register sums over `n` pulses of the noise-free code sequence `x(n)`.
fn twin(rom: &ProbeRom, alpha: f64, n: u64, x: impl Fn(u64) -> f64) -> Vec<f64> {
    let mut acc = ProbeAccumulator::new(rom, Some(alpha));
    let mut buf = Vec::with_capacity(4096);
    let mut i = 0u64;
    while i < n {
        buf.clear();
        let k = (n - i).min(4096);
        buf.extend((i..i + k).map(|j| Some(x(j))));
        acc.push_detections(&buf);
        i += k;
    }
    acc.sums().into_iter().flat_map(|(i, q)| [i, q]).collect()
}

impl StatisticalModel {
    /// The model of `design` (an `[array]` Fourier design at a level other than bit-true)
    /// with its probe ROM.
    pub fn new(design: &ResolvedDesign, rom: &ProbeRom) -> Result<Self, ArrayError> {
        let a = design
            .array
            .as_ref()
            .ok_or_else(|| ArrayError::Shape(format!("`{}` has no [array]", design.origin)))?;
        let p = &design.pixel;
        let (n, fs) = (p.frame_pulses, design.sensor().laser_rate_hz);
        let alpha = 1.0 / f64::from(1u32 << p.shift.min(31));
        let mut freqs: Vec<f64> = Vec::new();
        for m in &design.document.scene.motions {
            if let MotionConfig::Sine { frequency_hz, .. }
            | MotionConfig::PlateMode { frequency_hz, .. } = m
                && !freqs.contains(frequency_hz)
            {
                freqs.push(*frequency_hz);
            }
        }
        let mut jobs: Vec<Box<dyn Fn() -> Vec<f64> + Sync>> =
            vec![Box::new(|| twin(rom, alpha, n, |_| 1.0))];
        for &f in &freqs {
            let w = TAU * f / fs;
            jobs.push(Box::new(move || {
                twin(rom, alpha, n, |j| (w * j as f64).sin())
            }));
            jobs.push(Box::new(move || {
                twin(rom, alpha, n, |j| (w * j as f64).cos())
            }));
        }
        let (mut sums, bands) = rayon::join(
            || jobs.par_iter().map(|j| j()).collect::<Vec<_>>(),
            || ProbeBands::new(rom),
        );
        let constant = sums.remove(0);
        let mut it = sums.into_iter();
        let tones = freqs
            .iter()
            .map(|&f| {
                (
                    f,
                    it.next().unwrap_or_default(),
                    it.next().unwrap_or_default(),
                )
            })
            .collect();
        Ok(StatisticalModel {
            level: a.level,
            pulses: n,
            fs,
            lsb_mm: design.sensor().tdc_lsb_mm(),
            alpha,
            zoom: f64::from(p.zoom),
            word_scale: f64::from(1u32 << p.register_frac_bits()),
            constant,
            tones,
            bands,
            noise_scale: 1.0,
        })
    }

    /// The same model with the noise's standard deviation times `scale` (a deliberately
    /// wrong covariance, for the tests that must see it fail).
    pub fn with_noise_scale(mut self, scale: f64) -> Self {
        self.noise_scale = scale;
        self
    }

    /// The same model at `level` (statistical or closed-form).
    pub fn at_level(mut self, level: ArrayLevel) -> Self {
        self.level = level;
        self
    }

    /// The lower Cholesky factor of the register covariance of a pixel of `stats`.
    fn noise_factor(&self, stats: &CodeStats) -> Vec<f64> {
        let r = self.bands.registers;
        if stats.valid_rate <= 0.0 || self.level == ArrayLevel::ClosedForm {
            return vec![0.0; r * r];
        }
        let psd: Vec<f64> = self
            .bands
            .omega
            .iter()
            .map(|&w| {
                stats.variance
                    * hold_noise_factor(stats.valid_rate, w)
                    * prefilter_response(self.alpha, w / TAU).norm_sqr()
            })
            .collect();
        let mut l = cholesky(&self.bands.covariance(self.pulses, &psd), r);
        l.iter_mut().for_each(|v| *v *= self.noise_scale);
        l
    }

    /// The mean registers (codes) of a pixel of scene `px` and code statistics `stats`.
    fn mean(&self, px: &PixelScene, stats: &CodeStats) -> Vec<f64> {
        let r = self.bands.registers;
        if stats.valid_rate <= 0.0 {
            return vec![0.0; r];
        }
        let mut m: Vec<f64> = self
            .constant
            .iter()
            .map(|v| v * (stats.mean_code - self.zoom))
            .collect();
        for &(f, z) in &px.sines {
            let Some((_, rs, rc)) = self.tones.iter().find(|(g, _, _)| *g == f) else {
                continue;
            };
            let h = hold_response(stats.valid_rate, TAU * f / self.fs);
            // a·sin(ωn + φ) held: |H|·a·sin(ωn + φ + arg H) = Re(·)·sin + Im(·)·cos.
            let y: Complex64 = z * h * stats.gain / self.lsb_mm;
            for (k, v) in m.iter_mut().enumerate() {
                *v += y.re * rs[k] + y.im * rc[k];
            }
        }
        m
    }

    /// The moments of pixel (r, c) (its scene `px`, its code statistics `stats`).
    pub fn moments(&self, px: &PixelScene, stats: &CodeStats) -> Moments {
        Moments {
            mean: self.mean(px, stats),
            chol: self.noise_factor(stats),
            valid_rate: stats.valid_rate,
        }
    }

    /// One draw of pixel (r, c)'s register words and detections (the mean alone at the
    /// closed-form level), from its own stream of `seed`.
    pub fn draw(&self, m: &Moments, seed: u64, r: usize, c: usize) -> (Vec<i64>, u64) {
        let k = m.mean.len();
        let mut rng = SplitMix64::new(mix(tofprobe_design::pixel_seed(seed, r, c) ^ SALT));
        let noisy = self.level == ArrayLevel::Statistical;
        let mut z = vec![0.0; k + 1];
        if noisy {
            gaussians(&mut rng, &mut z);
        }
        let words = (0..k)
            .map(|i| {
                let e: f64 = (0..=i).map(|j| m.chol[i * k + j] * z[j]).sum();
                ((m.mean[i] + e) * self.word_scale).round() as i64
            })
            .collect();
        let (n, p) = (self.pulses as f64, m.valid_rate);
        let sd = if noisy {
            (n * p * (1.0 - p)).sqrt()
        } else {
            0.0
        };
        let detections = (n * p + sd * z[k]).round().clamp(0.0, n) as u64;
        (words, detections)
    }

    /// Each pixel's scene and the code statistics and noise factor shared by its key, for
    /// the tile rows × cols of `design` (row-major).
    fn plan(
        &self,
        design: &ResolvedDesign,
        rows: &Range<usize>,
        cols: &Range<usize>,
    ) -> Result<TilePlan, ArrayError> {
        let scene = Scene::new(&design.document.scene)
            .map_err(|e| ArrayError::from(DesignError::scene(&design.origin, e)))?;
        let w = cols.len();
        let at = |i: usize| (rows.start + i / w, cols.start + i % w);
        let scenes: Vec<PixelScene> = (0..rows.len() * w)
            .into_par_iter()
            .map(|i| pixel_scene(design, &scene, at(i).0, at(i).1))
            .collect::<Result<_, _>>()?;
        // The code statistics and noise factor once per distinct (ρ_s, ρ_b, depth).
        let mut keys: Vec<NoiseKey> = Vec::new();
        let mut index: HashMap<NoiseKey, usize> = HashMap::new();
        for s in &scenes {
            index.entry(s.key).or_insert_with(|| {
                keys.push(s.key);
                keys.len() - 1
            });
        }
        let stats = keys
            .par_iter()
            .map(|&k| {
                let st = code_stats(design, k)?;
                Ok((st, self.noise_factor(&st)))
            })
            .collect::<Result<_, ArrayError>>()?;
        Ok(TilePlan {
            scenes,
            index,
            stats,
        })
    }

    /// Per pixel of the tile rows × cols (row-major): true where `[array] level = "auto"`
    /// runs it bit-true ([`auto::moves`] with `threshold`).
    pub fn auto_levels(
        &self,
        design: &ResolvedDesign,
        rows: Range<usize>,
        cols: Range<usize>,
        threshold: f64,
    ) -> Result<Vec<bool>, ArrayError> {
        let plan = self.plan(design, &rows, &cols)?;
        Ok(plan
            .scenes
            .par_iter()
            .map(|px| {
                let (st, chol) = &plan.stats[plan.index[&px.key]];
                auto::moves(self, px, st, chol, threshold)
            })
            .collect())
    }

    /// The registers of the tile rows × cols of `design`, each pixel counting its N pulses
    /// on `watch`.
    pub fn run_tile(
        &self,
        design: &ResolvedDesign,
        rows: Range<usize>,
        cols: Range<usize>,
        watch: &Watch,
    ) -> Result<Tile, ArrayError> {
        self.run_tile_except(design, rows, cols, &[], watch)
    }

    /// [`Self::run_tile`] drawing only the pixels where `skip` (row-major over the tile;
    /// empty: none skipped) is false; a skipped pixel's registers and detections are 0 and
    /// it counts no pulses (the auto level runs it bit-true).
    pub fn run_tile_except(
        &self,
        design: &ResolvedDesign,
        rows: Range<usize>,
        cols: Range<usize>,
        skip: &[bool],
        watch: &Watch,
    ) -> Result<Tile, ArrayError> {
        let plan = self.plan(design, &rows, &cols)?;
        let w = cols.len();
        let at = |i: usize| (rows.start + i / w, cols.start + i % w);
        let count = rows.len() * w;
        let seed = design.document.acquisition.seed;
        let k = self.bands.registers;
        let mut registers = vec![0i64; count * k];
        let mut detections = vec![0u64; count];
        registers
            .par_chunks_mut(k.max(1))
            .zip(detections.par_iter_mut())
            .enumerate()
            .try_for_each(|(i, (regs, det))| {
                if skip.get(i).copied().unwrap_or(false) {
                    return Ok(());
                }
                let px = &plan.scenes[i];
                let (st, chol) = &plan.stats[plan.index[&px.key]];
                let m = Moments {
                    mean: self.mean(px, st),
                    chol: chol.clone(),
                    valid_rate: st.valid_rate,
                };
                let (words, d) = self.draw(&m, seed, at(i).0, at(i).1);
                regs.copy_from_slice(&words);
                *det = d;
                if !watch.advance(self.pulses) {
                    return Err(ArrayError::Stopped);
                }
                Ok(())
            })?;
        Ok(Tile {
            rows,
            cols,
            registers_per_pixel: k,
            registers,
            detections,
        })
    }
}

/// A tile's pixels as the statistical model reads them: each pixel's scene, and per
/// distinct noise key its code statistics and noise factor.
struct TilePlan {
    scenes: Vec<PixelScene>,
    index: HashMap<NoiseKey, usize>,
    stats: Vec<(CodeStats, Vec<f64>)>,
}

/// Fills `out` with standard normal draws (Box–Muller on 53-bit uniforms in (0, 1]).
fn gaussians(rng: &mut SplitMix64, out: &mut [f64]) {
    let mut u = || ((rng.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64;
    for pair in out.chunks_mut(2) {
        let (a, b) = (u(), u());
        let rad = (-2.0 * a.ln()).sqrt();
        let (s, c) = (TAU * b).sin_cos();
        pair[0] = rad * c;
        if let Some(v) = pair.get_mut(1) {
            *v = rad * s;
        }
    }
}

/// The model of `design` at `level`, built once per process and design and shared by
/// every tile of a run (a run of T tiles — shards, Dask tasks, `tradeoff`'s runs — pays
/// for the ROM and the twin's runs once, not T times). Keyed by what the model reads
/// (the pixel, sensor, scene, bins and probe design; the level); the last
/// `SHARED_MODELS` are kept. Built outside the cache's lock, so a tile that waits on a
/// rayon pool never blocks another's build.
pub fn shared_model(
    design: &ResolvedDesign,
    level: ArrayLevel,
) -> Result<Arc<StatisticalModel>, ArrayError> {
    let d = &design.document;
    let key = serde_json::to_string(&(
        &design.pixel,
        &d.sensor,
        &d.scene,
        &design.bins,
        &design.probe_design,
        level,
    ))
    .map_err(|e| ArrayError::Shape(format!("the statistical model's key: {e}")))?;
    let found = |c: &Vec<(String, Arc<StatisticalModel>)>| {
        c.iter()
            .find(|(k, _)| *k == key)
            .map(|(_, m)| Arc::clone(m))
    };
    if let Some(m) = found(&CACHE.lock().unwrap_or_else(|e| e.into_inner())) {
        return Ok(m);
    }
    let rom = design.probe_rom()?.ok_or_else(|| {
        ArrayError::Shape(format!(
            "array.level = \"{level}\" needs a Fourier pixel (`{}` has no probe ROM)",
            design.origin
        ))
    })?;
    let model = Arc::new(StatisticalModel::new(design, &rom)?.at_level(level));
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if cache.len() >= SHARED_MODELS {
        cache.remove(0);
    }
    cache.push((key, Arc::clone(&model)));
    Ok(model)
}

/// The models [`shared_model`] keeps: (key, model), oldest first.
static CACHE: Mutex<Vec<(String, Arc<StatisticalModel>)>> = Mutex::new(Vec::new());

/// Forgets every model [`shared_model`] kept (a benchmark timing each level's whole cost,
/// its model's build included).
pub fn clear_shared_models() {
    CACHE.lock().unwrap_or_else(|e| e.into_inner()).clear();
}

/// Models kept by [`shared_model`] (a model is ≈ 2B·(1 + 2·tones) sums and the probe's
/// band powers: kilobytes).
const SHARED_MODELS: usize = 8;

/// The tile rows × cols of `design` at its `[array] level` (statistical or closed-form),
/// with the design's model shared across tiles ([`shared_model`]).
pub fn run_tile(
    design: &ResolvedDesign,
    rows: Range<usize>,
    cols: Range<usize>,
    watch: &Watch,
) -> Result<Tile, ArrayError> {
    let level = design
        .array
        .as_ref()
        .map_or(ArrayLevel::BitTrue, |a| a.level);
    shared_model(design, level)?.run_tile(design, rows, cols, watch)
}
