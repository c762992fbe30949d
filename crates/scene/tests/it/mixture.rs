//! Variance of the measured depth when signal and background photons mix, against the law
//! of total variance: Var = ρ̂_b σ_b² + ρ̂_s σ_s² + ρ̂_b ρ̂_s (μ_s − μ_b)².

use crate::common;

use common::source;
use tofprobe_scene::MM_PER_PS;

const W_PS: f64 = 400.0;
const LSB_PS: f64 = 5.0;

/// Measured depths (mm) of all detections, the background-win fraction, and the sample
/// mean, variance and standard error of the variance (from the sample fourth moment:
/// SE(s²) ≈ sqrt((m4 − s⁴)/M)).
struct Measured {
    rho_b_hat: f64,
    mean: f64,
    var: f64,
    se_var: f64,
    se_mean: f64,
}

fn measure(depth_mm: f64, jitter_ps: f64, rho_s: f64, rho_b: f64, n: usize) -> Measured {
    let src = source(depth_mm, jitter_ps, rho_s, rho_b, 5);
    let mut out = vec![None; n];
    let c = src.fill_counted(0, &mut out);
    let d: Vec<f64> = out
        .iter()
        .flatten()
        .map(|&k| src.code_to_depth_mm(k))
        .collect();
    let m = d.len() as f64;
    let mean = d.iter().sum::<f64>() / m;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m - 1.0);
    let m4 = d.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / m;
    Measured {
        rho_b_hat: c.background_wins as f64 / c.detections as f64,
        mean,
        var,
        se_var: ((m4 - var * var) / m).sqrt(),
        se_mean: (var / m).sqrt(),
    }
}

/// The paper's closed form with a uniform background over the window: σ_b² = W²/12 (here
/// the discrete version (W² − lsb²)/12 at code centres), μ_b = window centre, σ_s² =
/// σ_I² + lsb²/12 (quantisation), and the measured mixture fractions ρ̂_b, ρ̂_s = 1 − ρ̂_b.
///
/// The closed form ignores that pile-up makes the winning background photons slightly
/// earlier than uniform (first of a Poisson process, and cut off by the signal photon). At
/// ρ_s = ρ_b = 0.02 with the signal at 3/4 of the window that bias is −0.47% of the variance
/// (exact first-photon density, integrated numerically). With N = 2·10^6 pulses there are
/// ≈ 8·10^4 detections and the standard error of the variance is ≈ 0.35%; the tolerance is
/// 4 SE plus the 0.5% model bias.
#[test]
fn mixture_variance_matches_closed_form_at_low_rates() {
    let (rho_s, rho_b, depth_mm, jitter_ps) = (0.02, 0.02, 45.0, 20.0);
    let m = measure(depth_mm, jitter_ps, rho_s, rho_b, 2_000_000);
    let w_mm = W_PS * MM_PER_PS;
    let lsb_mm = LSB_PS * MM_PER_PS;
    let var_b = (w_mm * w_mm - lsb_mm * lsb_mm) / 12.0;
    let var_s = (jitter_ps * MM_PER_PS).powi(2) + lsb_mm * lsb_mm / 12.0;
    let (pb, ps) = (m.rho_b_hat, 1.0 - m.rho_b_hat);
    let mu_b = w_mm / 2.0;
    let predicted = pb * var_b + ps * var_s + pb * ps * (depth_mm - mu_b).powi(2);
    let tol = 4.0 * m.se_var + 0.005 * predicted;
    assert!(
        (m.var - predicted).abs() < tol,
        "variance {} mm², closed form {predicted} ± {tol} (ρ̂_b = {pb})",
        m.var
    );
    // The mixture really is mixed: the cross term is a third of the total here.
    assert!(pb > 0.3 && pb < 0.7, "ρ̂_b = {pb}");
}

