//! The two-level ΣΔ modulator in f64, deterministic, with stability detection, and the
//! sweep that measures the largest input amplitude it stays stable for.
//!
//! A two-level modulator of order ≥ 2 that is overloaded does not saturate gracefully: its
//! integrator states run away. A state whose magnitude exceeds [`STATE_BOUND`] is therefore
//! treated as instability and reported with the input amplitude that caused it. In stable
//! operation the states of the realised (unscaled CIFB) designs stay below ≈ 10, so the
//! bound leaves an order of magnitude of headroom without letting a run-away go unnoticed.

use super::ntf::synthesize_ntf;
use super::realize::{StateSpace, realize_cifb};
use super::simd::lanes::{LANES, LaneGroup, LaneProbe};
use crate::error::DspError;
use crate::window::Window;
use std::f64::consts::PI;

pub use super::STATE_BOUND;

/// Samples of each fixed-length sine run of the stability sweep. For the default design
/// 2^16 samples still miss slow run-aways (1 kHz reads 0.785); from 2^18 on the limit
/// at 1 kHz is stable to the sweep step, and 2^20 lowers DC and 4.5 kHz by < 0.01.
pub const SWEEP_SAMPLES: usize = 1 << 18;

/// Amplitude step of the stability sweep.
pub const SWEEP_STEP: f64 = 0.0025;

/// Fraction of the measured maximum stable amplitude a probe may use: the sweep is a
/// finite run on a pure sine, while a probe is a windowed sine started from rest, so 10%
/// of headroom keeps long ROMs from meeting a rare excursion the sweep did not see.
pub const SAFETY_MARGIN: f64 = 0.9;

/// A designed two-level lowpass modulator (NTF + CIFB realisation with unity STF).
#[derive(Debug, Clone, PartialEq)]
pub struct Modulator {
    pub order: usize,
    pub osr: f64,
    pub h_inf: f64,
    pub optimised: bool,
    pub ss: StateSpace,
}

impl Modulator {
    /// Synthesises the NTF and realises it.
    pub fn design(order: usize, osr: f64, optimised: bool, h_inf: f64) -> Result<Self, DspError> {
        let ntf = synthesize_ntf(order, osr, optimised, h_inf)?;
        Ok(Modulator {
            order,
            osr,
            h_inf,
            optimised,
            ss: StateSpace::from_cifb(&realize_cifb(&ntf)),
        })
    }

    /// A zero initial state.
    pub fn zero_state(&self) -> Vec<f64> {
        vec![0.0; self.order]
    }

    /// Runs the modulator over `u`, writing ±1 to `v`, starting from and updating `state`.
    /// `amplitude` only labels the error; `first_sample` numbers the samples in it.
    pub fn run(
        &self,
        u: &[f64],
        state: &mut [f64],
        v: &mut [f64],
        amplitude: f64,
        first_sample: u64,
    ) -> Result<(), DspError> {
        let n = self.order;
        let ss = &self.ss;
        let mut next = vec![0.0; n];
        for (i, (&ui, vi)) in u.iter().zip(v.iter_mut()).enumerate() {
            // Same arithmetic order as the interleaved generator (`lanes`), bit for bit.
            let mut y = ss.d1 * ui;
            for (c, x) in ss.c.iter().zip(state.iter()) {
                y += c * x;
            }
            let q = if y >= 0.0 { 1.0 } else { -1.0 };
            *vi = q;
            // (A x)[r] + b1·u + b2·v, summed in this order by the interleaved generator
            // too (its zero terms dropped), so both give identical bits.
            for r in 0..n {
                let at = |j: usize| ss.a[r * n + j];
                let mut s = if r > 0 {
                    at(r - 1) * state[r - 1] + at(r) * state[r]
                } else {
                    at(r) * state[r]
                };
                if r + 1 < n && at(r + 1) != 0.0 {
                    s += at(r + 1) * state[r + 1];
                }
                // Entries off the tridiagonal (none in a CIFB realisation).
                for j in (0..n).filter(|&j| j.abs_diff(r) > 1) {
                    s += at(j) * state[j];
                }
                s += ss.b1[r] * ui;
                next[r] = s + ss.b2[r] * q;
            }
            state.copy_from_slice(&next);
            if let Some(&bad) = state.iter().find(|x| x.abs() > STATE_BOUND || x.is_nan()) {
                return Err(DspError::Unstable {
                    amplitude,
                    sample: first_sample + i as u64,
                    state: bad.abs(),
                    bound: STATE_BOUND,
                    hint: String::new(),
                });
            }
        }
        Ok(())
    }

