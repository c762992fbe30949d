//! The noise of each Haar coefficient in closed form, and the detection thresholds.
//!
//! # The held samples
//! On a static scene the detected depth of a pulse is a first-arrival mixture (signal with
//! timing jitter σ_I, background photons uniform in the window, first photon wins:
//! [`crate::closed_form::first_arrival`]) with variance σ_mix², plus the TDC quantisation
//! a²/12: σ² = σ_mix² + a²/12 (Sheppard's correction, good for σ_I ≳ a). A pulse detects
//! with probability ρ (the valid rate ρ_v; ρ_s·P(in window) without background). The 1NN
//! hold repeats the last detection, so two held samples k pulses apart are the same draw
//! with probability q^|k| (q = 1 − ρ: the pulses in between all missed) and independent
//! otherwise: Cov(h\[i\], h\[j\]) = σ²·q^|i−j| (stationary, i.e. primed well before the frame).
//!
//! # A mean over M held samples
//! G(M) = Σ_{i,j<M} q^|i−j| = M(1+q)/(1−q) − 2q(1 − q^M)/(1−q)², so
//! Var(mean of M) = σ²·G(M)/M² = (σ²/M)·[(2−ρ)/ρ − 2(1−ρ)(1 − (1−ρ)^M)/(Mρ²)].
//! The bracket is the inflation over independent samples: 1 at ρ = 1 or M = 1, → (2−ρ)/ρ
//! for M ≫ 1/ρ (the geometric run lengths of the random hold), and ≈ M (one draw repeated)
//! for M ≪ 1/ρ.
//!
//! # A coefficient
//! w = (S₊ − S₋)/L with halves of m₊ and m₋ samples (L = m₊ + m₋). The halves are
//! adjacent, so their sums are correlated: C = Σ_{i∈+, j∈−} q^(j−i) = q(1−q^m₊)(1−q^m₋)/(1−q)²,
//! and Var(w) = σ²·[G(m₊) + G(m₋) − 2C]/L². With ρ = 1: σ²/L = σ²/(2M) for equal halves
//! (w = (mean₊ − mean₋)/2). The correlation C reduces the variance of the difference; it
//! matters at the finest scales when M is not ≫ 1/ρ.
//!
//! # Thresholds
//! A coefficient is significant when |w| > z·sd(w). For a family-wise false-alarm
//! probability α over all K = 2^(U+1) − 1 coefficients, each is tested at the Šidák level
//! α₁ = 1 − (1 − α)^(1/K) (exact for independent coefficients: with ρ = 1 the Haar basis
//! is orthogonal and white Gaussian noise gives independent coefficients), two-sided:
//! z = Φ⁻¹(1 − α₁/2). α = 1%, K = 127: α₁ = 7.9e-5, z = 3.95.
//!
//! # Validity (measured, crates/dsp/tests/haar_noise.rs)
//! The sd of every scale matches simulation within ≈ 1 % for ρ_s = 1, 0.3, 0.03 and with
//! background. The *tail* is Gaussian only when each half-wavelet holds many independent
//! detections, M·ρ/(2 − ρ) ≫ 1: with the random hold a coefficient is a Gaussian scale
//! mixture (the run lengths vary), whose tails are heavier. At ρ_s = 1 the stated rate
//! holds (220 of 20,000 static frames of 2^12 pulses at α = 1 %, expected 200); at
//! N = 2^14, U = 6 (M = 128 at the finest scale) the false-event rate is 1.5× the stated
//! one at ρ_s = 0.3, 2.2× with ρ_b = 0.1 as well, and 4.5× at ρ_s = 0.03 (M·ρ/2 ≈ 2).

use tofprobe_scene::SensorConfig;

use super::{check_scales, register_count, support};
use crate::closed_form::{MixtureParams, first_arrival};
use crate::error::DspError;

/// The noise of the held depth samples on a static scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HaarNoise {
    /// σ: standard deviation of one detected depth, quantisation included (mm).
    pub sample_sd_mm: f64,
    /// ρ: probability that a pulse detects (the hold repeats the last sample otherwise).
    pub valid_rate: f64,
}

