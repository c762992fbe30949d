//! Table 2's closed-form predictions of a row: the noise floor over the band's bins (eq. 12
//! with the background mixture and the hold's noise factor) and the tone's expected
//! amplitude, from `tofprobe_dsp::closed_form`.

use tofprobe_dsp::closed_form::{
    MixtureParams, first_arrival, hold_noise_factor, hold_response_sq, mixture_gain, noise_floor_mm,
};
use tofprobe_dsp::stats::NoiseBand;

use super::super::setup::{FS_HZ, LSB_MM};
use super::{BAND, F0_HZ, Spec, WINDOW, tone_bin};
use crate::ExperimentError;

/// Number of DFT bins the noise floor of a row averages (the band minus DC and tone).
pub fn band_bins(spec: &Spec, n: usize) -> Result<usize, ExperimentError> {
    let tones: Vec<f64> = if spec.amp_um.is_some() {
        vec![tone_bin(n) as f64]
    } else {
        vec![]
    };
    Ok(NoiseBand::new(BAND.0, BAND.1)
        .bins(n / 2 + 1, n, FS_HZ, &tones)?
        .len())
}

/// The closed-form noise floor of a row over the same band bins (µm): eq. 12 with the
/// mixture variance (plus a²/12) and the held-noise factor F(ρ_v, ω) averaged as
/// sqrt(F) over the band's bins, like the measured mean magnitude.
pub fn closed_form_noise_um(spec: &Spec, n: usize) -> Result<f64, ExperimentError> {
    let tones: Vec<f64> = if spec.amp_um.is_some() {
        vec![tone_bin(n) as f64]
    } else {
        vec![]
    };
    let bins = NoiseBand::new(BAND.0, BAND.1).bins(n / 2 + 1, n, FS_HZ, &tones)?;
    let bins: Vec<u64> = bins.into_iter().map(|k| k as u64).collect();
    closed_form_noise_on_bins_um(spec, n, &bins)
}

/// The closed-form noise floor (µm) read as the mean magnitude over the DFT bins `bins`
/// of an N-pulse record: eq. 12 with the mixture variance (plus a²/12), N_eff of the
/// Blackman window, and the held-noise factor F(ρ_v, ω) averaged as sqrt(F) over `bins`.
/// The probe columns read the floor on their own bins (`sigma_delta::probe_bins`).
pub fn closed_form_noise_on_bins_um(
    spec: &Spec,
    n: usize,
    bins: &[u64],
) -> Result<f64, ExperimentError> {
    closed_form_noise_on_bins_for(spec, n, bins, &|rho, w| Ok(hold_noise_factor(rho, w)))
}

/// [`closed_form_noise_on_bins_um`] for any imputation whose held noise, in units of the
/// detections' variance, is `factor(ρ_v, ω)` (the hold's F(ρ, ω); the α-β form's
/// `tofprobe_dsp::imputation::response::noise_factor`).
pub fn closed_form_noise_on_bins_for(
    spec: &Spec,
    n: usize,
    bins: &[u64],
    factor: &dyn Fn(f64, f64) -> Result<f64, tofprobe_dsp::DspError>,
) -> Result<f64, ExperimentError> {
    let setup = spec.setup();
    let fa = first_arrival(&MixtureParams {
        signal_rate: spec.rho_s,
        background_rate: spec.rho_b,
        signal_depth_mm: setup.depth_mm(),
        jitter_mm: setup.jitter_mm()?,
        window_mm: setup.window_mm,
    })?;
    let sigma = (fa.variance_mm2 + LSB_MM * LSB_MM / 12.0).sqrt();
    let mut sum_sqrt_f = 0.0;
    for &k in bins {
        let w = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        sum_sqrt_f += factor(fa.valid_rate.min(1.0), w)?.sqrt();
    }
    let mean_sqrt_f = sum_sqrt_f / bins.len().max(1) as f64;
    let n_eff = n as f64 * WINDOW.effective_length_factor();
    Ok(noise_floor_mm(sigma, n_eff) * mean_sqrt_f * 1e3)
}

/// The expected SNR (dB) of `20·log10(Â/N̂)` for a tone read as the Rician mean of
/// amplitude `a_eff` in a floor `floor` (µm), N̂ a mean over `floor_rel_sd` relative sd:
/// the delta method's second-order terms. With Â = m + e_A (var (2/π)·floor², the noise's
/// projection on the tone) and N̂ = floor·(1 + e_N), E[ln Â] ≈ ln m − var_A/(2m²) and
/// E\[ln N̂\] ≈ ln floor − rel²/2, so E\[SNR\] ≈ 20·log10(m/floor) + (10/ln 10)·(rel² −
/// var_A/m²): −0.31 dB at A/floor = 3, −0.0002 dB at 130.
pub fn snr_closed_db(a_eff: f64, floor: f64, floor_rel_sd: f64) -> f64 {
    let m = super::super::stats::rician_mean(a_eff, floor);
    let var_a = 2.0 / std::f64::consts::PI * floor * floor;
    20.0 * (m / floor).log10()
        + 10.0 / std::f64::consts::LN_10 * (floor_rel_sd.powi(2) - var_a / (m * m))
}

