//! The full-band probe kernel: many I/Q modulator pairs stepped together in a
//! structure-of-arrays loop the compiler vectorises (SSE2 on the x86-64 baseline; copies for
//! AVX2 with twice the lanes and for AVX-512 with four times, chosen at run time,
//! [`super::Isa`]; the loop itself is `super::kernel`), each lane's ±1 output
//! accumulated against the shared depth record x\[n\] in the same pass, so no bitstream is
//! ever stored. The lane count only groups independent lanes: a lane's arithmetic, hence
//! its bits and sums, is the same at every width.
//!
//! Of a group's L lanes, lane p < L/2 is the I stream of its bin p and lane p + L/2 the Q
//! stream: their inputs are A·w\[n\]·cos θ and A·w\[n\]·sin θ with θ = 2πkn/N, so one complex
//! rotation per pair and step ((c, s) ← (c·cos d − s·sin d, s·cos d + c·sin d), two vector
//! products of one half of the lanes by the other) feeds both lanes. The rotators are re-anchored from the exact integer phase (k·n mod N) at every
//! multiple of [`ANCHOR`] samples, so rounding never accumulates beyond one anchor span and
//! the input at sample n depends on n alone, whatever the chunking.
//!
//! Two precisions, chosen explicitly by the caller ([`LanePrecision`], [`super`]):
//! - `F64`: bit-exact with the scalar reference [`crate::sd::Modulator::run`] fed the same
//!   input. Same operations in the same order; the only rewrites are exact ones: products
//!   with the CIFB's unit coefficients dropped (1·x = x), ±b₂ and ±x formed by flipping the
//!   sign bit, and the quantiser's `y ≥ 0` read from the sign bit of y (they differ only at
//!   y = −0, which needs the last state to be −0: it never is, since every state update
//!   ends by adding ±b₂ ≠ 0, and x + (−x) rounds to +0).
//! - `F32`: the same loop in f32 with four lanes per SSE2 register, ≈ 1.9× the f64 rate.
//!   Its bitstreams are *not* the f64 ones (a state differing in the last place flips a
//!   decision sooner or later, and the loop is chaotic), but they are valid ΣΔ bitstreams
//!   of the same input: f32 rounding adds white noise ≈ 10⁻⁷ of full scale at the first
//!   integrator, far below the shaped quantisation noise. The accumulator is f32 within
//!   one anchor span (≤ 1024 terms) and f64 across spans. Its effect on the readout is
//!   measured against the f64 path by the tests and by `tofprobe bench fullband`.

// The lane loops index several same-length arrays in lockstep (`x[l]`, `x[l ^ h]`): the
// plain index form is what the vectoriser and the reader both follow best.
#![allow(clippy::needless_range_loop)]

use super::Isa;
pub(crate) use super::Lane;
use super::kernel::{Consts, Span, step_on};
pub use super::{
    LANES_F32, LANES_F32_AVX2, LANES_F32_AVX512, LANES_F64, LANES_F64_AVX2, LANES_F64_AVX512,
    LanePrecision,
};
use crate::error::DspError;
use crate::sd::STATE_BOUND;
use crate::sd::realize::StateSpace;
use std::f64::consts::PI;

/// Samples between exact re-anchorings of the rotators (and f32 accumulator flushes).
pub const ANCHOR: u64 = 1024;
/// The CIFB state update the kernel needs, checked once: unit diagonal and sub-diagonal,
/// optional resonator entries above the diagonal, the quantiser reading the last state
/// with unit weight and the input with unit weight (what `StateSpace::from_cifb` builds).
#[derive(Debug, Clone)]
pub(crate) struct Coeffs {
    pub order: usize,
    pub sup: Vec<f64>,
    pub b1: Vec<f64>,
    pub b2: Vec<f64>,
    pub resonators: bool,
}

