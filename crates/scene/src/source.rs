//! The photon/TDC Monte Carlo (the paper's Sec. 6.1), streamed in chunks and deterministic
//! whatever the chunking or thread count.
//!
//! Semantics, per laser pulse n (fired at t = n / f_s):
//! - **Signal**: with probability ρ_s a signal photon arrives at 2δ(t)/c + N(0, σ_I), i.e.
//!   at `δ(t)/MM_PER_PS + σ_I·z` ps (z standard normal). With ρ_s = 1 no Bernoulli draw is
//!   made.
//! - **Background**: Poisson(ρ_b) arrivals per pulse, uniform over the timing window. Only
//!   the earliest one can matter, so it is drawn directly: the arrivals form a Poisson
//!   process of rate ρ_b / W over the window, whose first arrival is exponential; with one
//!   uniform u ∈ (0, 1] it lies at −ln(u)·W/ρ_b and is inside the window iff u > e^(−ρ_b)
//!   (probability 1 − e^(−ρ_b) of at least one arrival). With ρ_b = 0 nothing is drawn.
//! - **Window and pile-up**: arrivals before `window_start` or at/after `window_start +
//!   window_length` are not detected; of the rest, the earliest wins (first-photon pile-up).
//! - **TDC**: `code = floor((t − window_start) / lsb)`, 0 ≤ code < `tdc_codes()`; a pulse
//!   with no arrival in the window is `None`.
//!
//! Two kernels draw these laws. [`PhotonSource::fill`] (every command's path) is the batched
//! kernel of crates/scene/src/batch.rs: a block at a time, in vectorised passes (lanes of
//! xoshiro256++, a split ziggurat normal, branch-free selects; AVX-512 and AVX2 copies
//! chosen at run time, bit-identical to the baseline copy). [`PhotonSource::fill_reference`]
//! is the original per-pulse kernel, kept as the naive reference that judges it (the
//! scene crate's KS tests, tests/it/ks.rs) and that `tofprobe bench scene` times beside it.
//! The two draw the same laws from unrelated streams, so their seeded records differ.
//!
//! Determinism: pulses are grouped in fixed blocks of [`BLOCK_PULSES`]; block b draws from
//! its own generators seeded by a hash of (seed, b), and the motion δ(t) is evaluated from
//! the block's start. Any request is served by regenerating the blocks it touches from
//! their start, so every chunking and every thread count gives the same stream.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use crate::MM_PER_PS;
use crate::batch::{self, Block, Params, Scratch, Slot};
use crate::depths::Depths;
use crate::error::SceneError;
use crate::scene::Scene;
use crate::sensor::SensorConfig;
use crate::splitmix::mix;

/// Picoseconds of round-trip time of flight per mm of depth.
const PS_PER_MM: f64 = 1.0 / MM_PER_PS;

/// Pulses per deterministic block (the unit of seeding).
pub const BLOCK_PULSES: usize = 4096;

/// Counts from one fill, for summaries.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FillCounts {
    /// Pulses with a detection.
    pub detections: u64,
    /// Detections won by a background photon (it arrived before the signal photon, or
    /// the pulse had no signal photon in the window).
    pub background_wins: u64,
}

impl std::ops::AddAssign for FillCounts {
    fn add_assign(&mut self, o: FillCounts) {
        self.detections += o.detections;
        self.background_wins += o.background_wins;
    }
}

/// The photon source: a validated sensor and scene, and a seed.
#[derive(Debug, Clone)]
pub struct PhotonSource {
    scene: Scene,
    seed: u64,
    period_s: f64,
    jitter_ps: f64,
    lsb_ps: f64,
    window_start_ps: f64,
    window_length_ps: f64,
    codes: u32,
    signal_rate: f64,
    /// ρ_s as a threshold on 53-bit uniform integers.
    signal_threshold: u64,
    background_rate: f64,
    /// e^(−ρ_b): a uniform u ∈ (0, 1] above it means at least one background arrival.
    no_background: f64,
    /// The batched kernel's parameters (code units) and depth evaluation.
    params: Params,
    depths: Depths,
}

