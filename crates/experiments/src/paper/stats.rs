//! Seed statistics of the reproduce rows: every Table 2 value is the mean over [`SEEDS`]
//! independent records, shown with its seed-to-seed sd and two z-scores, and judged by a
//! tolerance derived from the spread (never a fixed percentage).
//!
//! Derivations (used by `table2` and `sigma_delta`):
//! - A mean over S seeds has standard error se = sd/√S (sd: std of one draw).
//! - The paper's value is one draw of the same experiment, so paper − mean has
//!   sd·sqrt(1 + 1/S); z_paper = (paper − mean)/(sd·sqrt(1 + 1/S)).
//! - The closed form is an expectation (no sampling error): z_closed = (closed − mean)/se.
//! - A noise floor is the mean magnitude over M band bins. For a Rayleigh |Y| of scale s,
//!   E|Y| = s·sqrt(π/2) and Var|Y| = s²(2 − π/2), so Var/E² = 4/π − 1 ≈ 0.273. Over M
//!   bins the variance of the mean is (Var/M)·Σ_k c_k with c_k the correlation of |Y| at
//!   bins k apart; ≈ |γ_k|², γ the window's complex correlation, and by Parseval
//!   Σ_k |γ_k|² = mean(w⁴)/mean(w²)² (Blackman: 2.35; rectangular: 1). So the relative sd of
//!   one seed's floor is sqrt((4/π − 1)·mean(w⁴)/mean(w²)²/M), i.e. M/2.35 independent bins
//!   under Blackman. Five seeds give an sd estimate with ≈ 35% relative error, so the
//!   noise rows use the larger of the measured sd and this prediction.

use tofprobe_dsp::Window;
use tofprobe_dsp::closed_form::horner;

/// The seeds of every Table 2 row (≥ 5).
pub const SEEDS: &[u64] = &[0, 1, 2, 3, 4];
/// Half-width of the acceptance interval, in standard errors (two-sided p ≈ 0.003 per row).
pub const K: f64 = 3.0;

/// Mean and sample standard deviation (n − 1).
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n.max(1.0);
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

/// Σ_k |γ_k|² = mean(w⁴)/mean(w²)² of a window (numerically over 4096 samples).
pub fn bin_correlation_sum(w: Window) -> f64 {
    let len = 4096;
    let (mut s2, mut s4) = (0.0, 0.0);
    for i in 0..len {
        let v = w.value(i, len);
        s2 += v * v;
        s4 += v.powi(4);
    }
    let n = len as f64;
    (s4 / n) / (s2 / n).powi(2)
}

/// Relative sd of one noise-floor estimate (mean |Y| over `m` contiguous band bins).
pub fn floor_rel_sd(m: usize, w: Window) -> f64 {
    ((4.0 / std::f64::consts::PI - 1.0) * bin_correlation_sum(w) / m.max(1) as f64).sqrt()
}

/// e^(−y)·I0(y) and e^(−y)·I1(y), y ≥ 0 (Abramowitz & Stegun 9.8.1–9.8.4, |ε| < 2e-7).
fn bessel_i01_scaled(y: f64) -> (f64, f64) {
    if y <= 3.75 {
        let t = (y / 3.75).powi(2);
        let i0 = horner(t, &I0_SMALL);
        let i1 = y * horner(t, &I1_SMALL);
        let e = (-y).exp();
        (i0 * e, i1 * e)
    } else {
        let u = 3.75 / y;
        let i0 = horner(u, &I0_LARGE);
        let i1 = horner(u, &I1_LARGE);
        (i0 / y.sqrt(), i1 / y.sqrt())
    }
}

/// Abramowitz & Stegun 9.8.1: I0(y) = Σ cₖ (y/3.75)^(2k), |y| ≤ 3.75.
const I0_SMALL: [f64; 7] = [
    1.0, 3.5156229, 3.0899424, 1.2067492, 0.2659732, 0.0360768, 0.0045813,
];
/// 9.8.3: I1(y)/y = Σ cₖ (y/3.75)^(2k), |y| ≤ 3.75.
const I1_SMALL: [f64; 7] = [
    0.5, 0.87890594, 0.51498869, 0.15084934, 0.02658733, 0.00301532, 0.00032411,
];
/// 9.8.2: √y e^(−y) I0(y) = Σ cₖ (3.75/y)^k, y ≥ 3.75.
const I0_LARGE: [f64; 9] = [
    0.39894228,
    0.01328592,
    0.00225319,
    -0.00157565,
    0.00916281,
    -0.02057706,
    0.02635537,
    -0.01647633,
    0.00392377,
];
/// 9.8.4: √y e^(−y) I1(y) = Σ cₖ (3.75/y)^k, y ≥ 3.75.
const I1_LARGE: [f64; 9] = [
    0.39894228,
    -0.03988024,
    -0.00362018,
    0.00163801,
    -0.01031555,
    0.02282967,
    -0.02895312,
    0.01787654,
    -0.00420059,
];

