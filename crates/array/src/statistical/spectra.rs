//! The probe's register sequences as power in frequency bands, so a pixel's register
//! covariance is a weighted sum over bands. Register a accumulates s_a\[n\]·x\[n\] (s_a the
//! ROM's ±1 bit, periodic in L, x the prefiltered held code). With c_a\[k\] the L-point DFT
//! of s_a over L, the covariance of registers a and b over N pulses of a stationary x of
//! power spectrum S(ω) is N·Σ_k Re(c_a\[k\]·c̄_b\[k\])·S(2πk/L) (each tone of the probe
//! picks S at its frequency; distinct tones are uncorrelated when N ≫ x's correlation
//! length; white x gives N·σ² by Parseval). The probe part is computed once per design
//! here; the pixel's S comes from the closed forms (`super::pixel`).
//!
//! Bands: every DFT index below `EXACT` is its own band (the hold's and the prefilter's
//! responses vary fastest there), beyond it bands of a constant ratio `RATIO` (0.5 %:
//! S varies by at most ≈ 1 % across one, and is evaluated at the band's mean index, so
//! the error is of second order).

use rayon::prelude::*;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;
use tofprobe_dsp::sd::ProbeRom;

/// DFT indices that are bands of their own.
const EXACT: usize = 512;
/// Ratio of consecutive band edges beyond [`EXACT`].
const RATIO: f64 = 1.005;
/// Registers up to which the covariance is full; beyond, only the variances (the pairs'
/// cost grows as R²) — the cross terms are small there (distinct bins' probes).
pub const FULL_COVARIANCE_REGISTERS: usize = 64;
/// Half-spectra kept in memory at once (complex values) before the pairs are computed by
/// the spectrum of each pair's sum instead (polarisation).
const MAX_HELD: usize = 1 << 23;

/// The probe's power per band for each register pair.
#[derive(Debug, Clone)]
pub struct ProbeBands {
    /// Registers R.
    pub registers: usize,
    /// ω (rad/pulse) at each band's mean index.
    pub omega: Vec<f64>,
    /// Whether the covariance is full (else only the diagonal).
    pub full: bool,
    /// Per pair (a ≤ b, row-major over the upper triangle, or the diagonal only when not
    /// full): Σ over the band's indices of Re(c_a·c̄_b), both signs of frequency counted.
    pub power: Vec<Vec<f64>>,
}

/// The band of folded index `k` (0 ..= L/2).
fn band_of(k: usize) -> usize {
    if k < EXACT {
        k
    } else {
        EXACT + ((k as f64 / EXACT as f64).ln() / RATIO.ln()).floor() as usize
    }
}

/// The pairs (a, b), a ≤ b, in the order of [`ProbeBands::power`].
pub fn pairs(registers: usize, full: bool) -> Vec<(usize, usize)> {
    if full {
        (0..registers)
            .flat_map(|a| (a..registers).map(move |b| (a, b)))
            .collect()
    } else {
        (0..registers).map(|a| (a, a)).collect()
    }
}