impl PhotonSource {
    /// Validates the sensor, the scene against the sensor (Nyquist, the window containing
    /// the scene's depth range), and builds the source.
    pub fn new(
        sensor: &SensorConfig,
        scene: &Scene,
        seed: u64,
    ) -> Result<PhotonSource, SceneError> {
        sensor.validate()?;
        if let Some((i, kind)) = scene.spatial_motion() {
            return Err(SceneError::out_of_range(
                format!("scene.motion[{i}].kind"),
                format!("\"{kind}\""),
                "a motion that does not depend on position (sine, square, disk, step, ramp, \
                 impulse), or an [array] section that places pixels on the scene plane",
            ));
        }
        check_scene(sensor, scene)?;
        let period_s = 1.0 / sensor.laser_rate_hz;
        let lsb = sensor.tdc_lsb_ps;
        let params = Params {
            period_s,
            code_per_mm: PS_PER_MM / lsb,
            start: sensor.window_start_ps / lsb,
            length: sensor.window_length_ps / lsb,
            sigma: sensor.jitter_ps / lsb,
            signal_threshold: (sensor.signal_rate * (1u64 << 53) as f64) as u64,
            signal_rate: sensor.signal_rate,
            background_rate: sensor.background_rate,
            no_background: (-sensor.background_rate).exp(),
        };
        Ok(PhotonSource {
            params,
            depths: Depths::new(scene, period_s),
            scene: scene.clone(),
            seed,
            period_s: 1.0 / sensor.laser_rate_hz,
            jitter_ps: sensor.jitter_ps,
            lsb_ps: sensor.tdc_lsb_ps,
            window_start_ps: sensor.window_start_ps,
            window_length_ps: sensor.window_length_ps,
            codes: sensor.tdc_codes(),
            signal_rate: sensor.signal_rate,
            signal_threshold: (sensor.signal_rate * (1u64 << 53) as f64) as u64,
            background_rate: sensor.background_rate,
            no_background: (-sensor.background_rate).exp(),
        })
    }

    /// The scene this source samples.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Number of TDC codes in the window.
    pub fn tdc_codes(&self) -> u32 {
        self.codes
    }

    /// Absolute depth (mm) of the centre of a TDC code's bin.
    pub fn code_to_depth_mm(&self, code: u32) -> f64 {
        (self.window_start_ps + (f64::from(code) + 0.5) * self.lsb_ps) * MM_PER_PS
    }

    /// Writes the detections of pulses `first_pulse ..` into `out`.
    ///
    /// Cost: a request that starts mid-block regenerates that block's first pulses (at most
    /// [`BLOCK_PULSES`] − 1), so stream in chunks that are multiples of [`BLOCK_PULSES`]
    /// (or at least much longer than it) for full speed.
    pub fn fill(&self, first_pulse: u64, out: &mut [Option<u32>]) {
        self.fill_counted(first_pulse, out);
    }

    /// Like [`Self::fill`], and returns how many detections there were and how many of them
    /// a background photon won. The batched kernel (crates/scene/src/batch.rs): the same
    /// laws as [`Self::fill_counted_reference`], other draws.
    pub fn fill_counted(&self, first_pulse: u64, out: &mut [Option<u32>]) -> FillCounts {
        self.fill_counted_slots(first_pulse, out)
    }

    /// Like [`Self::fill`] in the compact form: pulse i's TDC code, or [`NO_DETECTION`](crate::NO_DETECTION)
    /// (4 bytes a pulse instead of 8; what the pixel's drivers read directly). The same
    /// pulses as [`Self::fill`].
    pub fn fill_codes(&self, first_pulse: u64, out: &mut [u32]) {
        self.fill_counted_slots(first_pulse, out);
    }

    /// Like [`Self::fill_codes`], with the counts of [`Self::fill_counted`].
    pub fn fill_counted_codes(&self, first_pulse: u64, out: &mut [u32]) -> FillCounts {
        self.fill_counted_slots(first_pulse, out)
    }

    /// The batched kernel into either output form.
    fn fill_counted_slots<O: Slot>(&self, first_pulse: u64, out: &mut [O]) -> FillCounts {
        // The kernel's block buffers, kept per thread: a fresh set per call would allocate
        // and zero ≈ 130 kB each time (a tenth of an array run's time in 16 k-pulse chunks).
        thread_local! {
            static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
        }
        SCRATCH.with_borrow_mut(|sc| self.fill_with(sc, first_pulse, out))
    }

    /// [`Self::fill_counted_slots`] with the kernel's buffers `sc` (their contents in and
    /// out do not matter: every block overwrites what it reads).
    fn fill_with<O: Slot>(&self, sc: &mut Scratch, first_pulse: u64, out: &mut [O]) -> FillCounts {
        let mut counts = FillCounts::default();
        let last = self.codes - 1;
        let mut done = 0usize;
        while done < out.len() {
            let pulse = first_pulse + done as u64;
            let block = pulse / BLOCK_PULSES as u64;
            let offset = (pulse % BLOCK_PULSES as u64) as usize;
            let take = (BLOCK_PULSES - offset).min(out.len() - done);
            // A request starting mid-block regenerates the block's prefix: the result does
            // not depend on where chunks start.
            let (d, w) = batch::generate(
                &self.params,
                &self.scene,
                &self.depths,
                Block {
                    seed: batch_seed(self.seed, block),
                    first_pulse: block * BLOCK_PULSES as u64,
                    n: offset + take,
                },
                sc,
                (offset, last, &mut out[done..done + take]),
            );
            counts += FillCounts {
                detections: d,
                background_wins: w,
            };
            done += take;
        }
        counts
    }

