//! ΣΔ probing of every bin of a band in one streaming pass: the windowed-frame probe of
//! each bin k (A·w\[n\]·cos/sin(2πkn/N), modulated to ±1) is generated and accumulated
//! against the depth record x\[n\] in the same loop ([`super::simd::pairs`]), Y_k = Σ x\[n\]·b_k\[n\],
//! so 2·K bitstreams of N samples are never stored. Memory is the groups' states plus one
//! block of x: records stream in any chunking, and the sums do not depend on it (the
//! rotators re-anchor at absolute sample positions) nor on the thread count (groups are
//! independent; rayon splits over groups within each block).
//!
//! The readout is normalised like the chip's (`probing::normalise`):
//! Y_k = (I − jQ)·2/(N·G·A) / H_pre(f_k) (1/(N·G·A) at k = 0, where the real probe is not
//! split between ±k), so it reads the windowed DFT of the depth.

use super::config::ProbeConvention;
use super::probe::ProbeDesign;
use super::probing::prefilter_response;
use super::simd::Isa;
use super::simd::pairs::{
    Coeffs, LANES_F32, LANES_F32_AVX2, LANES_F32_AVX512, LANES_F64, LANES_F64_AVX2,
    LANES_F64_AVX512, Lane, LanePrecision, PairGroup,
};
use crate::error::DspError;
use crate::window::Window;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;

/// Samples per parallel block: x and A·w of a block (f64: 2 × 64 KiB) stay in L2 while
/// every group reads them.
pub const BLOCK: usize = 4096;

/// The groups, their width set by the precision and the instruction path.
#[derive(Debug, Clone)]
enum Groups {
    F64(Vec<PairGroup<f64, LANES_F64>>),
    F32(Vec<PairGroup<f32, LANES_F32>>),
    F64Avx2(Vec<PairGroup<f64, LANES_F64_AVX2>>),
    F32Avx2(Vec<PairGroup<f32, LANES_F32_AVX2>>),
    F64Avx512(Vec<PairGroup<f64, LANES_F64_AVX512>>),
    F32Avx512(Vec<PairGroup<f32, LANES_F32_AVX512>>),
}

/// Groups of `L` lanes (L/2 bins each) for `bins`.
fn groups<T: Lane, const L: usize>(
    bins: &[u64],
    frame: u64,
    order: usize,
    path: Isa,
) -> Vec<PairGroup<T, L>> {
    bins.chunks(L / 2)
        .map(|c| PairGroup::new(c, frame, order, path))
        .collect()
}

/// Streaming full-band prober: push the depth record in any chunking, read the sums.
#[derive(Debug, Clone)]
pub struct FullBandProber {
    coeffs: Coeffs,
    amplitude: f64,
    window: Window,
    /// The window's convention (the rotators always pair cos θ and sin θ, so Q starts at
    /// exactly 0 under either).
    convention: ProbeConvention,
    frame: u64,
    bins: Vec<u64>,
    precision: LanePrecision,
    path: Isa,
    groups: Groups,
    n: u64,
    aw: Vec<f64>,
}

impl FullBandProber {
    /// Probes `bins` (indices k, f_k = k·f_s/N, 0 ≤ k < N/(2·OSR)) of a windowed frame of
    /// `frame` pulses with the design's modulator, amplitude and window. The design's
    /// amplitude check (≤ 0.9 × the measured stable limit) is what keeps the lanes
    /// stable; a lane that still leaves the state bound is an error naming its bin.
    /// Runs on the fastest instruction path of this CPU ([`Isa::detect`]).
    pub fn new(
        design: &ProbeDesign,
        frame: u64,
        bins: &[u64],
        precision: LanePrecision,
    ) -> Result<Self, DspError> {
        Self::on_path(design, frame, bins, precision, Isa::current())
    }

    /// Like [`FullBandProber::new`] on a chosen instruction path (an error if this CPU
    /// cannot run it). Every path gives the same sums, bit for bit.
    pub fn on_path(
        design: &ProbeDesign,
        frame: u64,
        bins: &[u64],
        precision: LanePrecision,
        path: Isa,
    ) -> Result<Self, DspError> {
        let path = super::simd::require(path)?;
        let coeffs = Coeffs::new(&design.modulator.ss)?;
        if frame < 16 {
            return Err(DspError::out_of_range("frame_pulses", frame, ">= 16"));
        }
        if bins.is_empty() {
            return Err(DspError::out_of_range("bins", "[]", "at least one bin"));
        }
        let k_max = (frame as f64 / (2.0 * design.config.osr)).ceil() as u64;
        if let Some(&k) = bins.iter().find(|&&k| k >= k_max) {
            return Err(DspError::out_of_range(
                "bins",
                format!("k = {k}"),
                format!("0 <= k < {k_max}: below f_s/(2·OSR) for N = {frame}"),
            ));
        }
        let order = coeffs.order;
        let groups = match (precision, path) {
            (LanePrecision::F64, Isa::Scalar) => Groups::F64(groups(bins, frame, order, path)),
            (LanePrecision::F32, Isa::Scalar) => Groups::F32(groups(bins, frame, order, path)),
            (LanePrecision::F64, Isa::Avx2) => Groups::F64Avx2(groups(bins, frame, order, path)),
            (LanePrecision::F32, Isa::Avx2) => Groups::F32Avx2(groups(bins, frame, order, path)),
            (LanePrecision::F64, Isa::Avx512) => {
                Groups::F64Avx512(groups(bins, frame, order, path))
            }
            (LanePrecision::F32, Isa::Avx512) => {
                Groups::F32Avx512(groups(bins, frame, order, path))
            }
        };
        Ok(FullBandProber {
            coeffs,
            amplitude: design.config.amplitude,
            window: design.config.window,
            convention: design.config.convention,
            frame,
            bins: bins.to_vec(),
            precision,
            path,
            groups,
            n: 0,
            aw: Vec::with_capacity(BLOCK),
        })
    }