impl ProbeBands {
    /// The bands of `rom`'s register sequences.
    pub fn new(rom: &ProbeRom) -> ProbeBands {
        let l = rom.depth();
        let registers = rom.image.registers();
        let half = l / 2;
        let nbands = band_of(half) + 1;
        let (mut sum_k, mut count) = (vec![0.0; nbands], vec![0.0; nbands]);
        for k in 0..=half {
            sum_k[band_of(k)] += k as f64;
            count[band_of(k)] += 1.0;
        }
        let used: Vec<usize> = (0..nbands).filter(|&b| count[b] > 0.0).collect();
        let omega = used
            .iter()
            .map(|&b| 2.0 * std::f64::consts::PI * sum_k[b] / count[b] / l as f64)
            .collect();
        let mut index = vec![usize::MAX; nbands];
        for (i, &b) in used.iter().enumerate() {
            index[b] = i;
        }
        let slot: Vec<usize> = (0..=half).map(|k| index[band_of(k)]).collect();
        let full = registers <= FULL_COVARIANCE_REGISTERS;
        let fft = FftPlanner::<f64>::new().plan_fft_forward(l);
        // The half spectrum c[k] = DFT/L, k = 0 ..= L/2, of Σ of the given registers' ±1.
        let spectrum = |regs: &[usize]| -> Vec<Complex64> {
            let mut buf: Vec<Complex64> = (0..l)
                .map(|n| {
                    let v: f64 = regs
                        .iter()
                        .map(|&r| if rom.image.bit(n, r) { 1.0 } else { -1.0 })
                        .sum();
                    Complex64::new(v / l as f64, 0.0)
                })
                .collect();
            fft.process(&mut buf);
            buf.truncate(half + 1);
            buf
        };
        // Both signs of frequency: k and L − k, once for k = 0 and k = L/2 (L even).
        let weight = |k: usize| if k == 0 || 2 * k == l { 1.0 } else { 2.0 };
        let nb = omega_len(&slot);
        let reduce = |f: &dyn Fn(usize) -> f64| {
            let mut p = vec![0.0; nb];
            for k in 0..=half {
                p[slot[k]] += weight(k) * f(k);
            }
            p
        };
        let pairs = pairs(registers, full);
        let power: Vec<Vec<f64>> = if registers * (half + 1) <= MAX_HELD {
            let spectra: Vec<Vec<Complex64>> = (0..registers)
                .into_par_iter()
                .map(|r| spectrum(&[r]))
                .collect();
            pairs
                .par_iter()
                .map(|&(a, b)| reduce(&|k| (spectra[a][k] * spectra[b][k].conj()).re))
                .collect()
        } else {
            let own: Vec<Vec<f64>> = (0..registers)
                .into_par_iter()
                .map(|r| {
                    let s = spectrum(&[r]);
                    reduce(&|k| s[k].norm_sqr())
                })
                .collect();
            // Re(c_a c̄_b) = (|c_a + c_b|² − |c_a|² − |c_b|²)/2.
            pairs
                .par_iter()
                .map(|&(a, b)| {
                    if a == b {
                        return own[a].clone();
                    }
                    let s = spectrum(&[a, b]);
                    let sum = reduce(&|k| s[k].norm_sqr());
                    (0..nb)
                        .map(|i| 0.5 * (sum[i] - own[a][i] - own[b][i]))
                        .collect()
                })
                .collect()
        };
        ProbeBands {
            registers,
            omega,
            full,
            power,
        }
    }

    /// The R × R covariance (row-major) of registers over `pulses` pulses of an x whose
    /// power spectrum at each band is `psd[band]`.
    pub fn covariance(&self, pulses: u64, psd: &[f64]) -> Vec<f64> {
        let r = self.registers;
        let mut cov = vec![0.0; r * r];
        for (&(a, b), p) in pairs(r, self.full).iter().zip(&self.power) {
            let v = pulses as f64 * p.iter().zip(psd).map(|(p, s)| p * s).sum::<f64>();
            cov[a * r + b] = v;
            cov[b * r + a] = v;
        }
        cov
    }
}

fn omega_len(slot: &[usize]) -> usize {
    slot.iter().copied().max().map_or(0, |m| m + 1)
}

/// The lower Cholesky factor of a symmetric positive semi-definite `n` × `n` matrix
/// (row-major); a pivot that rounding leaves ≤ 0 gives a zero column (that direction has
/// no variance).
pub fn cholesky(a: &[f64], n: usize) -> Vec<f64> {
    let mut l = vec![0.0; n * n];
    for j in 0..n {
        let d = a[j * n + j] - (0..j).map(|k| l[j * n + k] * l[j * n + k]).sum::<f64>();
        if d <= 0.0 {
            continue;
        }
        let d = d.sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let s = a[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            l[i * n + j] = s / d;
        }
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L·Lᵀ gives back the matrix, and a rank-deficient one gets a zero column.
    #[test]
    fn cholesky_factors() {
        let a = [4.0, 2.0, 0.6, 2.0, 5.0, 1.0, 0.6, 1.0, 3.0];
        let l = cholesky(&a, 3);
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|k| l[i * 3 + k] * l[j * 3 + k]).sum();
                assert!((v - a[i * 3 + j]).abs() < 1e-12);
            }
        }
        let l = cholesky(&[1.0, 1.0, 1.0, 1.0], 2);
        assert_eq!(l[3], 0.0);
    }

    /// Bands are contiguous and grow: indices below EXACT alone, then 0.5 % wide.
    #[test]
    fn bands_are_ordered() {
        assert_eq!(band_of(511), 511);
        assert_eq!(band_of(512), 512);
        let mut last = 0;
        for k in 0..100_000 {
            let b = band_of(k);
            assert!(b == last || b == last + 1, "{k}");
            last = b;
        }
    }
}