impl Coeffs {
    pub fn new(ss: &StateSpace) -> Result<Self, DspError> {
        let n = ss.order;
        let bad = |what: &str| {
            Err(DspError::out_of_range(
                "state space",
                what,
                "a CIFB realisation (StateSpace::from_cifb) of order 1..=6",
            ))
        };
        if !(1..=6).contains(&n) {
            return bad("order outside 1..=6");
        }
        for r in 0..n {
            for j in 0..n {
                let v = ss.a[r * n + j];
                let ok = match j as isize - r as isize {
                    0 | -1 => v == 1.0,
                    1 => true,
                    _ => v == 0.0,
                };
                if !ok {
                    return bad("A is not unit-diagonal, unit-subdiagonal tridiagonal");
                }
            }
        }
        if ss.d1 != 1.0 || ss.c[n - 1] != 1.0 || ss.c[..n - 1].iter().any(|&c| c != 0.0) {
            return bad("the quantiser does not read u + x[last]");
        }
        if ss.b2.iter().any(|&b| b == 0.0 || !b.is_finite()) {
            return bad("a zero or non-finite feedback coefficient");
        }
        let sup: Vec<f64> = (0..n)
            .map(|r| if r + 1 < n { ss.a[r * n + r + 1] } else { 0.0 })
            .collect();
        Ok(Coeffs {
            order: n,
            resonators: sup.iter().any(|&v| v != 0.0),
            sup,
            b1: ss.b1.clone(),
            b2: ss.b2.clone(),
        })
    }
}

/// One group of `L` lanes (L/2 bins): states, rotators and accumulators.
#[derive(Debug, Clone)]
pub(crate) struct PairGroup<T: Lane, const L: usize> {
    /// Bin index of each lane (lanes p and p + L/2 share a bin).
    bins: [u64; L],
    /// Live bins (the last group may be partly idle: bin 0 lanes, never read).
    pub live: usize,
    period: u64,
    states: Vec<[T; L]>,
    rot: [T; L],
    cd: [T; L],
    /// −sin d on I lanes, +sin d on Q lanes.
    sdm: [T; L],
    /// Accumulator within the current anchor span.
    acc: [T; L],
    /// Accumulated spans (f32 lanes only).
    total: [f64; L],
    /// The instruction path `run` steps on (same bits on either).
    path: Isa,
}

impl<T: Lane, const L: usize> PairGroup<T, L> {
    /// A group at rest for `bins` (at most L/2), frame length `period` (the window's and
    /// the bins' N), stepping on `path` (the baseline where the CPU lacks it).
    pub fn new(bins: &[u64], period: u64, order: usize, path: Isa) -> Self {
        let h = L / 2;
        let mut lane_bins = [0u64; L];
        for (l, b) in lane_bins.iter_mut().enumerate() {
            *b = bins.get(l % h).copied().unwrap_or(0) % period;
        }
        let mut cd = [T::default(); L];
        let mut sdm = [T::default(); L];
        for l in 0..L {
            let d = lane_bins[l] as f64 * (2.0 * PI / period as f64);
            cd[l] = T::of(d.cos());
            sdm[l] = T::of(if l < h { -d.sin() } else { d.sin() });
        }
        PairGroup {
            bins: lane_bins,
            live: bins.len().min(h),
            period,
            states: vec![[T::default(); L]; order],
            rot: [T::default(); L],
            cd,
            sdm,
            acc: [T::default(); L],
            total: [0.0; L],
            path,
        }
    }

    /// Sets the rotators to the exact phase of sample `n`.
    fn anchor(&mut self, n: u64) {
        let l = self.period;
        for p in 0..L / 2 {
            let (k, m) = (self.bins[p], n % l);
            // k·m mod l, in u64 where the product fits (always, below 2^32 pulses).
            let km = match k.checked_mul(m) {
                Some(v) => v % l,
                None => ((k as u128 * m as u128) % l as u128) as u64,
            };
            let ph = km as f64 * (2.0 * PI / l as f64);
            self.rot[p] = T::of(ph.cos());
            self.rot[p + L / 2] = T::of(ph.sin());
        }
    }

    /// The lane of live bin `p`'s I (`quadrature` false) or Q stream.
    pub fn lane(p: usize, quadrature: bool) -> usize {
        p + if quadrature { L / 2 } else { 0 }
    }