    /// The per-pulse reference kernel (one pulse at a time, the draws of the original
    /// Monte Carlo): the naive path the batched [`Self::fill`] is judged against.
    pub fn fill_reference(&self, first_pulse: u64, out: &mut [Option<u32>]) {
        self.fill_counted_reference(first_pulse, out);
    }

    /// Like [`Self::fill_reference`], with the counts of [`Self::fill_counted`].
    pub fn fill_counted_reference(&self, first_pulse: u64, out: &mut [Option<u32>]) -> FillCounts {
        let mut counts = FillCounts::default();
        let mut depths = vec![0.0; BLOCK_PULSES];
        let mut scratch: Vec<Option<u32>> = Vec::new();
        let mut labels: Vec<bool> = Vec::new();
        let mut done = 0usize;
        while done < out.len() {
            let pulse = first_pulse + done as u64;
            let block = pulse / BLOCK_PULSES as u64;
            let offset = (pulse % BLOCK_PULSES as u64) as usize;
            let take = (BLOCK_PULSES - offset).min(out.len() - done);
            if offset == 0 {
                counts += self.generate(block, &mut depths[..take], &mut out[done..done + take]);
            } else {
                // A request starting mid-block: regenerate the block's prefix and keep the
                // tail, so the result does not depend on where chunks start.
                scratch.resize(offset + take, None);
                labels.resize(offset + take, false);
                self.generate_labelled(
                    block,
                    &mut depths[..offset + take],
                    &mut scratch,
                    Some(&mut labels),
                );
                out[done..done + take].copy_from_slice(&scratch[offset..]);
                counts += FillCounts {
                    detections: scratch[offset..].iter().filter(|o| o.is_some()).count() as u64,
                    background_wins: labels[offset..].iter().filter(|&&b| b).count() as u64,
                };
            }
            done += take;
        }
        counts
    }

    /// The same as [`Self::fill`], split over rayon's current thread pool in whole blocks.
    pub fn par_fill(&self, first_pulse: u64, out: &mut [Option<u32>]) {
        let misalign = (first_pulse % BLOCK_PULSES as u64) as usize;
        let head = if misalign == 0 {
            0
        } else {
            (BLOCK_PULSES - misalign).min(out.len())
        };
        let (a, b) = out.split_at_mut(head);
        self.fill(first_pulse, a);
        let per_task = 16 * BLOCK_PULSES;
        let start = first_pulse + head as u64;
        b.par_chunks_mut(per_task)
            .enumerate()
            .for_each(|(i, c)| self.fill(start + (i * per_task) as u64, c));
    }

    /// Streams pulses 0 .. `pulses` through `f(first_pulse, detections)` in chunks of
    /// `chunk` pulses (the last one shorter), never holding the whole record.
    pub fn for_each_chunk(
        &self,
        pulses: u64,
        chunk: usize,
        mut f: impl FnMut(u64, &[Option<u32>]),
    ) {
        let chunk = chunk.max(1);
        let mut buf = vec![None; chunk];
        let mut first = 0u64;
        while first < pulses {
            let n = ((pulses - first).min(chunk as u64)) as usize;
            self.fill(first, &mut buf[..n]);
            f(first, &buf[..n]);
            first += n as u64;
        }
    }

    /// The whole record of pulses 0 .. `pulses` in memory (for small records or when a full
    /// DFT is asked), generated in parallel.
    pub fn record(&self, pulses: u64) -> Vec<Option<u32>> {
        let mut out = vec![None; pulses as usize];
        self.par_fill(0, &mut out);
        out
    }

    /// Generates pulses 0 .. out.len() of `block` (out.len() ≤ BLOCK_PULSES).
    fn generate(&self, block: u64, depths: &mut [f64], out: &mut [Option<u32>]) -> FillCounts {
        self.generate_labelled(block, depths, out, None)
    }

    fn generate_labelled(
        &self,
        block: u64,
        depths: &mut [f64],
        out: &mut [Option<u32>],
        labels: Option<&mut [bool]>,
    ) -> FillCounts {
        debug_assert!(out.len() <= BLOCK_PULSES && depths.len() == out.len());
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(block_seed(self.seed, block));
        self.scene
            .fill_depths_mm(block * BLOCK_PULSES as u64, self.period_s, depths);
        let bern = self.signal_rate < 1.0;
        let bg = self.background_rate > 0.0;
        // Monomorphised kernels: the common cases skip the draws they do not need.
        match (bern, bg) {
            (false, false) => self.kernel::<false, false>(&mut rng, depths, out, labels),
            (true, false) => self.kernel::<true, false>(&mut rng, depths, out, labels),
            (false, true) => self.kernel::<false, true>(&mut rng, depths, out, labels),
            (true, true) => self.kernel::<true, true>(&mut rng, depths, out, labels),
        }
    }