impl HaarNoise {
    /// σ > 0 (mm) and 0 < ρ ≤ 1.
    pub fn new(sample_sd_mm: f64, valid_rate: f64) -> Result<HaarNoise, DspError> {
        if !(sample_sd_mm.is_finite() && sample_sd_mm > 0.0) {
            return Err(DspError::out_of_range("sample_sd_mm", sample_sd_mm, "> 0"));
        }
        if !(valid_rate > 0.0 && valid_rate <= 1.0) {
            return Err(DspError::out_of_range(
                "valid_rate",
                valid_rate,
                "0 < valid_rate ≤ 1 (no detections otherwise)",
            ));
        }
        Ok(HaarNoise {
            sample_sd_mm,
            valid_rate,
        })
    }

    /// The noise of a static scene at `depth_mm` seen by `sensor`: the first-arrival
    /// mixture's variance and valid rate (closed_form), plus a²/12.
    pub fn for_static_scene(sensor: &SensorConfig, depth_mm: f64) -> Result<HaarNoise, DspError> {
        sensor.validate()?;
        if sensor.jitter_ps <= 0.0 {
            return Err(DspError::out_of_range(
                "sensor.jitter_ps",
                sensor.jitter_ps,
                "> 0 (the noise model needs timing jitter; without it a static depth gives one code)",
            ));
        }
        let fa = first_arrival(&MixtureParams {
            signal_rate: sensor.signal_rate,
            background_rate: sensor.background_rate,
            signal_depth_mm: depth_mm - sensor.window_start_mm(),
            jitter_mm: sensor.jitter_mm(),
            window_mm: sensor.window_end_mm() - sensor.window_start_mm(),
        })?;
        let a = sensor.tdc_lsb_mm();
        HaarNoise::new(
            (fa.variance_mm2 + a * a / 12.0).sqrt(),
            fa.valid_rate.min(1.0),
        )
    }

    /// G(M)/M: Var(mean of M held samples) = σ²/M × this (1 for ρ = 1).
    pub fn mean_inflation(&self, m: usize) -> f64 {
        if m == 0 {
            return 0.0;
        }
        self.pair_sum(m) / m as f64
    }

    /// Σ_{i,j<m} q^|i−j|.
    fn pair_sum(&self, m: usize) -> f64 {
        let rho = self.valid_rate;
        let mf = m as f64;
        if rho >= 1.0 {
            return mf;
        }
        let q = 1.0 - rho;
        // 1 − q^m without cancellation at small ρ.
        let one_minus_qm = -((mf * (-rho).ln_1p()).exp_m1());
        mf * (2.0 - rho) / rho - 2.0 * q * one_minus_qm / (rho * rho)
    }

    /// Σ_{i∈+, j∈−} q^(j−i) for adjacent halves of m₊ and m₋ samples.
    fn cross_sum(&self, m_plus: usize, m_minus: usize) -> f64 {
        let rho = self.valid_rate;
        if rho >= 1.0 {
            return 0.0;
        }
        let q = 1.0 - rho;
        let l = (-rho).ln_1p();
        let a = -((m_plus as f64 * l).exp_m1());
        let b = -((m_minus as f64 * l).exp_m1());
        q * a * b / (rho * rho)
    }

    /// sd of w_{u,v} (mm) in an N-sample frame.
    pub fn coefficient_sd_mm(&self, n_total: usize, u: u32, v: usize) -> f64 {
        let (s, m, e) = support(n_total, u, v);
        let (mp, mm) = (m - s, e - m);
        let l = (e - s) as f64;
        let g = self.pair_sum(mp) + self.pair_sum(mm) - 2.0 * self.cross_sum(mp, mm);
        self.sample_sd_mm * (g.max(0.0)).sqrt() / l
    }

    /// sd of the coefficients of scale u (that of v = 0; all v agree for N = 2^k).
    pub fn scale_sd_mm(&self, n_total: usize, u: u32) -> f64 {
        self.coefficient_sd_mm(n_total, u, 0)
    }
}