/// E|A + n| for a tone of amplitude `a` plus complex Gaussian noise whose mean magnitude
/// (the noise floor) is `floor`: the Rician mean s·sqrt(π/2)·L_½(−ν), ν = A²/(2s²),
/// s² = (2/π)·floor² per component, L_½(−ν) = e^(−ν/2)[(1+ν)I0(ν/2) + ν·I1(ν/2)].
/// Floor → 0 gives A; A → 0 gives the floor. A measured amplitude is biased up by this.
pub fn rician_mean(a: f64, floor: f64) -> f64 {
    if floor <= 0.0 {
        return a.abs();
    }
    let s2 = 2.0 / std::f64::consts::PI * floor * floor;
    let nu = a * a / (2.0 * s2);
    let (i0e, i1e) = bessel_i01_scaled(nu / 2.0);
    s2.sqrt() * (std::f64::consts::PI / 2.0).sqrt() * ((1.0 + nu) * i0e + nu * i1e)
}

/// The statistics of one row: mean, sd of one draw, standard error of the mean, z-scores.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedStats {
    pub mean: f64,
    pub sd: f64,
    pub se: f64,
    pub z_paper: Option<f64>,
    pub z_closed: Option<f64>,
}

/// Statistics of `values` (one per seed); `sd_floor` is a predicted sd of one draw used
/// when larger than the measured one (see the module doc).
pub fn seed_stats(
    values: &[f64],
    sd_floor: f64,
    paper: Option<f64>,
    closed: Option<f64>,
) -> SeedStats {
    let (mean, sd_meas) = mean_sd(values);
    let s = values.len().max(1) as f64;
    let sd = sd_meas.max(sd_floor);
    let se = sd / s.sqrt();
    let z = |v: f64, d: f64| if d > 0.0 { (v - mean) / d } else { f64::NAN };
    SeedStats {
        mean,
        sd,
        se,
        z_paper: paper.map(|p| z(p, sd * (1.0 + 1.0 / s).sqrt())),
        z_closed: closed.map(|c| z(c, se)),
    }
}

impl super::Row {
    /// Attaches the seed statistics (seeds, sd, band, z-scores) to a judged row.
    pub fn with_seeds(mut self, seeds: &[u64], st: &SeedStats, band: Option<(f64, f64)>) -> Self {
        self.seeds = seeds.to_vec();
        self.seed_sd = Some(st.sd);
        self.band_hz = band;
        self.z_paper = st.z_paper.filter(|z| z.is_finite());
        self.z_closed_form = st.z_closed.filter(|z| z.is_finite());
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blackman_correlation_and_floor_sd() {
        let c = bin_correlation_sum(Window::Blackman);
        assert!((c - 2.348).abs() < 0.01, "{c}");
        assert!((bin_correlation_sum(Window::Rectangular) - 1.0).abs() < 1e-12);
        // 9000 band bins (1–10 kHz at N = 10^7): 0.84% per seed.
        let r = floor_rel_sd(9000, Window::Blackman);
        assert!((r - 0.00844).abs() < 2e-4, "{r}");
        let st = seed_stats(&[1.0, 2.0, 3.0], 0.0, Some(4.0), Some(2.0));
        assert_eq!((st.mean, st.sd), (2.0, 1.0));
        assert!((st.se - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        assert!((st.z_paper.unwrap() - 2.0 / (4.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(st.z_closed, Some(0.0));
    }

    /// Rician mean: the limits, and a Monte Carlo of |A + n| (200k draws, se ≈ 0.1%).
    #[test]
    fn rician_mean_limits_and_monte_carlo() {
        assert!((rician_mean(0.0, 2.0) - 2.0).abs() < 1e-6);
        let hi = rician_mean(100.0, 1.0);
        // A + s²/(2A), s² = 2/π.
        assert!(
            (hi - (100.0 + 1.0 / (std::f64::consts::PI * 100.0))).abs() < 1e-4,
            "{hi}"
        );
        // Box–Muller on a 64-bit LCG (no rand dependency in this crate).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut unif = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (a, floor) = (1.0, 1.0);
        let s = (2.0 / std::f64::consts::PI).sqrt() * floor;
        let draws = 200_000;
        let m: f64 = (0..draws)
            .map(|_| {
                let (u, v) = (unif(), unif());
                let r = (-2.0 * u.ln()).sqrt();
                let th = 2.0 * std::f64::consts::PI * v;
                (a + s * r * th.cos()).hypot(s * r * th.sin())
            })
            .sum::<f64>()
            / draws as f64;
        let r = rician_mean(a, floor);
        assert!((m / r - 1.0).abs() < 0.005, "{m} vs {r}");
    }
}