    /// Consumes the next samples of x (at most the frame in total).
    pub fn push(&mut self, x: &[f64]) -> Result<(), DspError> {
        if self.n + x.len() as u64 > self.frame {
            return Err(DspError::out_of_range(
                "samples pushed",
                self.n + x.len() as u64,
                format!("<= the frame of {} pulses", self.frame),
            ));
        }
        for block in x.chunks(BLOCK) {
            let n0 = self.n;
            let (frame, amp, window) = (self.frame as usize, self.amplitude, self.window);
            let convention = self.convention;
            self.aw.clear();
            self.aw.extend(
                (0..block.len())
                    .map(|t| amp * convention.window_value(window, n0 as usize + t, frame)),
            );
            let k = &self.coeffs;
            let narrow = |v: &[f64]| v.iter().map(|&v| v as f32).collect::<Vec<f32>>();
            match &mut self.groups {
                Groups::F64(g) => run_all(g, k, n0, &self.aw, block)?,
                Groups::F64Avx2(g) => run_all(g, k, n0, &self.aw, block)?,
                Groups::F32(g) => run_all(g, k, n0, &narrow(&self.aw), &narrow(block))?,
                Groups::F32Avx2(g) => run_all(g, k, n0, &narrow(&self.aw), &narrow(block))?,
                Groups::F64Avx512(g) => run_all(g, k, n0, &self.aw, block)?,
                Groups::F32Avx512(g) => run_all(g, k, n0, &narrow(&self.aw), &narrow(block))?,
            }
            self.n += block.len() as u64;
        }
        Ok(())
    }

    /// Samples consumed.
    pub fn samples(&self) -> u64 {
        self.n
    }

    /// Modulator steps run so far (two streams per bin).
    pub fn steps(&self) -> u64 {
        2 * self.bins.len() as u64 * self.n
    }

    /// The lanes' precision.
    pub fn precision(&self) -> LanePrecision {
        self.precision
    }

    /// The instruction path the lanes run on.
    pub fn path(&self) -> Isa {
        self.path
    }

    /// Raw (I, Q) sums per bin, in `bins` order.
    pub fn sums(&self) -> Vec<(f64, f64)> {
        match &self.groups {
            Groups::F64(g) => g.iter().flat_map(PairGroup::sums).collect(),
            Groups::F32(g) => g.iter().flat_map(PairGroup::sums).collect(),
            Groups::F64Avx2(g) => g.iter().flat_map(PairGroup::sums).collect(),
            Groups::F32Avx2(g) => g.iter().flat_map(PairGroup::sums).collect(),
            Groups::F64Avx512(g) => g.iter().flat_map(PairGroup::sums).collect(),
            Groups::F32Avx512(g) => g.iter().flat_map(PairGroup::sums).collect(),
        }
    }

    /// The normalised readout per bin (phasor in x's unit, see the module docs); `alpha`
    /// the prefilter whose gain is divided out, `None` for an unfiltered x.
    pub fn readout(&self, alpha: Option<f64>) -> Vec<Complex64> {
        let g = self.window.coherent_gain() * self.amplitude;
        self.bins
            .iter()
            .zip(self.sums())
            .map(|(&k, (i, q))| {
                let scale = bin_scale(k, self.frame) / g;
                Complex64::new(i, -q) * scale / gain(alpha, k, self.frame)
            })
            .collect()
    }

    /// Bin indices probed.
    pub fn bins(&self) -> &[u64] {
        &self.bins
    }
}

/// 2/N (1/N at DC): the one-sided amplitude scale of bin k of an N-point frame (bins stay
/// below the band edge, far from Nyquist).
pub fn bin_scale(k: u64, frame: u64) -> f64 {
    (if k == 0 { 1.0 } else { 2.0 }) / frame as f64
}

/// The prefilter response at bin k of an N-point frame (1 without a prefilter).
pub fn gain(alpha: Option<f64>, k: u64, frame: u64) -> Complex64 {
    alpha
        .map(|a| prefilter_response(a, k as f64 / frame as f64))
        .unwrap_or(Complex64::new(1.0, 0.0))
}

fn run_all<T: Lane, const L: usize>(
    groups: &mut [PairGroup<T, L>],
    k: &Coeffs,
    n0: u64,
    aw: &[T],
    x: &[T],
) -> Result<(), DspError> {
    groups
        .par_iter_mut()
        .try_for_each(|g| g.run(k, n0, aw, x, &mut []))
}
