//! Closed-form models of the noise floor, the 1NN hold, pile-up and ΣΔ resolution, and
//! their extensions that the reproduce rows compare simulations against.
//!
//! # Eq. 12: the noise floor of white depth noise
//! A windowed DFT of white noise of variance σ_s² gives a circular complex Gaussian
//! Y = 2/(N·G)·Σ w\[n\] e\[n\] e^(−jωn) with E|Y|² = 4σ_s²·P/(N·G²) = 4σ_s²/N_eff
//! (N_eff = N·G²/P). |Y| is Rayleigh, E|Y| = sqrt(π/4·E|Y|²) = sqrt(π σ_s²/N_eff).
//! σ_s² = σ_I² + a²/12 adds the TDC quantisation (LSB a) to the jitter.
//!
//! # Extension for the 1NN hold
//! With detections independent per pulse with probability ρ (the valid rate), the held
//! sample at pulse n is the detection of pulse n−k iff pulses n−k+1..n all missed, so two
//! held samples k pulses apart carry the *same* noise draw with probability (1−ρ)^|k|
//! and independent ones otherwise: the held noise has autocovariance
//! R\[k\] = σ²·q^|k|, q = 1 − ρ (an AR(1)-like sequence). Its power spectrum is
//! S(ω) = σ²·Σ_k q^|k| e^(−jωk) = σ²·(1 − q²)/(1 − 2q cos ω + q²),
//! so the noise floor at bin frequency ω (S smooth over the window's main lobe) is
//! E|Y(ω)| = sqrt(π σ² F(ρ, ω)/N_eff), F = (1 − q²)/(1 − 2q cos ω + q²)
//! ([`hold_noise_factor`]). At low frequency F → (1+q)/(1−q) = (2 − ρ)/ρ: the floor grows
//! as sqrt((2−ρ)/ρ) ≈ sqrt(2/ρ_s) (e.g. ×2.38 at ρ = 0.3, ×8.1 at ρ = 0.03). The mean
//! (signal) response of the same hold is E\[held\[n\]\] = Σ ρ q^k s\[n−k\], i.e.
//! |H|² = ρ²/(1 − 2q cos ω + q²) ([`hold_response_sq`]).
//!
//! # Extension for background: the first-arrival mixture
//! Per pulse: a signal photon with probability ρ_s at depth t ~ N(t_s, σ_I²) (lost if
//! outside the window [0, W)), and Poisson background photons, mean ρ_b per window,
//! uniform in [0, W) (rate λ = ρ_b/W per mm). The first photon wins, so the density of the
//! first arrival at t is
//! f(t) = e^(−λt)·[λ·(1 − ρ_s·Φ(t)) + ρ_s·φ(t)], Φ(t) = P(0 ≤ t_sig ≤ t),
//! (a background first: none earlier, signal not earlier; or the signal first: no
//! background earlier). Its integral is the valid rate ρ_v = 1 − (1 − ρ_s·P_in)·e^(−ρ_b),
//! and the detected depth is a mixture with mean μ and variance σ_mix² (by quadrature,
//! [`first_arrival`]; plus a²/12 for the TDC). The held sequence then has R\[k\] =
//! σ_mix²·(1 − ρ_v)^|k|, so the noise floor is sqrt(π σ_mix² F(ρ_v, ω)/N_eff)
//! ([`noise_floor_mixture_mm`]). A small motion of the signal moves the mixture's mean by
//! g = ∂μ/∂t_s < 1 (background arrivals do not follow it): the measured amplitude is
//! ≈ g·|H(ρ_v, ω)|·A. Pile-up of the signal alone is ρ_s·e^(−ρ_b·t_s/W)
//! ([`pileup_survival`]), e^(−ρ_b/2) mid-window.

use crate::error::DspError;
use std::f64::consts::PI;

/// Eq. 12: E|Y| = sqrt(π σ_s²/N_eff) (units of σ_s).
pub fn noise_floor_mm(sigma_s_mm: f64, n_eff: f64) -> f64 {
    (PI * sigma_s_mm * sigma_s_mm / n_eff).sqrt()
}

/// σ_s = sqrt(σ_I² + a²/12).
pub fn sigma_total_mm(jitter_mm: f64, lsb_mm: f64) -> f64 {
    (jitter_mm * jitter_mm + lsb_mm * lsb_mm / 12.0).sqrt()
}

