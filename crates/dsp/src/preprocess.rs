//! The pixel's pre-processing in float (docs/pixel-contract.md, steps 1–3), streaming:
//! time-window zoom, 1NN missing-pulse hold with priming, and the first-order prefilter.
//!
//! Per pulse n with detection d\[n\] (depth minus the zoom offset, or none):
//! - **hold**: held\[n\] = d\[n\] if detected, else held\[n−1\] (the pixel's imputation; beyond
//!   the paper, [`FrontEnd::with_imputation`] puts a constant-velocity Kalman filter or
//!   its fixed-gain α-β form in its place, [`crate::imputation`]: held\[n\] is then the
//!   filter's depth after pulse n, and everything below is unchanged);
//! - **priming**: pulses before the first detection contribute nothing (output 0, which
//!   adds nothing to any linear accumulator, exactly as the pixel's `acc_en = 0`);
//! - **raw output** (the DFT/Haar reference, no prefilter): y\[n\] = held\[n\] once primed,
//!   the priming pulse included (the pixel's Haar path);
//! - **prefiltered output** (the pixel's Fourier path): x\[n\] = x\[n−1\] + α(held\[n−1\] − x\[n−1\])
//!   = (1−α)·x[n−1] + α·held[n−1]; the priming pulse contributes nothing and starts
//!   x at its own depth (no start transient), from the next pulse on y\[n\] = x\[n\].
//!
//! State survives between chunks, so records of 10^7 pulses stream in any chunking.
//!
//! This is THE float front end: every float level (the DFT references, float ΣΔ probing
//! in [`crate::sd::probing`], the trade-off's levels, the paper reproduction) runs its
//! detections through [`FrontEnd`], and [`prefilter_response`] is the one formula for the
//! prefilter's response.

use std::f64::consts::PI;

use rustfft::num_complex::Complex64;

use crate::error::DspError;
use crate::imputation::{Imputation, Imputer};

/// Which signal the front end outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrontEndOutput {
    /// The held depth itself (no prefilter).
    Held,
    /// The prefiltered held depth with x\[n\] = x\[n−1\] + α(held\[n−1\] − x\[n−1\]).
    Prefiltered { alpha: f64 },
}

/// Zoom + hold (+ prefilter) state machine.
#[derive(Debug, Clone)]
pub struct FrontEnd {
    zoom: f64,
    output: FrontEndOutput,
    imputer: Imputer,
    x: f64,
    pulses: u64,
}

impl FrontEnd {
    /// `zoom` is subtracted from every detected depth (the timing-window start, in the
    /// input's units); α must lie in (0, 1].
    pub fn new(zoom: f64, output: FrontEndOutput) -> Result<Self, DspError> {
        if !zoom.is_finite() {
            return Err(DspError::out_of_range("zoom", zoom, "a finite number"));
        }
        if let FrontEndOutput::Prefiltered { alpha } = output
            && !(alpha > 0.0 && alpha <= 1.0)
        {
            return Err(DspError::out_of_range("alpha", alpha, "0 < alpha ≤ 1")
                .with_hint("the pixel uses 2^-S, e.g. 1/32"));
        }
        Ok(Self::unchecked(zoom, output))
    }

    /// [`FrontEnd::new`] with `imputation` in place of the 1NN hold (its parameters
    /// checked, [`Imputation::check`]).
    pub fn with_imputation(
        zoom: f64,
        output: FrontEndOutput,
        imputation: Imputation,
    ) -> Result<Self, DspError> {
        imputation.check()?;
        let mut fe = Self::new(zoom, output)?;
        fe.imputer = Imputer::new(imputation);
        Ok(fe)
    }

    /// The front end without the argument checks (callers whose α is the pixel's 2^−S).
    pub(crate) fn unchecked(zoom: f64, output: FrontEndOutput) -> Self {
        FrontEnd {
            zoom,
            output,
            imputer: Imputer::new(Imputation::Hold),
            x: 0.0,
            pulses: 0,
        }
    }

    /// One pulse: returns the value the accumulators see (0 before priming). Priming and
    /// the held depth are the imputer's own state (the hold: the last detection).
    #[inline]
    pub fn step(&mut self, detection: Option<f64>) -> f64 {
        self.pulses += 1;
        let (was_primed, held_before) = (self.imputer.primed(), self.imputer.depth());
        let imputed = self.imputer.step(detection.map(|v| v - self.zoom));
        match self.output {
            FrontEndOutput::Held => imputed.unwrap_or(0.0),
            FrontEndOutput::Prefiltered { alpha } => {
                if was_primed {
                    self.x += alpha * (held_before - self.x);
                    self.x
                } else {
                    // The priming pulse starts x at its own depth and contributes nothing.
                    if let Some(d) = imputed {
                        self.x = d;
                    }
                    0.0
                }
            }
        }
    }

    /// A chunk of pulses: `out[i]` is the value for `input[i]`.
    pub fn process(&mut self, input: &[Option<f64>], out: &mut [f64]) -> Result<(), DspError> {
        if input.len() != out.len() {
            return Err(DspError::out_of_range(
                "output length",
                out.len(),
                format!("= input length {}", input.len()),
            ));
        }
        for (o, &d) in out.iter_mut().zip(input) {
            *o = self.step(d);
        }
        Ok(())
    }