    /// The inputs `u[t][lane]` the kernel computes for samples n0 .. n0 + aw.len() of a run
    /// starting at n0 (the rotator as `run` leaves it at n0 when n0 is on an anchor):
    /// the same operations as the kernel's, for the reference check and the tests.
    pub fn inputs(&self, n0: u64, aw: &[T]) -> Vec<[T; L]> {
        let mut g = self.clone();
        let mut out = Vec::with_capacity(aw.len());
        for (t, &a) in aw.iter().enumerate() {
            let n = n0 + t as u64;
            if n.is_multiple_of(ANCHOR) {
                g.anchor(n);
            }
            out.push(g.rot.map(|r| a * r));
            let mut nr = [T::default(); L];
            for l in 0..L {
                nr[l] = g.rot[l] * g.cd[l] + g.rot[l ^ (L / 2)] * g.sdm[l];
            }
            g.rot = nr;
        }
        out
    }

    /// (I, Q) sums of the live bins so far.
    pub fn sums(&self) -> Vec<(f64, f64)> {
        let lane = |l: usize| {
            if T::FLUSH {
                self.total[l] + self.acc[l].wide()
            } else {
                self.acc[l].wide()
            }
        };
        (0..self.live)
            .map(|p| (lane(Self::lane(p, false)), lane(Self::lane(p, true))))
            .collect()
    }

    /// Runs samples n0 .. n0 + x.len() with window×amplitude `aw` and depths `x` (the same
    /// length). With `trace` non-empty, word t gets bit l set when lane l output +1.
    pub fn run(
        &mut self,
        k: &Coeffs,
        n0: u64,
        aw: &[T],
        x: &[T],
        trace: &mut [u32],
    ) -> Result<(), DspError> {
        match (k.order, k.resonators) {
            (1, _) => self.run_n::<1, false>(k, n0, aw, x, trace),
            (2, _) => self.run_n::<2, false>(k, n0, aw, x, trace),
            (3, false) => self.run_n::<3, false>(k, n0, aw, x, trace),
            (3, true) => self.run_n::<3, true>(k, n0, aw, x, trace),
            (4, false) => self.run_n::<4, false>(k, n0, aw, x, trace),
            (4, true) => self.run_n::<4, true>(k, n0, aw, x, trace),
            (5, false) => self.run_n::<5, false>(k, n0, aw, x, trace),
            (5, true) => self.run_n::<5, true>(k, n0, aw, x, trace),
            (6, false) => self.run_n::<6, false>(k, n0, aw, x, trace),
            _ => self.run_n::<6, true>(k, n0, aw, x, trace),
        }
    }

    fn run_n<const N: usize, const RES: bool>(
        &mut self,
        k: &Coeffs,
        n0: u64,
        aw: &[T],
        x: &[T],
        trace: &mut [u32],
    ) -> Result<(), DspError> {
        let mut s = [[T::default(); L]; N];
        for (d, row) in s.iter_mut().zip(&self.states) {
            *d = *row;
        }
        let (mut sup, mut b1, mut b2) = ([T::default(); N], [T::default(); N], [T::default(); N]);
        for r in 0..N {
            sup[r] = T::of(k.sup[r]);
            b1[r] = T::of(k.b1[r]);
            b2[r] = T::of(k.b2[r]);
        }
        let mut done = 0usize;
        while done < x.len() {
            let n = n0 + done as u64;
            if n.is_multiple_of(ANCHOR) {
                self.anchor(n);
            }
            let span = ((ANCHOR - n % ANCHOR) as usize).min(x.len() - done);
            let tr = if trace.is_empty() {
                &mut [][..]
            } else {
                &mut trace[done..done + span]
            };
            let step = if tr.is_empty() {
                step_on::<T, L, N, RES, false>
            } else {
                step_on::<T, L, N, RES, true>
            };
            step(
                self.path,
                Span {
                    s: &mut s,
                    rot: &mut self.rot,
                    acc: &mut self.acc,
                },
                Consts {
                    cd: &self.cd,
                    sdm: &self.sdm,
                    sup: &sup,
                    b1: &b1,
                    b2: &b2,
                },
                &aw[done..done + span],
                &x[done..done + span],
                tr,
            );
            done += span;
            let end = n0 + done as u64;
            if end.is_multiple_of(ANCHOR) || done == x.len() {
                self.check(&s, end)?;
            }
            if T::FLUSH && end.is_multiple_of(ANCHOR) {
                for l in 0..L {
                    self.total[l] += self.acc[l].wide();
                    self.acc[l] = T::default();
                }
            }
        }
        for (d, row) in self.states.iter_mut().zip(s.iter()) {
            *d = *row;
        }
        Ok(())
    }