/// The jitter σ_I that gives a total σ_s with TDC LSB a: sqrt(σ_s² − a²/12).
pub fn jitter_for_total_mm(sigma_s_mm: f64, lsb_mm: f64) -> Result<f64, DspError> {
    let v = sigma_s_mm * sigma_s_mm - lsb_mm * lsb_mm / 12.0;
    if v.is_nan() || v <= 0.0 {
        return Err(DspError::out_of_range(
            "sigma_s_mm",
            sigma_s_mm,
            format!(
                "> a/sqrt(12) = {} mm for LSB a = {lsb_mm} mm",
                lsb_mm / 12f64.sqrt()
            ),
        ));
    }
    Ok(v.sqrt())
}

/// Variance factor F(ρ, ω) = (1 − q²)/(1 − 2q cos ω + q²) of the held noise at ω
/// (rad/sample), q = 1 − ρ. F = 1 at ρ = 1.
pub fn hold_noise_factor(rho: f64, omega: f64) -> f64 {
    rho * (2.0 - rho) / hold_denominator(rho, omega)
}

/// 1 − 2q cos ω + q² written as ρ² + 4q·sin²(ω/2), which keeps its precision when ρ and ω
/// are both small (the direct form cancels to ≈ 1e-6 of its terms at ρ = 0.001).
fn hold_denominator(rho: f64, omega: f64) -> f64 {
    let s = (0.5 * omega).sin();
    rho * rho + 4.0 * (1.0 - rho) * s * s
}

/// Noise floor with the hold: sqrt(π σ² F(ρ, ω)/N_eff).
pub fn noise_floor_hold_mm(sigma_s_mm: f64, rho: f64, omega: f64, n_eff: f64) -> f64 {
    noise_floor_mm(sigma_s_mm, n_eff) * hold_noise_factor(rho, omega).sqrt()
}

/// Mean response of the random 1NN hold: |H|² = ρ²/(1 − 2(1−ρ)cos ω + (1−ρ)²).
pub fn hold_response_sq(rho: f64, omega: f64) -> f64 {
    rho * rho / hold_denominator(rho, omega)
}

/// The mean response itself, H(ω) = ρ/(1 − q·e^(−jω)) (q = 1 − ρ): E\[held\[n\]\] = Σ ρ q^k
/// s[n−k] moves a tone by |H| ([`hold_response_sq`]) and delays it by −arg H.
pub fn hold_response(rho: f64, omega: f64) -> rustfft::num_complex::Complex64 {
    let q = 1.0 - rho;
    let z = rustfft::num_complex::Complex64::from_polar(q, -omega);
    rho / (1.0 - z)
}

/// The −3 dB frequency (|H|² = ½) of the random hold: 1 − 2q cos ω + q² = 2ρ² gives
/// 1 − cos ω = ρ²/(2q), i.e. ω = 2·asin(ρ/(2√q)) (the asin form keeps full precision at
/// small ρ, where cos ω → 1). None when the response stays above ½ up to Nyquist
/// (ρ/(2√q) > 1, i.e. ρ > 2(√2 − 1) ≈ 0.83).
pub fn hold_bandwidth_hz(rho: f64, fs_hz: f64) -> Option<f64> {
    if !(rho > 0.0 && rho < 1.0) {
        return None;
    }
    let s = rho / (2.0 * (1.0 - rho).sqrt());
    if s > 1.0 {
        return None;
    }
    Some(2.0 * s.asin() / (2.0 * PI) * fs_hz)
}

/// The paper's zero-order-hold approximation: T_h = (2/ρ + 1)·T_s, f_3dB = 0.44/T_h.
pub fn zoh_hold_f3db(rho: f64, fs_hz: f64) -> f64 {
    0.44 * fs_hz / (2.0 / rho + 1.0)
}

/// Signal detections surviving pile-up: ρ_s·e^(−ρ_b·t_s/W), `t_s_frac` = t_s/W.
pub fn pileup_survival(rho_s: f64, rho_b: f64, t_s_frac: f64) -> f64 {
    rho_s * (-rho_b * t_s_frac).exp()
}

/// Eq. 4, ideal (1 − z⁻¹)^Θ one-bit ΣΔ: SNR_dB ≈ 7.78 + 10·log10(2Θ+1) − 9.94Θ
/// + 3.01(2Θ+1)d with OSR = 2^d.
pub fn sd_snr_db(order: u32, osr_log2: u32) -> f64 {
    let t = order as f64;
    7.78 + 10.0 * (2.0 * t + 1.0).log10() - 9.94 * t + 3.01 * (2.0 * t + 1.0) * osr_log2 as f64
}

/// ENOB = (SNR_dB − 1.76)/6.02.
pub fn enob(snr_db: f64) -> f64 {
    (snr_db - 1.76) / 6.02
}