/// Φ⁻¹(p), the standard normal quantile, for 0 < p < 1 (P. J. Acklam's rational
/// approximation, relative error < 1.15e-9 over the whole range).
pub fn inverse_normal_cdf(p: f64) -> Result<f64, DspError> {
    if !(p > 0.0 && p < 1.0) {
        return Err(DspError::out_of_range("probability", p, "0 < p < 1"));
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    Ok(if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        // 1 − p loses digits for p → 1, but only those of p itself.
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    })
}

/// The per-coefficient level α₁ = 1 − (1 − α)^(1/K) (Šidák) for a family-wise rate α.
pub fn per_coefficient_rate(family_rate: f64, count: usize) -> Result<f64, DspError> {
    if !(family_rate > 0.0 && family_rate < 1.0) {
        return Err(DspError::out_of_range(
            "false-alarm rate",
            family_rate,
            "0 < rate < 1 (e.g. 0.01)",
        ));
    }
    if count == 0 {
        return Err(DspError::out_of_range("coefficient count", 0, "≥ 1"));
    }
    Ok(-((-family_rate).ln_1p() / count as f64).exp_m1())
}

/// Per-coefficient thresholds for a family-wise false-alarm rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Thresholds {
    /// α: probability that a static frame yields at least one event.
    pub family_rate: f64,
    /// z = Φ⁻¹(1 − α₁/2): a coefficient is significant when |w| > z·sd.
    pub z: f64,
    /// sd(w) per coefficient (mm), register order.
    pub sd_mm: Vec<f64>,
}

impl Thresholds {
    /// Thresholds for an N-pulse frame, scales 0..=U.
    pub fn new(
        noise: &HaarNoise,
        n_total: usize,
        u_max: u32,
        family_rate: f64,
    ) -> Result<Thresholds, DspError> {
        check_scales(n_total, u_max)?;
        let k = register_count(u_max);
        let a1 = per_coefficient_rate(family_rate, k)?;
        let z = -inverse_normal_cdf(0.5 * a1)?;
        let mut sd_mm = Vec::with_capacity(k);
        for u in 0..=u_max {
            for v in 0..(1usize << u) {
                sd_mm.push(noise.coefficient_sd_mm(n_total, u, v));
            }
        }
        Ok(Thresholds {
            family_rate,
            z,
            sd_mm,
        })
    }

    /// |w| above which register r is significant (mm).
    pub fn threshold_mm(&self, register: usize) -> f64 {
        self.z * self.sd_mm[register]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Quantiles against tabulated values (R's qnorm, 16 digits) to 2e-9 relative.
    #[test]
    fn inverse_normal_matches_tables() {
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.99, 2.326_347_874_040_841),
            (0.01, -2.326_347_874_040_841),
            (0.02, -2.053_748_910_631_823),
            (1e-10, -6.361_340_902_404_056),
            (1.0 - 1e-6, 4.753_424_308_822_899),
            (0.3, -0.524_400_512_708_041_1),
        ] {
            let got = inverse_normal_cdf(p).unwrap();
            assert!(
                (got - z).abs() <= 2e-9 * z.abs().max(1.0),
                "{p}: {got} vs {z}"
            );
        }
        assert!(inverse_normal_cdf(0.0).is_err() && inverse_normal_cdf(1.0).is_err());
        assert!(inverse_normal_cdf(f64::NAN).is_err());
    }