    /// Every state of every live lane within [`STATE_BOUND`] (NaN caught explicitly).
    fn check<const N: usize>(&self, s: &[[T; L]; N], sample: u64) -> Result<(), DspError> {
        let lanes = (0..self.live).flat_map(|p| [Self::lane(p, false), Self::lane(p, true)]);
        for l in lanes {
            let peak = s.iter().map(|r| r[l].wide().abs()).fold(0.0, f64::max);
            if peak > STATE_BOUND || s.iter().any(|r| r[l].wide().is_nan()) {
                return Err(DspError::Unstable {
                    amplitude: f64::NAN,
                    sample,
                    state: peak,
                    bound: STATE_BOUND,
                    hint: format!(
                        "; full-band probe of bin {} ({}) of a frame of {} pulses",
                        self.bins[l],
                        if l < L / 2 { "I" } else { "Q" },
                        self.period
                    ),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sd::modulator::Modulator;

    /// The rotator inputs equal direct A·w·cos/sin: f64 within ≈ ANCHOR·ε (1e-12), f32
    /// within its rounding over one anchor span (2 roundings × 1024 steps × 2^-24 ≈ 1.2e-4
    /// worst case; 2e-5 is seen, allow 1e-4).
    #[test]
    fn rotator_inputs_match_direct_trig() {
        let n = 3000u64;
        let bins = [1u64, 17, 1499];
        for (tol, f32_lanes) in [(1e-12, false), (1e-4, true)] {
            let worst = if f32_lanes {
                input_error::<f32, LANES_F32>(&bins, n)
            } else {
                input_error::<f64, LANES_F64>(&bins, n)
            };
            assert!(worst < tol, "f32 {f32_lanes}: {worst}");
        }
    }

    /// Largest |input − A·w·cos/sin(2πkn/N)| over a frame of `n` samples (A = 0.5, Blackman).
    fn input_error<T: Lane, const L: usize>(bins: &[u64], n: u64) -> f64 {
        let w = crate::window::Window::Blackman;
        let aw: Vec<T> = (0..n as usize)
            .map(|i| T::of(0.5 * w.value(i, n as usize)))
            .collect();
        let mut worst = 0.0f64;
        for chunk in bins.chunks(L / 2) {
            let g = PairGroup::<T, L>::new(chunk, n, 3, Isa::Scalar);
            for (t, u) in g.inputs(0, &aw).iter().enumerate() {
                for (p, q) in (0..chunk.len()).flat_map(|p| [(p, false), (p, true)]) {
                    let l = PairGroup::<T, L>::lane(p, q);
                    let ul = u[l];
                    let th = 2.0 * PI * ((g.bins[l] * t as u64) % n) as f64 / n as f64;
                    let c = if q { th.sin() } else { th.cos() };
                    worst = worst.max((ul.wide() - 0.5 * w.value(t, n as usize) * c).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn non_cifb_state_space_is_rejected() {
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        assert!(Coeffs::new(&m.ss).is_ok());
        let mut bad = m.ss.clone();
        bad.d1 = 0.5;
        let e = Coeffs::new(&bad).unwrap_err().to_string();
        assert!(e.contains("CIFB"), "{e}");
        let mut bad = m.ss.clone();
        bad.a[2] = 0.1; // A[0][2]: off the tridiagonal
        assert!(Coeffs::new(&bad).is_err());
    }
}