/// Statistics of the first arrival per pulse (depths from the window start, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstArrival {
    /// ρ_v: probability that a pulse yields a detection.
    pub valid_rate: f64,
    /// Mean detected depth.
    pub mean_mm: f64,
    /// Variance of the detected depth (continuous; add a²/12 for the TDC).
    pub variance_mm2: f64,
    /// Fraction of detections that are the signal photon.
    pub signal_fraction: f64,
}

/// Inputs of the mixture model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MixtureParams {
    pub signal_rate: f64,
    pub background_rate: f64,
    /// Signal depth from the window start, mm.
    pub signal_depth_mm: f64,
    pub jitter_mm: f64,
    pub window_mm: f64,
}

fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// erfc with |relative error| < 1.2e-7 (Numerical Recipes' Chebyshev form).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t * (-z * z - 1.26551223 + t * horner(t, &ERFC_TAIL)).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// The Chebyshev coefficients of [`erfc`] after the constant term, lowest power first.
const ERFC_TAIL: [f64; 9] = [
    1.00002368,
    0.37409196,
    0.09678418,
    -0.18628806,
    0.27886807,
    -1.13520398,
    1.48851587,
    -0.82215223,
    0.17087277,
];

/// c₀ + x·(c₁ + x·(c₂ + …)) by Horner's rule, `coeffs` lowest power first: the same
/// operations in the same order as the nested expression written out (so bit-identical to
/// it), without the deep nesting that makes rustfmt's layout search take seconds per
/// polynomial.
pub fn horner(x: f64, coeffs: &[f64]) -> f64 {
    match coeffs.split_last() {
        Some((last, rest)) => rest.iter().rev().fold(*last, |acc, c| c + x * acc),
        None => 0.0,
    }
}

/// Moments of the first-arrival mixture by composite Simpson quadrature (4000 panels,
/// plus the signal's Gaussian resolved by ≥ 40 points per σ).
pub fn first_arrival(p: &MixtureParams) -> Result<FirstArrival, DspError> {
    let MixtureParams {
        signal_rate: rs,
        background_rate: rb,
        signal_depth_mm: ts,
        jitter_mm: sj,
        window_mm: w,
    } = *p;
    if !(w > 0.0 && w.is_finite()) {
        return Err(DspError::out_of_range("window_mm", w, "> 0"));
    }
    if !(0.0..=1.0).contains(&rs) {
        return Err(DspError::out_of_range("signal_rate", rs, "0..=1"));
    }
    if !(rb >= 0.0 && rb.is_finite()) {
        return Err(DspError::out_of_range("background_rate", rb, "≥ 0"));
    }
    if !(sj > 0.0 && sj.is_finite()) {
        return Err(DspError::out_of_range("jitter_mm", sj, "> 0"));
    }
    let lam = rb / w;
    let c0 = normal_cdf((0.0 - ts) / sj);
    let panels = (((w / sj) * 40.0).ceil() as usize).max(4000) * 2;
    let h = w / panels as f64;
    let (mut m0, mut m1, mut m2, mut ms) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..=panels {
        let t = i as f64 * h;
        let z = (t - ts) / sj;
        let phi = (-0.5 * z * z).exp() / (sj * (2.0 * PI).sqrt());
        let cdf = (normal_cdf(z) - c0).max(0.0);
        let e = (-lam * t).exp();
        let fs = rs * phi * e;
        let f = e * lam * (1.0 - rs * cdf) + fs;
        let wt = if i == 0 || i == panels {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        } * h
            / 3.0;
        m0 += wt * f;
        m1 += wt * f * t;
        m2 += wt * f * t * t;
        ms += wt * fs;
    }
    if m0.is_nan() || m0 <= 0.0 {
        return Err(DspError::out_of_range(
            "signal_rate + background_rate",
            rs + rb,
            "> 0 (no detections otherwise)",
        ));
    }
    let mean = m1 / m0;
    Ok(FirstArrival {
        valid_rate: m0,
        mean_mm: mean,
        variance_mm2: (m2 / m0 - mean * mean).max(0.0),
        signal_fraction: ms / m0,
    })
}

/// [`first_arrival`], or for a pixel without photons (ρ_s + ρ_b = 0) nothing detected:
/// ρ_v = 0 at the signal's depth with the jitter's variance.
pub fn detected(p: &MixtureParams) -> Result<FirstArrival, DspError> {
    if p.signal_rate + p.background_rate > 0.0 {
        return first_arrival(p);
    }
    Ok(FirstArrival {
        valid_rate: 0.0,
        mean_mm: p.signal_depth_mm,
        variance_mm2: p.jitter_mm * p.jitter_mm,
        signal_fraction: 0.0,
    })
}

