//! The time of one transition from a pixel's registers: a least-squares fit of a step or
//! a ramp to the cell profile (the inverse transform, [`super::profile`]), with its
//! uncertainty.
//!
//! # Model and fit
//! Cell c (duration τ, from c·τ) has mean x_c = L0 + h·F_c(t, D), F_c the cell's mean of
//! the ramp clamp((s − t + D/2)/D, 0, 1) centred at t with duration D (a step for D = 0).
//! For given (t, D) the levels L0 and h are linear least squares; t is searched on a grid
//! of τ/8 and refined by golden section, D on a geometric grid (0, τ/4 … 16τ). The cells
//! are independent with equal variance under white depth noise (the Haar transform is
//! orthogonal), so least squares is the maximum-likelihood fit for Gaussian noise.
//!
//! # Uncertainty
//! The sd of t̂ is the Cramér–Rao one of the fitted model: σ²·[(JᵀJ)⁻¹]_tt, J the
//! Jacobian of the cells over (L0, h, t) — and D when a ramp is fitted (D̂ ≥ τ/4) — and
//! σ the noise model's sd of one cell mean (the sum of its coefficients' variances).
//! crates/array/tests/it/validation.rs checks that edge pixels scatter by this sd.

use super::analysis::Scalogram;

/// A fitted transition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitionFit {
    /// Its centre (s from the frame start).
    pub time_s: f64,
    /// The sd of `time_s` (s).
    pub time_sd_s: f64,
    /// Height L1 − L0 (mm, positive when the depth increases).
    pub height_mm: f64,
    /// Fitted duration (s; 0 for a step).
    pub duration_s: f64,
}

/// The cell means of the unit ramp centred at t of duration d over cells of duration tau.
fn shape(k: usize, tau: f64, t: f64, d: f64) -> Vec<f64> {
    let a = t - d / 2.0;
    // G(s) = ∫_{-∞}^{s} ramp.
    let g = |s: f64| {
        if s <= a {
            0.0
        } else if d > 0.0 && s < a + d {
            (s - a).powi(2) / (2.0 * d)
        } else {
            s - a - d / 2.0
        }
    };
    (0..k)
        .map(|c| (g((c + 1) as f64 * tau) - g(c as f64 * tau)) / tau)
        .collect()
}

/// Least squares of x on (1, f): (L0, h, residual sum of squares).
fn levels(x: &[f64], f: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let (mx, mf) = (x.iter().sum::<f64>() / n, f.iter().sum::<f64>() / n);
    let (mut sff, mut sfx) = (0.0, 0.0);
    for (a, b) in f.iter().zip(x) {
        sff += (a - mf).powi(2);
        sfx += (a - mf) * (b - mx);
    }
    let h = if sff > 0.0 { sfx / sff } else { 0.0 };
    let l0 = mx - h * mf;
    let ssr = f.iter().zip(x).map(|(a, b)| (b - l0 - h * a).powi(2)).sum();
    (l0, h, ssr)
}

/// The best centre for duration d: (t, ssr).
fn best_time(x: &[f64], tau: f64, d: f64) -> (f64, f64) {
    let k = x.len();
    let ssr = |t: f64| levels(x, &shape(k, tau, t, d)).2;
    let step = tau / 8.0;
    let (mut t0, mut best) = (0.0, f64::INFINITY);
    for i in 0..=(8 * k) {
        let t = i as f64 * step;
        let s = ssr(t);
        if s < best {
            (t0, best) = (t, s);
        }
    }
    // Golden section on [t0 − step, t0 + step].
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (t0 - step, t0 + step);
    for _ in 0..40 {
        let (m1, m2) = (hi - r * (hi - lo), lo + r * (hi - lo));
        if ssr(m1) < ssr(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let t = 0.5 * (lo + hi);
    (t, ssr(t).min(best))
}

/// σ²·[(JᵀJ)⁻¹]_00 for Jacobian columns `cols`, the first being t's.
fn variance_of_first(cols: &[Vec<f64>], sigma: f64) -> f64 {
    let p = cols.len();
    let mut m: Vec<Vec<f64>> = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| cols[i].iter().zip(&cols[j]).map(|(a, b)| a * b).sum())
                .collect()
        })
        .collect();
    // Gauss–Jordan for the (0, 0) entry of the inverse: solve M y = e0.
    let mut y: Vec<f64> = (0..p).map(|i| f64::from(u8::from(i == 0))).collect();
    for c in 0..p {
        let piv = (c..p)
            .max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))
            .unwrap_or(c);
        m.swap(c, piv);
        y.swap(c, piv);
        let d = m[c][c];
        if d.abs() < 1e-300 {
            return f64::INFINITY;
        }
        for r in 0..p {
            if r != c {
                let q = m[r][c] / d;
                let pivot_row = m[c].clone();
                for (x, pv) in m[r].iter_mut().zip(&pivot_row) {
                    *x -= q * pv;
                }
                y[r] -= q * y[c];
            }
        }
    }
    sigma * sigma * y[0] / m[0][0]
}

/// The sd of one cell mean under the noise model: a cell mean is Σ ±w over one
/// coefficient per scale, so its variance is Σ_u sd_u² (`sd_mm` in register order).
pub(crate) fn cell_sigma(sd_mm: &[f64], scales: u32) -> f64 {
    (0..=scales)
        .map(|u| sd_mm[super::register_index(u, 0)].powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The least-squares transition of a scalogram (module doc), `sd_mm` the noise model's
/// sd per coefficient (register order, [`super::Thresholds::sd_mm`]); `None` for a frame
/// with fewer than 4 cells or mismatched `sd_mm`.
pub fn fit_transition(s: &Scalogram, sd_mm: &[f64]) -> Option<TransitionFit> {
    if sd_mm.len() != s.coefficients.len() {
        return None;
    }
    let x = s.cell_means_mm();
    let tau = s.duration_s() / x.len().max(1) as f64;
    fit_cells(&x, tau, cell_sigma(sd_mm, s.scales))
}

/// The fit of cell means `x` (cells of duration `tau`, noise sd `sigma` each), times from
/// the start of `x[0]`: the one implementation behind [`fit_transition`] (a whole frame)
/// and the single pixel's events (the cells between an event's neighbours,
/// [`super::events`]). `None` with fewer than 4 cells.
pub(crate) fn fit_cells(x: &[f64], tau: f64, sigma: f64) -> Option<TransitionFit> {
    let k = x.len();
    if k < 4 {
        return None;
    }
    let mut fit = (0.0, 0.0, f64::INFINITY);
    for d in [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0].map(|m| m * tau) {
        let (t, ssr) = best_time(x, tau, d);
        if ssr < fit.2 {
            fit = (t, d, ssr);
        }
    }
    let (t, d, _) = fit;
    let f = shape(k, tau, t, d);
    let (_, h, _) = levels(x, &f);
    let eps = 1e-4 * tau;
    let deriv = |g: &dyn Fn(f64) -> Vec<f64>| -> Vec<f64> {
        let (p, m) = (g(eps), g(-eps));
        p.iter()
            .zip(&m)
            .map(|(a, b)| h * (a - b) / (2.0 * eps))
            .collect()
    };
    let mut cols = vec![deriv(&|e| shape(k, tau, t + e, d)), vec![1.0; k], f.clone()];
    if d >= tau / 4.0 {
        cols.push(deriv(&|e| shape(k, tau, t, d + e)));
    }
    let var = variance_of_first(&cols, sigma);
    Some(TransitionFit {
        time_s: t,
        time_sd_s: var.sqrt(),
        height_mm: h,
        duration_s: d,
    })
}