/// Exact reference for any rates: the first-photon density of the model, integrated on a
/// 0.01 ps grid, split into its background-win and signal-win parts; their weights, means
/// and variances give the total variance by the law of total variance.
fn exact_mixture(depth_mm: f64, jitter_ps: f64, rho_s: f64, rho_b: f64) -> (f64, f64, f64) {
    let lambda = rho_b / W_PS;
    let mu = depth_mm / MM_PER_PS;
    let dt = 0.01;
    let steps = (W_PS / dt) as usize;
    let norm = 1.0 / (jitter_ps * (2.0 * std::f64::consts::PI).sqrt());
    // (weight, Σ w·q, Σ w·q²) for background and signal wins, q = code-centre depth (mm).
    let mut b = [0.0f64; 3];
    let mut s = [0.0f64; 3];
    let mut cdf = 0.0;
    for i in 0..steps {
        let t = (i as f64 + 0.5) * dt;
        let pdf = norm * (-0.5 * ((t - mu) / jitter_ps).powi(2)).exp();
        let signal_later = 1.0 - (cdf + 0.5 * pdf * dt);
        cdf += pdf * dt;
        let no_bg_before = (-lambda * t).exp();
        let q = ((t / LSB_PS).floor() + 0.5) * LSB_PS * MM_PER_PS;
        let wb = lambda * no_bg_before * ((1.0 - rho_s) + rho_s * signal_later) * dt;
        let ws = rho_s * pdf * no_bg_before * dt;
        for (acc, w) in [(&mut b, wb), (&mut s, ws)] {
            acc[0] += w;
            acc[1] += w * q;
            acc[2] += w * q * q;
        }
    }
    let total = b[0] + s[0];
    let (pb, ps) = (b[0] / total, s[0] / total);
    let (mb, ms) = (b[1] / b[0], s[1] / s[0]);
    let (vb, vs) = (b[2] / b[0] - mb * mb, s[2] / s[0] - ms * ms);
    let var = pb * vb + ps * vs + pb * ps * (ms - mb).powi(2);
    (pb, pb * mb + ps * ms, var)
}

/// At ρ_s = ρ_b = 0.3 pile-up matters (the closed form above would be 1.6% off here); the
/// Monte Carlo must match the exact first-photon mixture. N = 10^6 pulses give ≈ 4.8·10^5
/// detections, SE of the variance ≈ 0.2%, of ρ̂_b ≈ 7·10^-4; tolerances are 4 SE.
#[test]
fn mixture_variance_matches_exact_first_photon_model() {
    let (rho_s, rho_b, depth_mm, jitter_ps) = (0.3, 0.3, 45.0, 20.0);
    let n = 1_000_000;
    let m = measure(depth_mm, jitter_ps, rho_s, rho_b, n);
    let (pb, mean, var) = exact_mixture(depth_mm, jitter_ps, rho_s, rho_b);
    let detections = n as f64 * (1.0 - (1.0 - rho_s) * (-rho_b).exp());
    let se_pb = (pb * (1.0 - pb) / detections).sqrt();
    assert!(
        (m.rho_b_hat - pb).abs() < 4.0 * se_pb,
        "ρ̂_b {} vs exact {pb}",
        m.rho_b_hat
    );
    assert!(
        (m.mean - mean).abs() < 4.0 * m.se_mean,
        "mean {} vs exact {mean}",
        m.mean
    );
    assert!(
        (m.var - var).abs() < 4.0 * m.se_var,
        "variance {} vs exact {var} ± {}",
        m.var,
        m.se_var
    );
}

/// Without background the measured depth is the signal alone: mean δ0 and variance
/// σ_I² + lsb²/12 (Sheppard's correction, accurate here since σ_I = 10 lsb). N = 10^6:
/// SE of the mean 7.5 µm, of the variance 0.14%; 5 SE.
#[test]
fn signal_only_depth_statistics() {
    let m = measure(30.0, 50.0, 1.0, 0.0, 1_000_000);
    let var = (50.0 * MM_PER_PS).powi(2) + (LSB_PS * MM_PER_PS).powi(2) / 12.0;
    assert!((m.mean - 30.0).abs() < 5.0 * m.se_mean, "mean {}", m.mean);
    assert!(
        (m.var - var).abs() < 5.0 * m.se_var,
        "var {} vs {var}",
        m.var
    );
}