    #[inline(always)]
    fn kernel<const BERN: bool, const BG: bool>(
        &self,
        rng: &mut Xoshiro256PlusPlus,
        depths: &[f64],
        out: &mut [Option<u32>],
        mut labels: Option<&mut [bool]>,
    ) -> FillCounts {
        let w = self.window_length_ps;
        let ws = self.window_start_ps;
        let sigma = self.jitter_ps;
        let lsb = self.lsb_ps;
        let last = self.codes - 1;
        let bg_scale = if BG { w / self.background_rate } else { 0.0 };
        let mut counts = FillCounts::default();
        for (i, (o, &d)) in out.iter_mut().zip(depths.iter()).enumerate() {
            let mut best = f64::INFINITY;
            let signal = if BERN {
                (rng.next_u64() >> 11) < self.signal_threshold
            } else {
                true
            };
            if signal {
                let z: f64 = StandardNormal.sample(rng);
                // δ/MM_PER_PS as a multiply by the reciprocal (≤ 1 ulp apart, ~1e-15 ps).
                let x = d * PS_PER_MM + sigma * z - ws;
                if (0.0..w).contains(&x) {
                    best = x;
                }
            }
            let mut from_bg = false;
            if BG {
                // u ∈ (0, 1]: never 0, so ln(u) is finite.
                let u = ((rng.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64);
                if u > self.no_background {
                    let tb = -u.ln() * bg_scale;
                    if tb < best {
                        best = tb;
                        from_bg = true;
                    }
                }
            }
            *o = if best < w {
                counts.detections += 1;
                counts.background_wins += u64::from(from_bg);
                Some(((best / lsb) as u32).min(last))
            } else {
                None
            };
            if let Some(l) = labels.as_deref_mut() {
                l[i] = from_bg;
            }
        }
        counts
    }
}

/// Checks a sensor and a scene against each other without building a source: the
/// sensor, the Nyquist rate of the scene's tones and the window against the scene's depth
/// range (for a spatial scene, its bound over the whole plane).
pub fn check_scene(sensor: &SensorConfig, scene: &Scene) -> Result<(), SceneError> {
    sensor.validate()?;
    scene.check_nyquist(sensor.laser_rate_hz)?;
    check_window(sensor, scene)
}

/// The window must contain the scene's whole depth range, or the signal would be lost
/// for part (or all) of the record.
pub(crate) fn check_window(sensor: &SensorConfig, scene: &Scene) -> Result<(), SceneError> {
    let (lo, hi) = scene.depth_range_mm();
    let (ws, we) = (sensor.window_start_mm(), sensor.window_end_mm());
    if lo >= ws && hi < we {
        return Ok(());
    }
    // Depths in µm resolution: float noise (0.09999999999999432) helps nobody.
    let r = |x: f64| {
        let t = format!("{x:.4}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let depth = scene.static_depth_mm();
    let (below, above) = (depth - lo, hi - depth);
    let allowed = if below + above < we - ws {
        format!(
            "{} <= scene.depth_mm < {} (the motion reaches {} mm below and {} mm above it), \
             or a window with window_start_ps <= {:.1} and window_start_ps + window_length_ps >= {:.1}",
            r(ws + below),
            r(we - above),
            r(below),
            r(above),
            (lo / MM_PER_PS).max(0.0),
            hi / MM_PER_PS + sensor.tdc_lsb_ps
        )
    } else {
        format!(
            "a motion narrower than the window: it spans {} mm, the window {} mm \
             (smaller scene.motion amplitude_mm, or sensor.window_length_ps > {:.1})",
            r(hi - lo),
            r(we - ws),
            (hi - lo) / MM_PER_PS
        )
    };
    Err(SceneError::WindowExcludesDepth {
        depth_mm: depth,
        span: format!(
            "with its motion spans {}..{} mm, which lies outside the timing window [{}, {}) mm \
             (sensor.window_start_ps = {}, sensor.window_length_ps = {})",
            r(lo),
            r(hi),
            r(ws),
            r(we),
            sensor.window_start_ps,
            sensor.window_length_ps
        ),
        allowed,
    })
}

/// The seed of a block's batched streams: unrelated to the reference's stream of the same
/// block (a further mix), so the two paths are independent samples of one law.
fn batch_seed(seed: u64, block: u64) -> u64 {
    mix(block_seed(seed, block) ^ 0x6A09_E667_F3BC_C909)
}

/// The counter-based seed of a block: distinct (seed, block) pairs give unrelated streams.
fn block_seed(seed: u64, block: u64) -> u64 {
    mix(mix(seed) ^ block.wrapping_mul(0xD1B5_4A32_D192_ED03))
}