    /// Var of a mean over M held samples against a direct double sum of q^|i−j|, and the
    /// limits 1 (ρ = 1 or M = 1) and (2 − ρ)/ρ (M ≫ 1/ρ).
    #[test]
    fn mean_inflation_closed_form() {
        for rho in [1.0, 0.5, 0.3, 0.03, 0.001] {
            let n = HaarNoise::new(1.0, rho).unwrap();
            let q: f64 = 1.0 - rho;
            for m in [1usize, 2, 7, 100, 300] {
                let mut direct = 0.0;
                for i in 0..m {
                    for j in 0..m {
                        direct += q.powi((i as i32 - j as i32).abs());
                    }
                }
                let got = n.mean_inflation(m) * m as f64;
                assert!(
                    (got - direct).abs() < 1e-9 * direct,
                    "ρ {rho} M {m}: {got} {direct}"
                );
            }
            assert!((n.mean_inflation(1) - 1.0).abs() < 1e-9);
            let big = n.mean_inflation(10_000_000);
            assert!(
                (big / ((2.0 - rho) / rho) - 1.0).abs() < 1e-3,
                "ρ {rho}: {big}"
            );
        }
    }

    /// sd(w) against a direct double sum over the wavelet's ±1 weights, unequal halves
    /// included (N = 100), and σ/sqrt(2M) at ρ = 1.
    #[test]
    fn coefficient_sd_against_direct_sum() {
        for (rho, n, u, v) in [
            (0.3, 64usize, 2, 1usize),
            (0.1, 100, 3, 5),
            (1.0, 128, 1, 0),
        ] {
            let noise = HaarNoise::new(2.0, rho).unwrap();
            let q: f64 = 1.0 - rho;
            let (s, m, e) = support(n, u, v);
            let wgt = |i: usize| if i < m { 1.0 } else { -1.0 };
            let mut var = 0.0;
            for i in s..e {
                for j in s..e {
                    var += wgt(i) * wgt(j) * q.powi((i as i32 - j as i32).abs());
                }
            }
            let direct = 2.0 * var.sqrt() / (e - s) as f64;
            let got = noise.coefficient_sd_mm(n, u, v);
            assert!((got - direct).abs() < 1e-12, "{got} {direct}");
        }
        let noise = HaarNoise::new(3.0, 1.0).unwrap();
        assert!((noise.scale_sd_mm(1 << 14, 6) - 3.0 / (2.0 * 128.0f64).sqrt()).abs() < 1e-15);
    }

    /// α = 1 %, K = 127 → α₁ = 7.914e-5 and z = 3.948 (Φ⁻¹(1 − 3.957e-5)).
    #[test]
    fn thresholds_for_a_family_rate() {
        let a1 = per_coefficient_rate(0.01, 127).unwrap();
        assert!((1.0 - (1.0 - a1).powi(127) - 0.01).abs() < 1e-13);
        let t = Thresholds::new(&HaarNoise::new(1.0, 1.0).unwrap(), 1 << 10, 6, 0.01).unwrap();
        assert!((t.z - 3.948).abs() < 1e-3, "{}", t.z);
        assert_eq!(t.sd_mm.len(), 127);
        assert!(per_coefficient_rate(0.0, 127).is_err());
        assert!(Thresholds::new(&HaarNoise::new(1.0, 1.0).unwrap(), 64, 6, 0.01).is_err());
    }

    /// The sensor path: ρ_s = 1, no background → σ² = σ_I² + a²/12, ρ = 1.
    #[test]
    fn static_scene_noise_from_the_sensor() {
        // The noise checks' sensor (`montecarlo::sensor_with_rates(1.0, 0.0)`), written out:
        // σ_I = 20 ps = 3 mm, LSB 5 ps = 0.75 mm.
        let sensor = SensorConfig {
            laser_rate_hz: 10e6,
            jitter_ps: 20.0,
            tdc_lsb_ps: 5.0,
            window_start_ps: 0.0,
            window_length_ps: 400.0,
            signal_rate: 1.0,
            background_rate: 0.0,
        };
        let n = HaarNoise::for_static_scene(&sensor, 30.0).unwrap();
        assert!((n.sample_sd_mm - (9.0f64 + 0.75 * 0.75 / 12.0).sqrt()).abs() < 1e-6);
        assert!((n.valid_rate - 1.0).abs() < 1e-9);
        let zero = SensorConfig {
            jitter_ps: 0.0,
            ..sensor
        };
        assert!(HaarNoise::for_static_scene(&zero, 30.0).is_err());
    }
}
