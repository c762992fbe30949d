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

/// G(s) = ∫_{-∞}^{s} of the unit ramp centred at t of duration d (a step for d = 0).
#[inline]
fn ramp_integral(s: f64, t: f64, d: f64) -> f64 {
    let a = t - d / 2.0;
    if s <= a {
        0.0
    } else if d > 0.0 && s < a + d {
        (s - a).powi(2) / (2.0 * d)
    } else {
        s - a - d / 2.0
    }
}

/// The cell means of the unit ramp centred at t of duration d over cells of duration tau.
fn shape(k: usize, tau: f64, t: f64, d: f64) -> Vec<f64> {
    let g = |s: f64| ramp_integral(s, t, d);
    (0..k)
        .map(|c| (g((c + 1) as f64 * tau) - g(c as f64 * tau)) / tau)
        .collect()
}

/// Below this Σ(f − f̄)² the shape is flat (the transition outside the frame): the cell
/// fractions lie in [0, 1], a transition an eighth of a cell inside the frame gives
/// ≈ 0.015, and a flat shape's rounding (boundary differences over τ) ≈ 1e-30 — which a
/// regression on it would fit as a spurious height of any size (once: times at 0 with
/// heights past the threshold).
const FLAT: f64 = 1e-9;

/// The height h of the least squares of x on (1, f).
fn height(x: &[f64], f: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, mf) = (x.iter().sum::<f64>() / n, f.iter().sum::<f64>() / n);
    let (mut sff, mut sfx) = (0.0, 0.0);
    for (a, b) in f.iter().zip(x) {
        sff += (a - mf).powi(2);
        sfx += (a - mf) * (b - mx);
    }
    if sff > FLAT { sfx / sff } else { 0.0 }
}

/// The residual sum of squares of one pixel's cells against the unit ramp (t, d) with its
/// best levels, allocation-free. A fit evaluates it 8·(k + 60) times (k cells, eight
/// durations); building the shape and refitting the levels on a fine grid over the whole
/// frame (9k a duration) made the fits of a 256 × 256 Haar frame take 33 CPU-s against
/// the model's 0.35 (now ≈ 4).
struct Residual<'a> {
    x: &'a [f64],
    tau: f64,
    mx: f64,
    sxx: f64,
    /// G(c·τ) at the k + 1 cell boundaries ([`ramp_integral`]), then
    /// the centred shape f_c − f̄ in its first k.
    g: Vec<f64>,
}

impl<'a> Residual<'a> {
    fn new(x: &'a [f64], tau: f64) -> Self {
        let mx = x.iter().sum::<f64>() / x.len() as f64;
        let sxx = x.iter().map(|v| (v - mx).powi(2)).sum();
        Self {
            x,
            tau,
            mx,
            sxx,
            g: vec![0.0; x.len() + 1],
        }
    }

    fn ssr(&mut self, t: f64, d: f64) -> f64 {
        let (k, tau) = (self.x.len(), self.tau);
        for (c, g) in self.g.iter_mut().enumerate() {
            *g = ramp_integral(c as f64 * tau, t, d);
        }
        // Σ f_c telescopes to (G(kτ) − G(0))/τ; f − f̄ overwrites G, its cell's left edge.
        let mf = (self.g[k] - self.g[0]) / tau / k as f64;
        let (mut sff, mut sfx) = (0.0, 0.0);
        for c in 0..k {
            let f = (self.g[c + 1] - self.g[c]) / tau - mf;
            self.g[c] = f;
            sff += f * f;
            sfx += f * (self.x[c] - self.mx);
        }
        if sff <= FLAT {
            return self.sxx;
        }
        // The residuals summed, not Sxx − Sfx²/Sff: that difference cancels near a close
        // fit and would blur the minimum the golden section looks for.
        let h = sfx / sff;
        self.x
            .iter()
            .zip(&self.g)
            .map(|(x, f)| (x - self.mx - h * f).powi(2))
            .sum()
    }

