//! The superpixel's noise in closed form (`[array] superpixel = G`; the bit-true rule is
//! `tofprobe_pixel::superpixel`): G² SPADs each detect the signal of a pulse with
//! probability p (no background), at t + e_i, e_i ~ N(0, σ²) independent, TDC code
//! c_i = ⌊t + e_i⌋ (in LSB); the pixel receives the rounded mean of the k valid codes.
//!
//! - **Detection rate**: k ~ Binomial(G², p), valid' = (k ≥ 1): ρ' = 1 − (1 − p)^{G²}.
//! - **Jitter**: given k, the mean of k codes has the jitter variance σ²/k, so
//!   E\[σ_eff²\] = σ²·E\[1/k | k ≥ 1\] = σ²·Σ_{k≥1} P(k)/k / ρ' — not σ²/G² unless p = 1
//!   (the missing SPADs do not average).
//! - **Quantisation**: each code adds its own ±½ LSB uniform error (1/12 LSB² — Sheppard's
//!   correction, exact to e^{−2π²σ²} for σ ≳ 1 LSB), which averages like the jitter:
//!   (σ² + 1/12)/k; the mean is then rounded half up on the grid of 1/k, an error r with
//!   E[r² | k] = (k² − 1)/(12k²) for odd k (0 at k = 1) and (k² + 2)/(12k²) for even k
//!   (the tie's +½ included), assuming the sum's residue mod k uniform (σ·√k ≫ k/(2π)).
//!   It tends to the 1/12 LSB² of a rounding as k grows.
//!
//! So the mean square error of the pixel's code about t − ½ (the floor's own offset), given
//! a detection, is
//! E\[ε²\] = Σ_{k≥1} P(k | k ≥ 1)·((σ² + 1/12)/k + E\[r² | k\]) ([`SuperpixelNoise::mse_lsb2`]).
//! G = 1 gives σ² + 1/12, the single pixel's σ_s² (`closed_form::sigma_total_mm`).

use crate::error::DspError;

/// The superpixel's detection rate and noise (LSB units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SuperpixelNoise {
    /// ρ' = 1 − (1 − p)^{G²}: a pulse's probability of a valid average.
    pub detection_rate: f64,
    /// E[1/k | k ≥ 1].
    pub mean_inverse_count: f64,
    /// σ²·E[1/k | k ≥ 1]: the jitter part of the average (LSB²).
    pub jitter_lsb2: f64,
    /// E\[ε²\] about t − ½: jitter, the codes' quantisation and the mean's rounding (LSB²).
    pub mse_lsb2: f64,
}

impl SuperpixelNoise {
    /// The effective jitter sqrt(E\[ε²\]) (LSB).
    pub fn sigma_eff_lsb(&self) -> f64 {
        self.mse_lsb2.sqrt()
    }
}

/// E[r² | k]: the second moment of rounding half up a mean of k integers (residue mod k
/// uniform): (k² − 1)/(12k²) for odd k, (k² + 2)/(12k²) for even k.
pub fn rounding_lsb2(k: u32) -> f64 {
    let k2 = f64::from(k) * f64::from(k);
    if k % 2 == 1 {
        (k2 - 1.0) / (12.0 * k2)
    } else {
        (k2 + 2.0) / (12.0 * k2)
    }
}

/// P(k) of Binomial(n, p), k = 0 ..= n.
pub fn binomial_pmf(n: u32, p: f64) -> Vec<f64> {
    let mut choose = 1.0f64;
    (0..=n)
        .map(|k| {
            if k > 0 {
                choose *= f64::from(n - k + 1) / f64::from(k);
            }
            choose * p.powi(k as i32) * (1.0 - p).powi((n - k) as i32)
        })
        .collect()
}

/// The closed form for `spads` = G² SPADs (1 ..= 64), detection probability `p` (0 < p ≤
/// 1) and jitter `sigma_lsb` (≥ 0, LSB).
pub fn superpixel_noise(spads: u32, p: f64, sigma_lsb: f64) -> Result<SuperpixelNoise, DspError> {
    if !(1..=64).contains(&spads) {
        return Err(DspError::out_of_range("spads", spads, "1..=64 (G² SPADs)"));
    }
    if !(p > 0.0 && p <= 1.0) {
        return Err(DspError::out_of_range("p", p, "0 < p <= 1"));
    }
    if !(sigma_lsb.is_finite() && sigma_lsb >= 0.0) {
        return Err(DspError::out_of_range("sigma_lsb", sigma_lsb, ">= 0"));
    }
    let pmf = binomial_pmf(spads, p);
    let rate = 1.0 - (1.0 - p).powi(spads as i32);
    let (mut inv, mut mse) = (0.0, 0.0);
    for (k, &pk) in pmf.iter().enumerate().skip(1) {
        let kf = k as f64;
        inv += pk / kf;
        mse += pk * ((sigma_lsb * sigma_lsb + 1.0 / 12.0) / kf + rounding_lsb2(k as u32));
    }
    Ok(SuperpixelNoise {
        detection_rate: rate,
        mean_inverse_count: inv / rate,
        jitter_lsb2: sigma_lsb * sigma_lsb * inv / rate,
        mse_lsb2: mse / rate,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits() {
        // One SPAD: the single pixel's σ² + 1/12, rate p.
        let one = superpixel_noise(1, 0.3, 2.0).unwrap();
        assert!((one.mse_lsb2 - (4.0 + 1.0 / 12.0)).abs() < 1e-12);
        assert!((one.detection_rate - 0.3).abs() < 1e-15);
        // p = 1: k = G² always, σ²/G² exactly.
        let all = superpixel_noise(4, 1.0, 2.0).unwrap();
        assert!((all.jitter_lsb2 - 1.0).abs() < 1e-12);
        // G = 2, p = 1/2: E[1/k | k ≥ 1] = (4 + 6/2 + 4/3 + 1/4)/15.
        let h = superpixel_noise(4, 0.5, 1.0).unwrap();
        assert!((h.mean_inverse_count - (4.0 + 3.0 + 4.0 / 3.0 + 0.25) / 15.0).abs() < 1e-12);
        assert!((h.detection_rate - 15.0 / 16.0).abs() < 1e-15);
        // The rounding of a mean of 2: errors 0 and +½ → 1/8; of 3: 0, ±1/3 → 2/27.
        assert!((rounding_lsb2(2) - 0.125).abs() < 1e-15);
        assert!((rounding_lsb2(3) - 2.0 / 27.0).abs() < 1e-15);
        assert_eq!(rounding_lsb2(1), 0.0);
        assert!(superpixel_noise(0, 0.5, 1.0).is_err());
        assert!(superpixel_noise(4, 0.0, 1.0).is_err());
    }
}
