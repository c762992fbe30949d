//! Analysis windows and their normalisation constants.
//!
//! A windowed DFT amplitude is divided by the coherent gain G = mean(w) so a tone reads its
//! true amplitude; the noise floor of a windowed DFT is set by the effective length
//! N_eff = N·G²/P with P = mean(w²) (0.579·N for Blackman).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The window families tofprobe uses (periodic forms, so an L-point window tiles exactly).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Window {
    Rectangular,
    Hann,
    #[default]
    Blackman,
}

impl Window {
    /// w\[n\] for a window of `len` points (periodic definition: w\[n\] = f(2πn/len)).
    #[inline]
    pub fn value(self, n: usize, len: usize) -> f64 {
        let ph = 2.0 * PI * n as f64 / len as f64;
        match self {
            Window::Rectangular => 1.0,
            Window::Hann => 0.5 - 0.5 * ph.cos(),
            Window::Blackman => 0.42 - 0.5 * ph.cos() + 0.08 * (2.0 * ph).cos(),
        }
    }

    /// w\[n\] of the symmetric `len`-point window (f(2πn/(len − 1)), w\[0\] = w\[len − 1\]), as
    /// numpy's `np.blackman` / `np.hanning` evaluate it: with m = 2n + 1 − len,
    /// 0.42 + 0.5·cos(π·m/(len − 1)) + 0.08·cos(2π·m/(len − 1)), left to right (the
    /// toolbox's convention, [`crate::sd::config::ProbeConvention::Toolbox`]).
    #[inline]
    pub fn symmetric_value(self, n: usize, len: usize) -> f64 {
        if len <= 1 {
            return 1.0;
        }
        let m = (2 * n) as f64 + 1.0 - len as f64;
        let d = len as f64 - 1.0;
        match self {
            Window::Rectangular => 1.0,
            Window::Hann => 0.5 + 0.5 * (PI * m / d).cos(),
            Window::Blackman => 0.42 + 0.5 * (PI * m / d).cos() + 0.08 * (2.0 * PI * m / d).cos(),
        }
    }

    /// The whole window as a vector.
    pub fn samples(self, len: usize) -> Vec<f64> {
        (0..len).map(|n| self.value(n, len)).collect()
    }

    /// Coherent gain G = mean(w) in the limit of a long window (exact for the periodic
    /// form at any len ≥ 3, since the cosine terms sum to zero over whole periods).
    pub fn coherent_gain(self) -> f64 {
        match self {
            Window::Rectangular => 1.0,
            Window::Hann => 0.5,
            Window::Blackman => 0.42,
        }
    }

    /// Noise-power factor P = mean(w²) (exact for the periodic form at len ≥ 5).
    pub fn power_factor(self) -> f64 {
        match self {
            Window::Rectangular => 1.0,
            // 0.25 + 0.25·0.5
            Window::Hann => 0.375,
            // 0.42² + 0.5²/2 + 0.08²/2
            Window::Blackman => 0.42 * 0.42 + 0.125 + 0.0032,
        }
    }

    /// N_eff / N = G² / P (Blackman: 0.5791).
    pub fn effective_length_factor(self) -> f64 {
        let g = self.coherent_gain();
        g * g / self.power_factor()
    }

    /// Name as used in configuration files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Window::Rectangular => "rectangular",
            Window::Hann => "hann",
            Window::Blackman => "blackman",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form G and P must equal the sample means of the periodic window
    /// (to rounding: 1e-12 over 1000 points).
    #[test]
    fn gains_match_sample_means() {
        for w in [Window::Rectangular, Window::Hann, Window::Blackman] {
            let s = w.samples(1000);
            let g = s.iter().sum::<f64>() / 1000.0;
            let p = s.iter().map(|v| v * v).sum::<f64>() / 1000.0;
            assert!((g - w.coherent_gain()).abs() < 1e-12, "{w:?} G {g}");
            assert!((p - w.power_factor()).abs() < 1e-12, "{w:?} P {p}");
        }
        // The design's figure: N_eff = 0.5791 N for Blackman.
        assert!((Window::Blackman.effective_length_factor() - 0.5791).abs() < 5e-5);
    }

    /// The symmetric window against the textbook formula f(2πn/(L − 1)) written
    /// independently: equal to a few ulps, not bit for bit (the two evaluate the cosines at
    /// arguments up to 4π that round differently, ≤ 1 ulp of 4π = 1.8e-15 each, weighted
    /// by 0.5 and 0.08, plus three roundings of the sum: |Δ| ≤ 1.5e-15), symmetric
    /// exactly, zero at both ends to rounding, and not the periodic window.
    #[test]
    fn symmetric_window_is_the_textbook_formula() {
        for len in [2usize, 3, 16, 1001, 4096] {
            let d = (len - 1) as f64;
            for n in 0..len {
                let x = 2.0 * PI * n as f64 / d;
                let black = 0.42 - 0.5 * x.cos() + 0.08 * (2.0 * x).cos();
                let hann = 0.5 - 0.5 * x.cos();
                let b = Window::Blackman.symmetric_value(n, len);
                assert!(
                    (b - black).abs() < 1.5e-15,
                    "len {len} n {n}: {b} vs {black}"
                );
                assert!((Window::Hann.symmetric_value(n, len) - hann).abs() < 1.5e-15);
                assert_eq!(b, Window::Blackman.symmetric_value(len - 1 - n, len));
            }
            assert!(Window::Blackman.symmetric_value(0, len).abs() < 1e-16);
        }
        assert_eq!(Window::Rectangular.symmetric_value(3, 10), 1.0);
        assert_ne!(
            Window::Blackman.symmetric_value(100, 1000),
            Window::Blackman.value(100, 1000)
        );
    }
}
