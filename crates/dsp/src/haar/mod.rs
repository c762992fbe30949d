//! Haar wavelets as the paper and the pixel use them.
//!
//! Ψ_{u,v}(t') = Ψ(2^u t' − v) on a record of N samples (t' = n/N): scale u = 0 is the
//! coarsest (one wavelet over the whole record), v = 0..2^u − 1; Ψ is +1 on the first half
//! of its support and −1 on the second. Coefficient (u, v) lives at register index
//! 2^u − 1 + v, so scales 0..U fill 2^(U+1) − 1 registers.
//!
//! Sample n belongs to wavelet v = ⌊n·2^u/N⌋ with sign + iff ⌊n·2^(u+1)/N⌋ is even; for
//! N a power of two this is exactly the pixel's bit rule (v = n >> (log2 N − u), sign from
//! bit log2 N − u − 1 of n). Other N (e.g. 100,000) are supported with integer support
//! boundaries.
//!
//! Two forms: [`haar_sums`] is the un-normalised integer form (Σ of + samples − Σ of −
//! samples), which the pixel's integer registers must equal exactly; [`haar_coefficients`]
//! divides by the wavelet's length (its number of samples).
//!
//! The transient analysis built on them lives in the submodules: [`analysis`] turns the
//! pixel's Haar registers into typed coefficients in mm (the scalogram), [`noise`] gives
//! each coefficient's noise in closed form and the detection thresholds, [`events`] turns
//! the coefficients that stand out of the noise into events (one per transition, grouped
//! across scales), [`profile`] measures an event's height, duration and mean rate from the
//! inverse transform (the paper's ramp-rate estimate beside them), [`checks`] validates Haar frames and notes transients outside them, [`montecarlo`]
//! checks the noise model by simulation; the paper's Fig. 3 and Fig. 12 results are
//! computed from these in `tofprobe-experiments` (`paper::haar_figures`).

pub mod analysis;
pub mod checks;
pub mod events;
pub mod fit;
pub mod montecarlo;
pub mod noise;
pub mod profile;

pub use analysis::{Coefficient, Scalogram, held_codes};
pub use events::{Event, EventReport, FAMILY_RATE, detect_events};
pub use fit::{TransitionFit, fit_transition};
pub use noise::{HaarNoise, Thresholds, inverse_normal_cdf};
pub use profile::Shape;

use crate::error::DspError;

/// Checks U against N: each half-wavelet at the finest scale needs ≥ 1 sample, i.e.
/// 2^(U+1) ≤ N.
fn check_scales(n: usize, u_max: u32) -> Result<(), DspError> {
    if n < 2 {
        return Err(DspError::RecordTooShort {
            what: "Haar transform",
            len: n,
            needed: 2,
        });
    }
    let max_u = n.ilog2() - 1;
    if u_max > max_u {
        return Err(DspError::out_of_range(
            "U (finest Haar scale)",
            u_max,
            format!("0..={max_u} for N = {n}"),
        )
        .with_hint(format!("U = {max_u} works")));
    }
    Ok(())
}

/// Register index of coefficient (u, v).
pub fn register_index(u: u32, v: usize) -> usize {
    (1usize << u) - 1 + v
}

/// Number of registers for scales 0..=U.
pub fn register_count(u_max: u32) -> usize {
    (1usize << (u_max + 1)) - 1
}

/// (v, sign) of sample n at scale u in an N-sample record.
#[inline]
pub fn wavelet_of(n: usize, n_total: usize, u: u32) -> (usize, bool) {
    let v = ((n as u128) << u) / n_total as u128;
    let half = ((n as u128) << (u + 1)) / n_total as u128;
    (v as usize, half.is_multiple_of(2))
}

/// Streaming un-normalised Haar sums over a record of known length (O(2^U) memory).
#[derive(Debug, Clone)]
pub struct HaarAccumulator<T> {
    n_total: usize,
    u_max: u32,
    next: usize,
    sums: Vec<T>,
}