    /// Whether a sine (or, at f = 0, a constant) of `amplitude` at normalised frequency
    /// `f_norm` runs `samples` samples without leaving the state bound.
    pub fn is_stable(&self, amplitude: f64, f_norm: f64, samples: usize) -> bool {
        let u: Vec<f64> = (0..samples)
            .map(|n| amplitude * (2.0 * PI * f_norm * n as f64).cos())
            .collect();
        let mut v = vec![0.0; samples];
        self.run(&u, &mut self.zero_state(), &mut v, amplitude, 0)
            .is_ok()
    }

    /// The largest sine amplitude stable at `f_norm`: amplitudes are swept upwards in
    /// steps of [`SWEEP_STEP`] from 0.5 (from 0 if 0.5 already fails), each a fresh run of
    /// [`SWEEP_SAMPLES`] samples from rest, and the last amplitude before the first
    /// unstable one is returned. A sweep rather than a bisection because overload is not
    /// monotone in amplitude near the edge: bisection lands on a stable island above the
    /// first failure (0.81 at DC for the default design). Eight amplitudes run at once in
    /// the interleaved generator; the frequency is rounded to a whole number of cycles in
    /// the run (≤ 19 Hz off at 10 MHz).
    pub fn max_stable_amplitude(&self, f_norm: f64) -> f64 {
        let len = SWEEP_SAMPLES;
        let bin = (f_norm.abs() * len as f64).round() as u64;
        let mut out = vec![0u16; len];
        let probe_half = {
            let mut g = LaneGroup::new(
                &[LaneProbe {
                    bin,
                    quadrature: false,
                    amplitude: 0.5,
                }],
                len as u64,
                Window::Rectangular,
                self.order,
            );
            g.run_flagging(&self.ss, 0, &mut out)[0]
        };
        let mut sweep_from = |start: f64| -> Option<f64> {
            let mut k = 1usize;
            while start + k as f64 * SWEEP_STEP < 1.0 {
                let probes: Vec<LaneProbe> = (0..LANES)
                    .map(|i| LaneProbe {
                        bin,
                        quadrature: false,
                        amplitude: (start + (k + i) as f64 * SWEEP_STEP).min(1.0),
                    })
                    .collect();
                let mut g = LaneGroup::new(&probes, len as u64, Window::Rectangular, self.order);
                let ok = g.run_flagging(&self.ss, 0, &mut out);
                if let Some(i) = ok.iter().position(|s| !s) {
                    return Some(start + (k + i - 1) as f64 * SWEEP_STEP);
                }
                k += LANES;
            }
            None
        };
        let start = if probe_half { 0.5 } else { 0.0 };
        sweep_from(start).unwrap_or(1.0 - SWEEP_STEP)
    }

    /// The largest probe amplitude accepted at `f_norm`: [`SAFETY_MARGIN`] × the measured
    /// maximum stable amplitude.
    pub fn amplitude_limit(&self, f_norm: f64) -> (f64, f64) {
        let a_max = self.max_stable_amplitude(f_norm);
        (SAFETY_MARGIN * a_max, a_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_design_max_stable_amplitude_matches_the_design_figures() {
        // Design figures (independent re-implementation): ≈ 0.77 at 1 kHz, ≈ 0.765 at
        // 4.5 kHz, ≈ 0.78 at DC, f_s = 10 MHz. The edge depends on run length and on the
        // sweep's definition by ≈ ±0.015 (2^16..2^20 samples move it that much), so the
        // figures are checked to ±0.02.
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        for (f_hz, want) in [(1000.0, 0.77), (4500.0, 0.765), (0.0, 0.78)] {
            let a = m.max_stable_amplitude(f_hz / 10e6);
            assert!((a - want).abs() < 0.02, "{f_hz} Hz: {a} vs {want}");
        }
    }

    #[test]
    fn overload_is_an_error_naming_the_amplitude() {
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        let u = vec![0.95; 20_000];
        let mut v = vec![0.0; u.len()];
        let e = m
            .run(&u, &mut m.zero_state(), &mut v, 0.95, 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("amplitude 0.95"), "{e}");
    }

    #[test]
    fn dc_input_is_the_mean_of_the_bitstream() {
        // Unity STF: the mean of v over a long run equals the DC input to within the
        // bounded state divided by the length (|Σ(v − u)| ≤ |x1|/a1 ≈ 10/0.044).
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        let u = vec![0.3; 100_000];
        let mut v = vec![0.0; u.len()];
        m.run(&u, &mut m.zero_state(), &mut v, 0.3, 0).unwrap();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        assert!((mean - 0.3).abs() < 3e-3, "{mean}");
    }
}
