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
}