impl<T> HaarAccumulator<T>
where
    T: Copy + Default + std::ops::AddAssign + std::ops::SubAssign,
{
    pub fn new(n_total: usize, u_max: u32) -> Result<Self, DspError> {
        check_scales(n_total, u_max)?;
        Ok(HaarAccumulator {
            n_total,
            u_max,
            next: 0,
            sums: vec![T::default(); register_count(u_max)],
        })
    }

    /// Feeds the next samples.
    pub fn push(&mut self, samples: &[T]) -> Result<(), DspError> {
        if self.next + samples.len() > self.n_total {
            return Err(DspError::out_of_range(
                "samples pushed",
                self.next + samples.len(),
                format!("≤ N = {}", self.n_total),
            ));
        }
        for &x in samples {
            for u in 0..=self.u_max {
                let (v, plus) = wavelet_of(self.next, self.n_total, u);
                let r = register_index(u, v);
                if plus {
                    self.sums[r] += x;
                } else {
                    self.sums[r] -= x;
                }
            }
            self.next += 1;
        }
        Ok(())
    }

    /// The sums, register order; the record must be complete.
    pub fn finish(self) -> Result<Vec<T>, DspError> {
        if self.next != self.n_total {
            return Err(DspError::RecordTooShort {
                what: "Haar transform (record incomplete)",
                len: self.next,
                needed: self.n_total,
            });
        }
        Ok(self.sums)
    }
}

/// Un-normalised sums (Σ + samples − Σ − samples), register order; exact in integers.
pub fn haar_sums(x: &[i64], u_max: u32) -> Result<Vec<i64>, DspError> {
    let mut acc = HaarAccumulator::<i64>::new(x.len(), u_max)?;
    acc.push(x)?;
    acc.finish()
}

/// Un-normalised sums by prefix sums, O(N + 2^U) instead of O(N·U): each coefficient is
/// 2·P\[mid\] − P\[start\] − P\[end\] over the running sum P. The fast path of the simulations;
/// [`haar_sums`] (the streaming form, sample by sample) is its reference.
pub fn haar_sums_prefix(x: &[i64], u_max: u32) -> Result<Vec<i64>, DspError> {
    check_scales(x.len(), u_max)?;
    let n = x.len();
    let mut prefix = Vec::with_capacity(n + 1);
    let mut acc = 0i64;
    prefix.push(0);
    for &v in x {
        acc = acc.wrapping_add(v);
        prefix.push(acc);
    }
    let mut out = Vec::with_capacity(register_count(u_max));
    for u in 0..=u_max {
        for v in 0..(1usize << u) {
            let (s, m, e) = support(n, u, v);
            out.push(
                prefix[m]
                    .wrapping_mul(2)
                    .wrapping_sub(prefix[s])
                    .wrapping_sub(prefix[e]),
            );
        }
    }
    Ok(out)
}

/// Sample boundaries (start, mid, end) of wavelet (u, v) in an N-sample record: the +
/// half is start..mid, the − half mid..end (start = ⌈vN/2^u⌉, mid = ⌈(2v+1)N/2^(u+1)⌉,
/// end = ⌈(v+1)N/2^u⌉, the same rule as [`wavelet_of`]).
pub fn support(n_total: usize, u: u32, v: usize) -> (usize, usize, usize) {
    let n = n_total as u128;
    let ceil = |num: u128, den_log2: u32| num.div_ceil(1u128 << den_log2) as usize;
    (
        ceil(v as u128 * n, u),
        ceil((2 * v as u128 + 1) * n, u + 1),
        ceil((v as u128 + 1) * n, u),
    )
}

/// Number of samples in the support of wavelet (u, v).
pub fn wavelet_len(n_total: usize, u: u32, v: usize) -> usize {
    // support = {n : ⌊n 2^u / N⌋ = v} = [ceil(v N / 2^u), ceil((v+1) N / 2^u))
    let start = (v * n_total).div_ceil(1 << u);
    let end = ((v + 1) * n_total).div_ceil(1 << u);
    end - start
}