/// ∂μ/∂t_s: how much of a small signal motion the mixture's mean follows (1 without
/// background), by a central difference of ±1% σ_I.
pub fn mixture_gain(p: &MixtureParams) -> Result<f64, DspError> {
    let h = 0.01 * p.jitter_mm;
    let up = first_arrival(&MixtureParams {
        signal_depth_mm: p.signal_depth_mm + h,
        ..*p
    })?;
    let dn = first_arrival(&MixtureParams {
        signal_depth_mm: p.signal_depth_mm - h,
        ..*p
    })?;
    Ok((up.mean_mm - dn.mean_mm) / (2.0 * h))
}

/// Noise floor of held first arrivals with background (see the module doc):
/// sqrt(π (σ_mix² + a²/12)·F(ρ_v, ω)/N_eff), and the valid rate ρ_v.
pub fn noise_floor_mixture_mm(
    p: &MixtureParams,
    lsb_mm: f64,
    omega: f64,
    n_eff: f64,
) -> Result<f64, DspError> {
    let fa = first_arrival(p)?;
    let var = fa.variance_mm2 + lsb_mm * lsb_mm / 12.0;
    Ok(noise_floor_hold_mm(var.sqrt(), fa.valid_rate, omega, n_eff))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The design's figures: Fig. 4 (rectangular 0.53/5.3/53 µm, Blackman 0.70/6.98/69.8)
    /// and 2.21 µm at σ = 3 mm, N = 10^7, Blackman.
    #[test]
    fn eq12_reproduces_the_papers_figures() {
        let b = crate::Window::Blackman.effective_length_factor();
        for (ps, rect, black) in [(2.0, 0.53, 0.70), (20.0, 5.3, 6.98), (200.0, 53.0, 69.8)] {
            let s = ps * 0.15; // mm
            let r = noise_floor_mm(s, 1e6) * 1e3;
            let bl = noise_floor_mm(s, 1e6 * b) * 1e3;
            assert!((r / rect - 1.0).abs() < 0.01, "{r}");
            assert!((bl / black - 1.0).abs() < 0.01, "{bl}");
        }
        assert!((noise_floor_mm(3.0, 1e7 * b) * 1e3 - 2.21).abs() < 0.005);
    }

    /// The hold's 3 dB points: the design's 167.8 / 16.0 / 1.59 kHz, and |H|² there = ½.
    #[test]
    fn hold_bandwidths() {
        for (rho, khz) in [(0.1, 167.8), (0.01, 16.0), (0.001, 1.59)] {
            let f = hold_bandwidth_hz(rho, 1e7).unwrap();
            assert!((f / 1e3 / khz - 1.0).abs() < 0.005, "{rho}: {f}");
            let w = 2.0 * PI * f / 1e7;
            assert!((hold_response_sq(rho, w) - 0.5).abs() < 1e-12);
        }
        assert_eq!(hold_bandwidth_hz(1.0, 1e7), None);
        assert!((zoh_hold_f3db(0.1, 1e7) - 0.44e7 / 21.0).abs() < 1e-6);
    }

    /// F(ρ, ω) is the DTFT of q^|k|: compare with a direct truncated sum (q^2000 ≈ 0).
    /// H(ω) against the direct sum Σ ρ q^k e^(−jωk), and |H|² against its closed form.
    #[test]
    fn hold_response_is_the_sum_of_the_held_delays() {
        for (rho, w) in [(0.3, 0.01), (0.03, 0.0028), (0.5, 2.0)] {
            let q: f64 = 1.0 - rho;
            let (mut re, mut im) = (0.0, 0.0);
            for k in 0..4000 {
                let a = rho * q.powi(k);
                re += a * (w * k as f64).cos();
                im -= a * (w * k as f64).sin();
            }
            let h = hold_response(rho, w);
            assert!(
                (h.re - re).abs() < 1e-9 && (h.im - im).abs() < 1e-9,
                "{h} {re} {im}"
            );
            assert!((h.norm_sqr() - hold_response_sq(rho, w)).abs() < 1e-12);
        }
    }

    #[test]
    fn hold_noise_factor_is_the_dtft_of_the_autocovariance() {
        for (rho, w) in [(0.3, 0.01), (0.03, 0.0028), (0.5, 2.0)] {
            let q: f64 = 1.0 - rho;
            let direct: f64 = 1.0
                + 2.0
                    * (1..4000)
                        .map(|k| q.powi(k) * (w * k as f64).cos())
                        .sum::<f64>();
            assert!((direct - hold_noise_factor(rho, w)).abs() < 1e-9 * direct);
        }
        // Low-frequency limit (2 − ρ)/ρ.
        assert!((hold_noise_factor(0.3, 0.0) - 1.7 / 0.3).abs() < 1e-12);
    }

    /// ΣΔ: order 3, OSR 32 (d = 5): 7.78 + 8.45 − 29.82 + 105.35 = 91.76 dB, ENOB 14.95.
    #[test]
    fn sd_formula() {
        let s = sd_snr_db(3, 5);
        assert!((s - (7.78 + 10.0 * 7f64.log10() - 29.82 + 3.01 * 35.0)).abs() < 1e-12);
        assert!((enob(s) - (s - 1.76) / 6.02).abs() < 1e-12);
        assert!((enob(74.0) - 12.0).abs() < 0.001);
    }

    /// Mixture: without background it is the Gaussian (mean t_s, variance σ²); with only
    /// background it is the exponential-truncated first arrival; with both, the valid
    /// rate equals 1 − (1 − ρ_s)e^(−ρ_b) (signal fully in the window) and the signal
    /// fraction equals ρ_s·E[e^(−λ t_sig)]/ρ_v ≈ pile-up survival e^(−ρ_b t_s/W)·ρ_s/ρ_v.
    #[test]
    fn mixture_closed_forms() {
        let p = MixtureParams {
            signal_rate: 0.3,
            background_rate: 0.0,
            signal_depth_mm: 30.0,
            jitter_mm: 3.0,
            window_mm: 60.0,
        };
        let fa = first_arrival(&p).unwrap();
        assert!((fa.valid_rate - 0.3).abs() < 1e-9);
        assert!((fa.mean_mm - 30.0).abs() < 1e-9);
        assert!((fa.variance_mm2 - 9.0).abs() < 1e-6);
        assert!((mixture_gain(&p).unwrap() - 1.0).abs() < 1e-6);

        let q = MixtureParams {
            background_rate: 0.3,
            ..p
        };
        let fa = first_arrival(&q).unwrap();
        let rv = 1.0 - 0.7 * (-0.3f64).exp();
        assert!((fa.valid_rate - rv).abs() < 1e-6, "{}", fa.valid_rate);
        // Signal first: E[e^(−λ t)] for t ~ N(30, 3²) = e^(−λ·30 + λ²·9/2).
        let lam: f64 = 0.3 / 60.0;
        let sig = 0.3 * (-lam * 30.0 + lam * lam * 4.5).exp() / rv;
        assert!((fa.signal_fraction - sig).abs() < 1e-6);
        assert!((pileup_survival(0.3, 0.3, 0.5) - 0.3 * (-0.15f64).exp()).abs() < 1e-15);
        // Background only: first arrival of a Poisson process truncated at W.
        let b = MixtureParams {
            signal_rate: 0.0,
            background_rate: 1.0,
            ..p
        };
        let fa = first_arrival(&b).unwrap();
        let l = 1.0 / 60.0;
        let mean: f64 = (1.0 / l - (60.0 + 1.0 / l) * (-1.0f64).exp()) / (1.0 - (-1.0f64).exp());
        assert!((fa.mean_mm - mean).abs() < 1e-6, "{} {mean}", fa.mean_mm);
        assert!(
            first_arrival(&MixtureParams {
                jitter_mm: 0.0,
                ..p
            })
            .is_err()
        );
    }

    #[test]
    fn horner_is_the_nested_expression_bit_for_bit() {
        // The nested form written out, three levels (shallow enough for rustfmt), over
        // signs, magnitudes and a subtraction: the loop must give the same bits, not merely
        // close ones, since erfc and the Bessel fits were rewritten onto it.
        let c = [0.39894228, -0.03988024, 0.01787654, -0.00420059];
        for x in [0.0, 1e-9, 0.3, 0.999, 1.0, 3.75 / 7.0, 2.5, -1.7, 1e6] {
            let nested = c[0] + x * (c[1] + x * (c[2] - x * 0.00420059));
            assert_eq!(horner(x, &c).to_bits(), nested.to_bits(), "x = {x}");
        }
        assert_eq!(horner(2.0, &[]), 0.0);
        assert_eq!(horner(2.0, &[5.0]), 5.0);
        // erfc against values of the exact function (|relative error| < 1.2e-7 is the
        // fit's bound): erfc(0) = 1, erfc(1) = 0.157299207050285, erfc(−1) = 1.842700792949715.
        for (x, want) in [
            (0.0, 1.0),
            (1.0, 0.157_299_207_050_285),
            (-1.0, 1.842_700_792_949_715),
        ] {
            assert!(((erfc(x) - want) / want).abs() < 1.2e-7, "erfc({x})");
        }
    }
}