    /// The best centre for duration d: (t, ssr) — on a grid of τ over the frame, then of
    /// τ/8 within a cell of its best, then by golden section within an eighth of a cell
    /// (k + 60 residuals, not the 9k of a fine grid over the frame: the fit's cost grows as
    /// k, not k²).
    fn best_time(&mut self, d: f64) -> (f64, f64) {
        let tau = self.tau;
        let (coarse, _) = self.grid(0.0, tau, self.x.len(), d);
        let step = tau / 8.0;
        let (t0, best) = self.grid(coarse - tau, step, 16, d);
        // Golden section on [t0 − step, t0 + step], one new residual a step.
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let (mut lo, mut hi) = (t0 - step, t0 + step);
        let (mut m1, mut m2) = (hi - r * (hi - lo), lo + r * (hi - lo));
        let (mut s1, mut s2) = (self.ssr(m1, d), self.ssr(m2, d));
        for _ in 0..40 {
            if s1 < s2 {
                (hi, m2, s2) = (m2, m1, s1);
                m1 = hi - r * (hi - lo);
                s1 = self.ssr(m1, d);
            } else {
                (lo, m1, s1) = (m1, m2, s2);
                m2 = lo + r * (hi - lo);
                s2 = self.ssr(m2, d);
            }
        }
        let t = 0.5 * (lo + hi);
        (t, self.ssr(t, d).min(best))
    }

    /// The first least residual over t = start + i·step, i = 0..=n: (t, ssr).
    fn grid(&mut self, start: f64, step: f64, n: usize, d: f64) -> (f64, f64) {
        let (mut t0, mut best) = (start, f64::INFINITY);
        for i in 0..=n {
            let t = start + i as f64 * step;
            let s = self.ssr(t, d);
            if s < best {
                (t0, best) = (t, s);
            }
        }
        (t0, best)
    }
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
    let mut residual = Residual::new(x, tau);
    for d in [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0].map(|m| m * tau) {
        let (t, ssr) = residual.best_time(d);
        if ssr < fit.2 {
            fit = (t, d, ssr);
        }
    }
    let (t, d, _) = fit;
    let f = shape(k, tau, t, d);
    let h = height(x, &f);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The naive residual: the cell shape built, then the levels refitted by least squares.
    fn naive_ssr(x: &[f64], tau: f64, t: f64, d: f64) -> f64 {
        let f = shape(x.len(), tau, t, d);
        let h = height(x, &f);
        let n = x.len() as f64;
        let l0 = x.iter().sum::<f64>() / n - h * f.iter().sum::<f64>() / n;
        f.iter().zip(x).map(|(a, b)| (b - l0 - h * a).powi(2)).sum()
    }

    #[test]
    fn the_fast_residual_is_the_naive_least_squares() {
        // A noisy step of 1 mm at 5.3 cells over 16 cells (a fixed LCG for the noise).
        let mut state = 7u64;
        let x: Vec<f64> = (0..16)
            .map(|c| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                f64::from(u8::from(c >= 5)) + 0.1 * noise
            })
            .collect();
        let tau = 1e-4;
        let mut fast = Residual::new(&x, tau);
        for d in [0.0, 0.5, 3.0, 16.0] {
            for i in -4..140 {
                let t = f64::from(i) * tau / 8.0;
                let (a, b) = (fast.ssr(t, d * tau), naive_ssr(&x, tau, t, d * tau));
                // Two summation orders of ≤ 16 terms of size ≤ 1: agree to 1e-12 absolute.
                assert!((a - b).abs() < 1e-12, "t {t} d {d}: {a} vs {b}");
            }
        }
        // The fit finds the step: centre at 5 cells within an eighth of a cell, a step.
        let f = fit_cells(&x, tau, 0.1 / 12f64.sqrt()).unwrap();
        assert!((f.time_s - 5.0 * tau).abs() < tau / 8.0, "{f:?}");
        assert!((f.height_mm - 1.0).abs() < 0.1, "{f:?}");
        // Noise alone (the same draws without the step): where the shape is flat (t at or
        // outside the frame's edges) its rounding is no regressor, so no height beyond the
        // noise's (sd 0.029 a cell; the best of ≈ 700 trial steps stays under 10 sd).
        let noise: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(c, v)| v - f64::from(u8::from(c >= 5)))
            .collect();
        let f = fit_cells(&noise, tau, 0.1 / 12f64.sqrt()).unwrap();
        assert!(f.height_mm.abs() < 0.3, "{f:?}");
    }
}