/// Normalised coefficients w_{u,v} = sums / wavelet length, register order.
pub fn haar_coefficients(x: &[f64], u_max: u32) -> Result<Vec<f64>, DspError> {
    let mut acc = HaarAccumulator::<f64>::new(x.len(), u_max)?;
    acc.push(x)?;
    normalise(&acc.finish()?, x.len(), u_max)
}

/// Divides un-normalised sums (any source, e.g. a pixel readout) by the wavelet lengths.
pub fn normalise(sums: &[f64], n_total: usize, u_max: u32) -> Result<Vec<f64>, DspError> {
    check_scales(n_total, u_max)?;
    if sums.len() != register_count(u_max) {
        return Err(DspError::out_of_range(
            "Haar registers",
            sums.len(),
            format!("= 2^(U+1) − 1 = {}", register_count(u_max)),
        ));
    }
    let mut out = sums.to_vec();
    for u in 0..=u_max {
        for v in 0..(1usize << u) {
            out[register_index(u, v)] /= wavelet_len(n_total, u, v) as f64;
        }
    }
    Ok(out)
}

/// The scalogram: U+1 rows (u = 0 first), each 2^U columns; a coarse coefficient is
/// repeated over the 2^(U−u) finest cells it covers.
pub fn scalogram(coeffs: &[f64], u_max: u32) -> Result<Vec<Vec<f64>>, DspError> {
    if coeffs.len() != register_count(u_max) {
        return Err(DspError::out_of_range(
            "Haar coefficients",
            coeffs.len(),
            format!("= 2^(U+1) − 1 = {}", register_count(u_max)),
        ));
    }
    let cols = 1usize << u_max;
    Ok((0..=u_max)
        .map(|u| {
            (0..cols)
                .map(|c| coeffs[register_index(u, c >> (u_max - u))])
                .collect()
        })
        .collect())
}

/// The ramp-rate estimate at the largest |coefficient|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampEstimate {
    pub u: u32,
    pub v: usize,
    /// Rate in input units per second; positive for a rising ramp.
    pub rate_per_s: f64,
}

/// A ramp of slope r over a wavelet of duration T_u = T/2^u gives w = −r·T_u/4 (the +
/// half sees the earlier, lower values), so r = −4·w/T_u: the paper's 4·w/(T/2^u) with the
/// sign that makes a rising ramp positive. `duration_s` = T, the record's duration.
pub fn ramp_rate(coeffs: &[f64], u_max: u32, duration_s: f64) -> Result<RampEstimate, DspError> {
    if coeffs.len() != register_count(u_max) {
        return Err(DspError::out_of_range(
            "Haar coefficients",
            coeffs.len(),
            format!("= {}", register_count(u_max)),
        ));
    }
    if !(duration_s > 0.0 && duration_s.is_finite()) {
        return Err(DspError::out_of_range("duration_s", duration_s, "> 0"));
    }
    let mut best = (0u32, 0usize, 0.0f64);
    for u in 0..=u_max {
        for v in 0..(1usize << u) {
            let w = coeffs[register_index(u, v)];
            if w.abs() > best.2.abs() {
                best = (u, v, w);
            }
        }
    }
    let t_u = duration_s / (1u64 << best.0) as f64;
    Ok(RampEstimate {
        u: best.0,
        v: best.1,
        rate_per_s: -4.0 * best.2 / t_u,
    })
}

