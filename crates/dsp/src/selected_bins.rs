//! Streaming DFT on a few selected bins (direct accumulation): what the pixel computes,
//! in float, without holding the record.
//!
//! Memory is O(B): per bin one accumulator and one rotating phasor. The phasor
//! e^(−j2πkn/N) is advanced by one complex multiply per sample and re-synchronised
//! exactly (from the integer phase k·n mod N) every [`RESYNC`] samples, so the rounding
//! drift stays ≈ RESYNC·ε and the bins match the FFT within 1e-9 relative at N = 10^7.
//! Cost is ≈ B complex MACs per sample against the FFT's ≈ 5·log2 N flops per sample
//! plus the O(N) memory: the selected bins are cheaper for small B (see `bench dsp`).

use crate::dft::{amplitude_scale, check_len};
use crate::error::DspError;
use crate::window::Window;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// Samples between exact phasor re-synchronisations.
pub const RESYNC: u64 = 1024;

/// Accumulates X\[k\] = Σ w\[n\] x\[n\] e^(−j2πkn/N) for a list of bins over a streamed record
/// of known length N.
#[derive(Debug, Clone)]
pub struct SelectedBins {
    n_total: u64,
    window: Window,
    bins: Vec<usize>,
    acc: Vec<Complex64>,
    phasor: Vec<Complex64>,
    step: Vec<Complex64>,
    next: u64,
}

impl SelectedBins {
    /// Bins must lie in 0..=N/2 (a real record has no independent bin above Nyquist).
    pub fn new(n_total: u64, bins: &[usize], window: Window) -> Result<Self, DspError> {
        check_len(
            "selected-bin DFT",
            usize::try_from(n_total).unwrap_or(usize::MAX),
        )?;
        if bins.is_empty() {
            return Err(DspError::out_of_range("bins", "[]", "at least one bin"));
        }
        for &k in bins {
            if k as u64 > n_total / 2 {
                return Err(DspError::out_of_range(
                    "bin",
                    k,
                    format!("0..={} (Nyquist of an N = {n_total} record)", n_total / 2),
                ));
            }
        }
        let step = bins
            .iter()
            .map(|&k| Complex64::from_polar(1.0, -2.0 * PI * k as f64 / n_total as f64))
            .collect();
        Ok(SelectedBins {
            n_total,
            window,
            bins: bins.to_vec(),
            acc: vec![Complex64::new(0.0, 0.0); bins.len()],
            phasor: vec![Complex64::new(1.0, 0.0); bins.len()],
            step,
            next: 0,
        })
    }

    /// Exact e^(−j2πkn/N) from the integer phase.
    fn exact_phasor(&self, k: usize, n: u64) -> Complex64 {
        let m = (k as u128 * n as u128 % self.n_total as u128) as f64;
        Complex64::from_polar(1.0, -2.0 * PI * m / self.n_total as f64)
    }

    /// Feeds the next samples of the record (any chunking gives the same result).
    pub fn push(&mut self, samples: &[f64]) -> Result<(), DspError> {
        let end = self.next + samples.len() as u64;
        if end > self.n_total {
            return Err(DspError::out_of_range(
                "samples pushed",
                end,
                format!("≤ N = {}", self.n_total),
            ));
        }
        let n_us = self.n_total as usize;
        for &v in samples {
            let n = self.next;
            if n.is_multiple_of(RESYNC) {
                for b in 0..self.bins.len() {
                    self.phasor[b] = self.exact_phasor(self.bins[b], n);
                }
            }
            let wv = v * self.window.value(n as usize, n_us);
            for ((a, p), s) in self.acc.iter_mut().zip(&mut self.phasor).zip(&self.step) {
                *a += *p * wv;
                *p *= *s;
            }
            self.next += 1;
        }
        Ok(())
    }

    /// The raw sums X\[k\] (in the order of the bins given); the record must be complete.
    pub fn finish(&self) -> Result<Vec<Complex64>, DspError> {
        if self.next != self.n_total {
            return Err(DspError::RecordTooShort {
                what: "selected-bin DFT (record incomplete)",
                len: self.next as usize,
                needed: self.n_total as usize,
            });
        }
        Ok(self.acc.clone())
    }

    /// |Y\[k\]| with the paper's 2/(N·G) normalisation, in the input's units.
    pub fn amplitudes(&self) -> Result<Vec<f64>, DspError> {
        let n = self.n_total as usize;
        Ok(self
            .finish()?
            .iter()
            .zip(&self.bins)
            .map(|(c, &k)| c.norm() * amplitude_scale(k, n, self.window))
            .collect())
    }

    /// The bins, in the order given.
    pub fn bins(&self) -> &[usize] {
        &self.bins
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dft::tests::{lcg_noise, naive_dft};
    use crate::dft::windowed_dft;

    /// Selected bins equal the FFT's within 1e-9 relative, for any chunking, on a record
    /// longer than several re-synchronisation periods.
    #[test]
    fn matches_fft_bins() {
        let n = 10_000usize;
        let x: Vec<f64> = lcg_noise(n, 7).iter().map(|v| 30.0 + 5.0 * v).collect();
        let bins = [0usize, 1, 45, 1234, 4999, 5000];
        for w in [Window::Rectangular, Window::Blackman] {
            let fft = windowed_dft(&x, w).unwrap();
            let mut sb = SelectedBins::new(n as u64, &bins, w).unwrap();
            for chunk in x.chunks(777) {
                sb.push(chunk).unwrap();
            }
            let got = sb.finish().unwrap();
            for (g, &k) in got.iter().zip(&bins) {
                let rel = (g - fft[k]).norm() / fft[k].norm().max(1.0);
                assert!(rel < 1e-9, "{w:?} bin {k}: rel {rel}");
            }
        }
    }

    #[test]
    fn matches_naive_on_small_n() {
        let x = lcg_noise(50, 3);
        let slow = naive_dft(&x, Window::Hann);
        let mut sb = SelectedBins::new(50, &[2, 25], Window::Hann).unwrap();
        sb.push(&x).unwrap();
        let got = sb.finish().unwrap();
        assert!((got[0] - slow[2]).norm() < 1e-12);
        assert!((got[1] - slow[25]).norm() < 1e-12);
    }

    #[test]
    fn bad_input_is_rejected() {
        assert!(SelectedBins::new(100, &[51], Window::Blackman).is_err());
        assert!(SelectedBins::new(100, &[], Window::Blackman).is_err());
        assert!(SelectedBins::new(0, &[0], Window::Blackman).is_err());
        let mut sb = SelectedBins::new(10, &[1], Window::Blackman).unwrap();
        assert!(sb.push(&[0.0; 11]).is_err());
        sb.push(&[0.0; 9]).unwrap();
        assert!(sb.finish().is_err());
    }
}