    /// Whether a detection has been seen.
    pub fn primed(&self) -> bool {
        self.imputer.primed()
    }
    /// The held (imputed) depth (after zoom).
    pub fn held(&self) -> f64 {
        self.imputer.depth()
    }
    /// The prefilter state x.
    pub fn prefilter_state(&self) -> f64 {
        self.x
    }
    /// Pulses seen so far.
    pub fn pulses(&self) -> u64 {
        self.pulses
    }
}

/// The prefilter's response H_pre(e^{jω}) = α e^{−jω} / (1 − (1−α) e^{−jω}) at
/// f/f_s = `f_norm`, of x\[n\] = (1−α)x\[n−1\] + α·h\[n−1\]. Its magnitude squared is
/// α² / (1 − 2(1−α)cos ω + (1−α)²), the form of the mean 1NN hold response with ρ in
/// place of α (`closed_form::hold_response_sq`).
pub fn prefilter_response(alpha: f64, f_norm: f64) -> Complex64 {
    let zi = Complex64::from_polar(1.0, -2.0 * PI * f_norm);
    alpha * zi / (1.0 - (1.0 - alpha) * zi)
}

/// Prefilter gain |H_pre(ω)| at ω = 2π·f/f_s: the magnitude of [`prefilter_response`].
pub fn prefilter_gain(alpha: f64, omega: f64) -> f64 {
    prefilter_response(alpha, omega / (2.0 * PI)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hold_with_priming() {
        let mut fe = FrontEnd::new(10.0, FrontEndOutput::Held).unwrap();
        let input = [None, None, Some(13.0), None, Some(11.0), None];
        let mut out = [0.0; 6];
        fe.process(&input, &mut out).unwrap();
        assert_eq!(out, [0.0, 0.0, 3.0, 3.0, 1.0, 1.0]);
    }

    /// The prefilter follows the contract: the priming pulse outputs nothing, x starts at
    /// the first depth, then x[n] = x[n−1] + α(held[n−1] − x[n−1]) (hand-computed).
    #[test]
    fn prefilter_follows_the_contract() {
        let mut fe = FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha: 0.5 }).unwrap();
        let input = [None, Some(4.0), Some(8.0), None, None];
        let out: Vec<f64> = input.iter().map(|&d| fe.step(d)).collect();
        // pulse1 primes (x=4, held=4) → 0; pulse2: x = 4 + .5(4−4) = 4, then held=8;
        // pulse3: x = 4 + .5(8−4) = 6; pulse4: x = 6 + .5(8−6) = 7.
        assert_eq!(out, vec![0.0, 0.0, 4.0, 6.0, 7.0]);
        // Chunking does not matter.
        let mut a = FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha: 0.25 }).unwrap();
        let mut b = a.clone();
        let input: Vec<Option<f64>> = (0..100)
            .map(|i| if i % 3 == 0 { Some(i as f64) } else { None })
            .collect();
        let mut whole = vec![0.0; 100];
        a.process(&input, &mut whole).unwrap();
        let mut parts = vec![0.0; 100];
        b.process(&input[..37], &mut parts[..37]).unwrap();
        b.process(&input[37..], &mut parts[37..]).unwrap();
        assert_eq!(whole, parts);
    }

    /// The steady-state sinusoidal gain of the prefilter equals the closed form (1e-6: the
    /// transient after 4000 samples is (1−α)^4000 ≈ 0, the residue is the DFT's leakage).
    #[test]
    fn prefilter_gain_matches_simulation() {
        let alpha = 1.0 / 32.0;
        let n = 8192;
        let k = 64;
        let omega = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        let mut fe = FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha }).unwrap();
        let y: Vec<f64> = (0..2 * n)
            .map(|i| fe.step(Some((omega * i as f64).sin())))
            .collect();
        let s = crate::dft::amplitude_spectrum(&y[n..], crate::Window::Rectangular).unwrap();
        assert!(
            (s[k] - prefilter_gain(alpha, omega)).abs() < 1e-6,
            "{}",
            s[k]
        );
    }

    /// The one response formula's magnitude is the closed form
    /// |H|² = α²/(1 − 2(1−α)cos ω + (1−α)²) (1e-12: two exact forms in f64), and at α = 1
    /// it is a pure one-pulse delay.
    #[test]
    fn response_magnitude_is_the_closed_form() {
        for &(alpha, f) in &[(1.0 / 32.0, 4.5e-4), (0.5, 0.1), (1.0, 0.25)] {
            let omega = 2.0 * PI * f;
            let want = crate::closed_form::hold_response_sq(alpha, omega).sqrt();
            assert!((prefilter_gain(alpha, omega) - want).abs() < 1e-12);
        }
        // α = 1: a pure one-pulse delay, e^{−jω}.
        let h = prefilter_response(1.0, 0.25);
        assert!((h.re).abs() < 1e-12 && (h.im + 1.0).abs() < 1e-12, "{h}");
    }

    #[test]
    fn bad_alpha_rejected() {
        assert!(FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha: 0.0 }).is_err());
        assert!(FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha: 1.5 }).is_err());
        assert!(FrontEnd::new(f64::NAN, FrontEndOutput::Held).is_err());
    }
}