/// Compression N : (2^(U+1) − 1) of N raw samples into the Haar registers.
pub fn compression_ratio(n: u64, u_max: u32) -> f64 {
    n as f64 / register_count(u_max) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Naive reference: evaluate Ψ(2^u t' − v) at the sample times directly.
    fn naive(x: &[i64], u_max: u32) -> Vec<i64> {
        let n = x.len();
        let mut out = vec![0; register_count(u_max)];
        for u in 0..=u_max {
            for v in 0..(1usize << u) {
                let mut s = 0;
                for (i, &xi) in x.iter().enumerate() {
                    let t = (i as f64 / n as f64) * (1u64 << u) as f64 - v as f64;
                    if (0.0..0.5).contains(&t) {
                        s += xi;
                    } else if (0.5..1.0).contains(&t) {
                        s -= xi;
                    }
                }
                out[register_index(u, v)] = s;
            }
        }
        out
    }

    #[test]
    fn sums_match_naive_and_pixel_bit_rule() {
        for n in [64usize, 100, 96] {
            let x: Vec<i64> = (0..n as i64).map(|i| (i * 37 % 11) - 5).collect();
            assert_eq!(haar_sums(&x, 3).unwrap(), naive(&x, 3), "n {n}");
        }
        // Power of two: v = n >> (L−u), sign from bit L−u−1.
        let l = 6;
        for n in 0..64usize {
            for u in 0..l {
                let (v, plus) = wavelet_of(n, 64, u);
                assert_eq!(v, n >> (l - u));
                assert_eq!(plus, (n >> (l - u - 1)) & 1 == 0);
            }
        }
    }

    /// A ramp x = r·t gives back r from the largest coefficient (exact for even supports:
    /// the two halves' means differ by r·T_u/2 up to the sampling offset, 1e-9 relative).
    #[test]
    fn ramp_rate_recovers_slope() {
        let n = 1024;
        let fs = 1.0e4;
        let r = 3.5;
        let x: Vec<f64> = (0..n).map(|i| r * i as f64 / fs).collect();
        let c = haar_coefficients(&x, 4).unwrap();
        let e = ramp_rate(&c, 4, n as f64 / fs).unwrap();
        assert_eq!((e.u, e.v), (0, 0));
        assert!((e.rate_per_s - r).abs() / r < 1e-9, "{}", e.rate_per_s);
    }

    /// The prefix-sum fast path equals the streaming reference, powers of two or not, and
    /// the support boundaries agree with the per-sample rule.
    #[test]
    fn prefix_sums_match_the_streaming_reference() {
        for n in [2usize, 7, 64, 100, 1000, 4096] {
            let x: Vec<i64> = (0..n as i64).map(|i| (i * 7919 % 101) - 50).collect();
            let u = n.ilog2() - 1;
            assert_eq!(
                haar_sums_prefix(&x, u).unwrap(),
                haar_sums(&x, u).unwrap(),
                "n {n}"
            );
            for uu in 0..=u {
                for v in 0..(1usize << uu) {
                    let (s, m, e) = support(n, uu, v);
                    for i in s..e {
                        assert_eq!(wavelet_of(i, n, uu), (v, i < m), "n {n} u {uu} v {v} i {i}");
                    }
                    assert_eq!(e - s, wavelet_len(n, uu, v));
                }
            }
        }
        // A deliberately broken input fails the check: one sample changed changes a sum.
        let x: Vec<i64> = (0..64).collect();
        let mut y = x.clone();
        y[5] += 1;
        assert_ne!(haar_sums_prefix(&y, 5).unwrap(), haar_sums(&x, 5).unwrap());
    }

    #[test]
    fn scalogram_repeats_coarse_scales() {
        let c: Vec<f64> = (0..7).map(|i| i as f64).collect();
        let s = scalogram(&c, 2).unwrap();
        assert_eq!(s[0], vec![0.0; 4]);
        assert_eq!(s[1], vec![1.0, 1.0, 2.0, 2.0]);
        assert_eq!(s[2], vec![3.0, 4.0, 5.0, 6.0]);
    }

    #[test]
    fn compression_and_bad_input() {
        assert_eq!(compression_ratio(100_000, 6).round(), 787.0);
        assert_eq!(compression_ratio(500_000, 6).round(), 3937.0);
        assert!(haar_sums(&[1; 8], 3).is_err()); // 2^4 > 8
        assert!(haar_sums(&[1; 8], 2).is_ok());
        assert!(haar_sums(&[], 0).is_err());
    }
}