/// The expected tone amplitude (µm): the mixture's mean follows the signal with gain
/// g = ∂μ/∂t_s, and the hold's mean response at f0 is |H(ρ_v, ω0)|.
pub fn closed_form_amp_um(spec: &Spec) -> Result<Option<f64>, ExperimentError> {
    closed_form_amp_for(spec, &|rho, w| Ok(hold_response_sq(rho, w)))
}

/// [`closed_form_amp_um`] for any imputation whose mean response is `response_sq(ρ_v, ω)`
/// (|H|²; the hold's, or the α-β form's `response::mean_response` squared).
pub fn closed_form_amp_for(
    spec: &Spec,
    response_sq: &dyn Fn(f64, f64) -> Result<f64, tofprobe_dsp::DspError>,
) -> Result<Option<f64>, ExperimentError> {
    let Some(a) = spec.amp_um else {
        return Ok(None);
    };
    let setup = spec.setup();
    let p = MixtureParams {
        signal_rate: spec.rho_s,
        background_rate: spec.rho_b,
        signal_depth_mm: setup.depth_mm(),
        jitter_mm: setup.jitter_mm()?,
        window_mm: setup.window_mm,
    };
    let g = mixture_gain(&p)?;
    let rho_v = first_arrival(&p)?.valid_rate.min(1.0);
    let w0 = 2.0 * std::f64::consts::PI * F0_HZ / FS_HZ;
    Ok(Some(a * g * response_sq(rho_v, w0)?.sqrt()))
}

/// The number of DFT bins "A meas." of a row without a tone is the largest of (those of
/// [`super::PEAK_BAND`] in an N-pulse record).
pub fn peak_band_bins(n: usize) -> usize {
    let df = FS_HZ / n as f64;
    let lo = ((super::PEAK_BAND.0 / df).ceil() as usize).max(1);
    let hi = ((super::PEAK_BAND.1 / df).floor() as usize).min((n / 2).saturating_sub(1));
    hi.saturating_sub(lo) + 1
}

/// Mean and sd of the largest of `m` independent Rayleigh magnitudes whose mean (the
/// noise floor) is `floor`: with s² = (2/π)·floor² per component, P(max ≤ x) =
/// (1 − e^(−x²/2s²))^m, so E\[max\] = ∫₀^∞ (1 − F^m) dx and E\[max²\] = ∫₀^∞ 2x(1 − F^m) dx
/// (Simpson, 4000 steps to 12 s beyond the mode). The Blackman window correlates
/// neighbouring bins, but over a finite range: the maximum of such a stationary sequence
/// behaves as that of m independent values (Berman's condition), and the reproduction's
/// no-tone rows agree (3.5–3.7 floors measured against 3.65 for 19,000 bins).
pub fn largest_bin_um(floor: f64, m: usize) -> (f64, f64) {
    let s = floor * (2.0 / std::f64::consts::PI).sqrt();
    let mf = m.max(1) as f64;
    let tail = |x: f64| {
        let f = -(-(x * x) / (2.0 * s * s)).exp();
        // 1 − (1 − e^(−y))^m without cancellation.
        -((mf * f.ln_1p()).exp_m1())
    };
    let top = s * ((2.0 * mf.ln()).max(1.0).sqrt() + 12.0);
    let steps = 4000usize;
    let h = top / steps as f64;
    let (mut m1, mut m2) = (0.0, 0.0);
    for i in 0..=steps {
        let x = i as f64 * h;
        let w = if i == 0 || i == steps {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let t = tail(x);
        m1 += w * t;
        m2 += w * 2.0 * x * t;
    }
    let (m1, m2) = (m1 * h / 3.0, m2 * h / 3.0);
    (m1, (m2 - m1 * m1).max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest of m Rayleigh bins: m = 1 is one bin (mean = the floor, sd =
    /// floor·sqrt(4/π − 1)); m = 19,001 gives 3.645 floors (Gumbel: s·(sqrt(2 ln m) +
    /// γ/sqrt(2 ln m)) = 3.645, sd s·π/sqrt(6)/sqrt(2 ln m) = 0.231); and a Monte Carlo of
    /// 2000 maxima of 1000 bins (se of the mean ≈ 0.5 %) agrees within 2 %.
    #[test]
    fn largest_bin_against_limits_and_monte_carlo() {
        let (m1, s1) = largest_bin_um(2.0, 1);
        assert!((m1 - 2.0).abs() < 1e-6, "{m1}");
        assert!(
            (s1 - 2.0 * (4.0 / std::f64::consts::PI - 1.0).sqrt()).abs() < 1e-5,
            "{s1}"
        );
        let (m, s) = largest_bin_um(1.0, 19_001);
        assert!(
            (m - 3.645).abs() < 0.01 && (s - 0.231).abs() < 0.02,
            "{m} {s}"
        );
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut unif = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let scale = (2.0 / std::f64::consts::PI).sqrt();
        let draws = 2000;
        let mean = (0..draws)
            .map(|_| {
                (0..1000)
                    .map(|_| scale * (-2.0 * unif().ln()).sqrt())
                    .fold(0.0, f64::max)
            })
            .sum::<f64>()
            / draws as f64;
        let (want, _) = largest_bin_um(1.0, 1000);
        assert!((mean / want - 1.0).abs() < 0.02, "{mean} vs {want}");
    }
}
