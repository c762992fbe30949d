//! Full-record windowed DFT (rustfft): the reference every cheaper spectrum is judged
//! against.
//!
//! Amplitude convention (the paper's): |Y\[k\]| = 2/N · |Σ w\[n\] x\[n\] e^(−j2πkn/N)| / G, so a
//! tone of amplitude A on bin k reads A whatever the window. DC (k = 0) uses 1/N instead of
//! 2/N so it reads the mean. Units are those of the input (the reproduce command feeds mm
//! and reports µm).

use crate::error::DspError;
use crate::window::Window;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// The shortest record a window's closed-form G and P are exact for (periodic cosine
/// sums vanish over ≥ 5 points; 8 leaves margin and keeps Nyquist a distinct bin).
pub const MIN_RECORD_LEN: usize = 8;

/// Checks a record length against [`MIN_RECORD_LEN`].
pub fn check_len(what: &'static str, len: usize) -> Result<(), DspError> {
    if len < MIN_RECORD_LEN {
        return Err(DspError::RecordTooShort {
            what,
            len,
            needed: MIN_RECORD_LEN,
        });
    }
    Ok(())
}

/// The raw windowed DFT X\[k\] = Σ w\[n\] x\[n\] e^(−j2πkn/N), k = 0..N (all N bins).
pub fn windowed_dft(x: &[f64], window: Window) -> Result<Vec<Complex64>, DspError> {
    check_len("windowed DFT", x.len())?;
    let n = x.len();
    let mut buf: Vec<Complex64> = x
        .iter()
        .enumerate()
        .map(|(i, &v)| Complex64::new(v * window.value(i, n), 0.0))
        .collect();
    let mut planner = FftPlanner::<f64>::new();
    planner.plan_fft_forward(n).process(&mut buf);
    Ok(buf)
}

/// The amplitude scale of bin k for an N-point record: 2/(N·G) (1/(N·G) at DC and, for
/// even N, at Nyquist, where the real tone is not split between ±k).
pub fn amplitude_scale(k: usize, n: usize, window: Window) -> f64 {
    let single = k == 0 || (n.is_multiple_of(2) && k == n / 2);
    let factor = if single { 1.0 } else { 2.0 };
    factor / (n as f64 * window.coherent_gain())
}

/// The one-sided windowed DFT X\[k\], k = 0..=N/2. For even N it packs the real record
/// into an N/2-point complex FFT (z\[m\] = x\[2m\] + j·x\[2m+1\]) and untangles the even and odd
/// halves: X\[k\] = E\[k\] + e^(−j2πk/N)·O\[k\] with E\[k\] = (Z\[k\] + Z*\[N/2−k\])/2 and
/// O\[k\] = (Z\[k\] − Z*\[N/2−k\])/(2j): half the work and memory of a complex FFT.
pub fn windowed_dft_half(x: &[f64], window: Window) -> Result<Vec<Complex64>, DspError> {
    check_len("windowed DFT", x.len())?;
    let n = x.len();
    if !n.is_multiple_of(2) {
        let mut full = windowed_dft(x, window)?;
        full.truncate(n / 2 + 1);
        return Ok(full);
    }
    let h = n / 2;
    let mut z: Vec<Complex64> = (0..h)
        .map(|m| {
            Complex64::new(
                x[2 * m] * window.value(2 * m, n),
                x[2 * m + 1] * window.value(2 * m + 1, n),
            )
        })
        .collect();
    let mut planner = FftPlanner::<f64>::new();
    planner.plan_fft_forward(h).process(&mut z);
    Ok((0..=h)
        .map(|k| {
            let a = z[k % h];
            let b = z[(h - k) % h].conj();
            let e = (a + b) * 0.5;
            let o = (a - b) * Complex64::new(0.0, -0.5);
            let tw = Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * k as f64 / n as f64);
            e + tw * o
        })
        .collect())
}

/// One-sided amplitude spectrum |Y\[k\]|, k = 0..=N/2, in the input's units.
pub fn amplitude_spectrum(x: &[f64], window: Window) -> Result<Vec<f64>, DspError> {
    let n = x.len();
    let half = windowed_dft_half(x, window)?;
    Ok(half
        .iter()
        .enumerate()
        .map(|(k, c)| c.norm() * amplitude_scale(k, n, window))
        .collect())
}

/// The frequency (Hz) of bin k of an N-point record sampled at `fs_hz`.
pub fn bin_frequency_hz(k: f64, n: usize, fs_hz: f64) -> f64 {
    k * fs_hz / n as f64
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Independent O(N²) reference.
    pub(crate) fn naive_dft(x: &[f64], window: Window) -> Vec<Complex64> {
        let n = x.len();
        (0..n)
            .map(|k| {
                x.iter()
                    .enumerate()
                    .map(|(i, &v)| {
                        let ph = -2.0 * PI * ((k * i) % n) as f64 / n as f64;
                        Complex64::from_polar(v * window.value(i, n), ph)
                    })
                    .sum()
            })
            .collect()
    }

    /// Deterministic pseudo-noise for tests (a small LCG; no rand dependency needed).
    pub(crate) fn lcg_noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    #[test]
    fn fft_matches_naive_dft() {
        for n in [8usize, 30, 64, 105] {
            let x = lcg_noise(n, n as u64);
            for w in [Window::Rectangular, Window::Hann, Window::Blackman] {
                let fast = windowed_dft(&x, w).unwrap();
                let slow = naive_dft(&x, w);
                for (a, b) in fast.iter().zip(&slow) {
                    // Both are sums of n terms of magnitude ≤ 0.5: rounding ≤ n·1e-16.
                    assert!((a - b).norm() < 1e-12, "n {n} {w:?}");
                }
            }
        }
    }

    /// A tone on a bin reads its amplitude for every window (the 2/(N·G) normalisation);
    /// the sidelobe-free periodic windows make this exact to rounding.
    #[test]
    fn half_spectrum_matches_naive_dft() {
        for n in [8usize, 9, 30, 64, 105, 250] {
            let x = lcg_noise(n, 100 + n as u64);
            for w in [Window::Rectangular, Window::Blackman] {
                let half = windowed_dft_half(&x, w).unwrap();
                let slow = naive_dft(&x, w);
                assert_eq!(half.len(), n / 2 + 1);
                for (k, a) in half.iter().enumerate() {
                    assert!((a - slow[k]).norm() < 1e-12, "n {n} {w:?} k {k}");
                }
            }
        }
    }

    #[test]
    fn tone_reads_its_amplitude() {
        let n = 256;
        let (k0, a) = (17usize, 3.25);
        let x: Vec<f64> = (0..n)
            .map(|i| 1.5 + a * (2.0 * PI * (k0 * i) as f64 / n as f64 + 0.3).cos())
            .collect();
        for w in [Window::Rectangular, Window::Hann, Window::Blackman] {
            let s = amplitude_spectrum(&x, w).unwrap();
            assert!((s[k0] - a).abs() < 1e-12, "{w:?}: {}", s[k0]);
            assert!((s[0] - 1.5).abs() < 1e-12, "{w:?} DC {}", s[0]);
        }
    }

    #[test]
    fn short_records_are_rejected() {
        assert_eq!(
            amplitude_spectrum(&[], Window::Blackman),
            Err(DspError::RecordTooShort {
                what: "windowed DFT",
                len: 0,
                needed: MIN_RECORD_LEN
            })
        );
        assert!(amplitude_spectrum(&[1.0; 7], Window::Hann).is_err());
    }
}
