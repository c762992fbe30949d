//! The depth profile behind the coefficients, and what it measures about an event: whether
//! the depth moves across a gap between two groups of significant wavelets, and an event's
//! height, duration and mean rate.
//!
//! # The profile
//! The 2^(U+1) half-wavelets of the finest scale are the profile's *cells* (duration
//! τ = T/2^(U+1)). With w = (mean of the first half − mean of the second)/2, a cell's mean
//! depth relative to the frame's mean is x_c = Σ_u ±w_{u,v(c)} (+ in the first half of the
//! wavelet holding c, − in the second): the inverse Haar transform, exact for equal halves
//! (N divisible by 2^(U+1), always so for the pixel's power-of-two frames; otherwise the
//! halves differ by at most one sample). Every statistic below is linear in the
//! coefficients, Σ_c b_c x_c = Σ_i a_i w_i, so its sd is √(Σ a_i² sd(w_i)²) under the
//! noise model's independent coefficients ([`super::Thresholds`]).
//!
//! # Height, duration, mean rate
//! An event spanning cells [S, E), widened by one finest wavelet each side (a transition's
//! faint ends may fall short of the threshold) without reaching its neighbours, has a level
//! before it, L0 = the mean over up to E − S
//! cells before S (not reaching the previous event), and after it, L1 likewise; its height
//! is h = L1 − L0 (mm, positive when the depth increases), from the coarse structure of the
//! coefficients (a difference of window means). The depth steps between the consecutive
//! levels L0, x_S, …, x_{E−1}, L1 are a distribution of mass p_j = Δ_j/h (Σp = 1) over the
//! cell boundaries t_j; its variance is that of the transition's dδ/dt convolved with the
//! cells' box of width τ, so a linear ramp of duration D gives 12·var = D² + τ², and the
//! duration is D̂ = √(12·var − τ²) at the resolution of the finest scale. A transition is
//! *resolved* when D̂² exceeds T_U² (one finest wavelet = 2τ: a noiseless step inside one
//! cell gives at most 2τ²) by 2 sd of D̂²; then its mean rate is h/D̂. Otherwise it is
//! *step-like*: its duration is below the bound √max(T_U², D̂² + 2 sd) and |rate| above
//! |h| over that bound, and only those bounds are given. The sd of D̂² and of h/D̂ are the
//! delta method's (their gradients over the cells, through the same linear noise).
//!
//! # Excursions
//! An event whose net height is not significant (|h| ≤ z sd) is an excursion: the depth
//! leaves and returns, an impulse's rise and fall. Both are reported with their heights at
//! the cell of the event's span furthest from the mean of L0 and L1 (cell p): the rise is
//! x_p − L0 and the fall L1 − x_p. The registers hold cell means, so an excursion shorter
//! than a cell (τ) inside cell p shows its area: an impulse of height H and width w < τ
//! gives a rise of H·w/τ and a fall of −H·w/τ (the true height is H = rise·τ/w, at least
//! the rise's); crates/experiments/tests/it/transients.rs
//! (`a_step_and_an_impulse_are_one_event_each_for_every_seed`) checks that on the model.

use serde::{Deserialize, Serialize};

use super::analysis::Scalogram;
use super::support;

/// Cells (one finest wavelet) added to each side of an event's span for its measurement.
const GUARD: usize = 2;

/// A duration is resolved when D̂² exceeds T_U² by this many sd of D̂²; a step's upper
/// bound is √max(T_U², D̂² + this · sd).
const RESOLVED_Z: f64 = 2.0;

/// Two equal steps δ apart spread like a ramp of D = √3·δ (variance δ²/4 = D²/12): steps
/// under two finest wavelets apart look like a ramp of up to 2√3 finest wavelets.
const PAIR_SPREAD: f64 = 3.464_101_615_137_754_4;

/// Cells of steady depth that separate two transitions: three, the fewest whole cells
/// between two transitions two finest wavelets (four cells) apart.
pub(crate) const PLATEAU_CELLS: usize = 3;

/// The cell profile of one scalogram with its noise model.
pub(crate) struct Profile<'a> {
    sd_mm: &'a [f64],
    scales: u32,
    /// x_c − x̄ per cell (mm).
    cells: Vec<f64>,
    /// Cell boundaries (samples), cells + 1 of them.
    edges: Vec<usize>,
    fs: f64,
}

/// What the profile says about an event's transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A finite duration is resolved: duration and mean rate are measured.
    Ramp,
    /// No finite duration resolved (shorter than one finest wavelet): only an upper bound
    /// on the duration and a lower bound on |rate|.
    Step,
    /// The depth returns: no significant net height (an impulse, a there-and-back).
    Excursion,
    /// The event touches the frame's edge: no level on one side, no height.
    Edge,
    /// A transition spread over less than 2√3 finest wavelets: one ramp, or several
    /// transitions closer than two finest wavelets (module doc), which the registers cannot
    /// tell apart: the height is measured, no duration and no single-ramp rate.
    Unresolved,
}

/// The measured transition of one event (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measured {
    pub shape: Shape,
    pub height_mm: Option<f64>,
    pub height_sd_mm: Option<f64>,
    pub duration_s: Option<f64>,
    pub duration_sd_s: Option<f64>,
    pub mean_rate_m_per_s: Option<f64>,
    pub mean_rate_sd_m_per_s: Option<f64>,
    pub duration_upper_bound_s: Option<f64>,
    pub abs_rate_lower_bound_m_per_s: Option<f64>,
    /// An excursion's rise and fall (mm) with their sd (module doc, "Excursions").
    pub rise_mm: Option<f64>,
    pub rise_sd_mm: Option<f64>,
    pub fall_mm: Option<f64>,
    pub fall_sd_mm: Option<f64>,
    /// The cell the excursion's rise and fall are measured at: [start, end) (s).
    pub excursion_cell_s: Option<(f64, f64)>,
}

impl<'a> Profile<'a> {
    pub(crate) fn new(s: &Scalogram, sd_mm: &'a [f64], n: usize) -> Profile<'a> {
        let cells = s.cell_means_mm();
        let mut edges = Vec::with_capacity(cells.len() + 1);
        for v in 0..(1usize << s.scales) {
            let (a, m, _) = support(n, s.scales, v);
            edges.push(a);
            edges.push(m);
        }
        edges.push(n);
        Profile {
            sd_mm,
            scales: s.scales,
            cells,
            edges,
            fs: s.laser_rate_hz,
        }
    }

    /// Number of cells, 2^(U+1).
    pub(crate) fn len(&self) -> usize {
        self.cells.len()
    }

    /// Time of cell boundary j (s).
    pub(crate) fn time_s(&self, j: usize) -> f64 {
        self.edges[j] as f64 / self.fs
    }

    /// Cells of wavelet (u, v): [first, end).
    pub(crate) fn cells_of(&self, u: u32, v: usize) -> (usize, usize) {
        let per = self.len() >> u;
        (v * per, (v + 1) * per)
    }

    /// Σ_c b_c x_c and its sd (module doc).
    fn linear(&self, b: &[f64]) -> (f64, f64) {
        let value = b.iter().zip(&self.cells).map(|(b, x)| b * x).sum();
        let mut prefix = Vec::with_capacity(b.len() + 1);
        prefix.push(0.0);
        for &x in b {
            prefix.push(prefix.last().copied().unwrap_or(0.0) + x);
        }
        let mut var = 0.0;
        let mut r = 0;
        for u in 0..=self.scales {
            for v in 0..(1usize << u) {
                let (a, e) = self.cells_of(u, v);
                let m = (a + e) / 2;
                let coef = (prefix[m] - prefix[a]) - (prefix[e] - prefix[m]);
                var += (coef * self.sd_mm[r]).powi(2);
                r += 1;
            }
        }
        (value, var.sqrt())
    }

    /// 12·var − τ² of the depth steps over cells [s, e) of profile `x` (module doc), the
    /// levels from the windows [b0, s) and [e, a1).
    fn duration_squared(&self, x: &[f64], s: usize, e: usize, (b0, a1): (usize, usize)) -> f64 {
        let mean_of = |a: usize, b: usize| x[a..b].iter().sum::<f64>() / (b - a) as f64;
        let (l0, l1) = (mean_of(b0, s), mean_of(e, a1));
        let h = l1 - l0;
        // Levels L0, x_s..x_{e−1}, L1 and the boundaries s..=e between them.
        let mut prev = l0;
        let mut mass = Vec::with_capacity(e - s + 1);
        let levels = x[s..e].iter().copied().chain(std::iter::once(l1));
        for (j, y) in (s..=e).zip(levels) {
            mass.push((self.time_s(j), (y - prev) / h));
            prev = y;
        }
        let mean: f64 = mass.iter().map(|(t, p)| t * p).sum();
        let var: f64 = mass.iter().map(|(t, p)| (t - mean).powi(2) * p).sum();
        let tau = (self.time_s(e) - self.time_s(s)) / (e - s) as f64;
        12.0 * var - tau * tau
    }

    /// The least-squares transition of cells [a, b) ([`super::fit::fit_cells`], the one
    /// implementation), its time from the frame start; `None` under 4 cells.
    pub(crate) fn fit(&self, a: usize, b: usize) -> Option<super::fit::TransitionFit> {
        let tau = (self.time_s(b) - self.time_s(a)) / b.saturating_sub(a).max(1) as f64;
        let sigma = super::fit::cell_sigma(self.sd_mm, self.scales);
        super::fit::fit_cells(&self.cells[a..b], tau, sigma).map(|mut f| {
            f.time_s += self.time_s(a);
            f
        })
    }

    /// Mean of cells [a, b) as weights.
    fn window(&self, a: usize, b: usize) -> Vec<f64> {
        let mut w = vec![0.0; self.len()];
        let k = (b - a) as f64;
        for x in &mut w[a..b] {
            *x = 1.0 / k;
        }
        w
    }

    /// Whether the depth steps at cell boundary `m` inside `within`: the mean of up to one
    /// finest wavelet after it minus that before it exceeds z sd.
    pub(crate) fn steps_at(&self, m: usize, within: (usize, usize), z: f64) -> bool {
        let (a, b) = (
            within.0.max(m.saturating_sub(GUARD)),
            within.1.min(m + GUARD),
        );
        if a >= m || b <= m {
            return false;
        }
        let (before, after) = (self.window(a, m), self.window(m, b));
        let d: Vec<f64> = after.iter().zip(&before).map(|(x, y)| x - y).collect();
        let (v, sd) = self.linear(&d);
        v.abs() > z * sd
    }

    /// Whether cells `run` = [a, b) are a plateau between a transition over [gs, a) and
    /// one over [b, ge) (module doc, "Telling transitions apart"), with level windows of
    /// up to one finest wavelet outside [gs, ge) within `free`: the run's least-squares
    /// slope is within z sd of 0, and the slopes from the level before to the run's mean
    /// and from it to the level after each differ from the run's by more than z sd. The
    /// score is the smaller of those two |differences|/sd.
    pub(crate) fn plateau(
        &self,
        free: (usize, usize),
        gs: usize,
        (a, b): (usize, usize),
        ge: usize,
        z: f64,
    ) -> Option<f64> {
        if b < a + PLATEAU_CELLS || gs >= a || ge <= b {
            return None;
        }
        let before = (free.0.max(gs.saturating_sub(GUARD)), gs);
        let after = (ge, free.1.min(ge + GUARD));
        if before.0 >= before.1 || after.0 >= after.1 {
            return None;
        }
        // Centres in cell units (cell c spans [c, c + 1)).
        let mid = |(a, b): (usize, usize)| (a + b) as f64 / 2.0;
        let n = self.len();
        let cbar = mid((a, b)) - 0.5;
        let sxx: f64 = (a..b).map(|c| (c as f64 - cbar).powi(2)).sum();
        let mut slope = vec![0.0; n];
        for (c, x) in slope.iter_mut().enumerate().take(b).skip(a) {
            *x = (c as f64 - cbar) / sxx;
        }
        let (sp, sd_sp) = self.linear(&slope);
        if sp.abs() > z * sd_sp {
            return None;
        }
        let run = self.window(a, b);
        let side = |w: (usize, usize), sign: f64| {
            let level = self.window(w.0, w.1);
            let dist = (mid((a, b)) - mid(w)).abs();
            let g: Vec<f64> = (0..n)
                .map(|c| sign * (run[c] - level[c]) / dist - slope[c])
                .collect();
            let (v, sd) = self.linear(&g);
            v.abs() / sd.max(f64::MIN_POSITIVE)
        };
        let score = side(before, 1.0).min(side(after, -1.0));
        (score > z).then_some(score)
    }

    /// The transition of the event over cells [s, e), with free cells back to `prev_end`
    /// and up to `next_start` (module doc); `z` judges the height's significance.
    pub(crate) fn measure(
        &self,
        s: usize,
        e: usize,
        prev_end: usize,
        next_start: usize,
        z: f64,
    ) -> Measured {
        let mut m = Measured {
            shape: Shape::Edge,
            height_mm: None,
            height_sd_mm: None,
            duration_s: None,
            duration_sd_s: None,
            mean_rate_m_per_s: None,
            mean_rate_sd_m_per_s: None,
            duration_upper_bound_s: None,
            abs_rate_lower_bound_m_per_s: None,
            rise_mm: None,
            rise_sd_mm: None,
            fall_mm: None,
            fall_sd_mm: None,
            excursion_cell_s: None,
        };
        let (s0, e0) = (s, e);
        // A guard of one finest wavelet each side: a transition's faint ends (a ramp's end
        // inside a finest wavelet) may fall short of the threshold, outside the leaves.
        let s = s.saturating_sub(GUARD).max(prev_end);
        let e = (e + GUARD).min(next_start);
        let span = e - s;
        let b0 = prev_end.max(s.saturating_sub(span));
        let a1 = next_start.min(e + span);
        if b0 >= s || a1 <= e {
            return m;
        }
        let before = self.window(b0, s);
        let after = self.window(e, a1);
        let diff: Vec<f64> = after.iter().zip(&before).map(|(a, b)| a - b).collect();
        let (h, sd_h) = self.linear(&diff);
        m.height_mm = Some(h);
        m.height_sd_mm = Some(sd_h);
        if h.abs() <= z * sd_h {
            m.shape = Shape::Excursion;
            // The cell of the event's own span furthest from the mean of the two levels.
            let base = 0.5 * (self.linear(&after).0 + self.linear(&before).0);
            let p = (s0..e0)
                .max_by(|&a, &b| {
                    (self.cells[a] - base)
                        .abs()
                        .total_cmp(&(self.cells[b] - base).abs())
                })
                .unwrap_or(s0);
            let unit = self.window(p, p + 1);
            let rise: Vec<f64> = unit.iter().zip(&before).map(|(a, b)| a - b).collect();
            let fall: Vec<f64> = after.iter().zip(&unit).map(|(a, b)| a - b).collect();
            let ((r, sd_r), (f, sd_f)) = (self.linear(&rise), self.linear(&fall));
            m.rise_mm = Some(r);
            m.rise_sd_mm = Some(sd_r);
            m.fall_mm = Some(f);
            m.fall_sd_mm = Some(sd_f);
            m.excursion_cell_s = Some((self.time_s(p), self.time_s(p + 1)));
            return m;
        }
        let d2 = self.duration_squared(&self.cells, s, e, (b0, a1));
        let tau = (self.time_s(e) - self.time_s(s)) / span as f64;
        let finest = 2.0 * tau;
        // sd of D̂² and of h/D̂ by the delta method: their gradients over the cells
        // (finite differences; D̂² is smooth in the cells, h/D̂ where D̂ > 0).
        let d = d2.max(0.0).sqrt();
        let eps = 1e-6 * sd_h.max(1e-12);
        let mut x = self.cells.clone();
        let mut g2 = vec![0.0; self.len()];
        let mut gr = vec![0.0; self.len()];
        let h_of = |x: &[f64]| {
            let l = |w: &[f64]| w.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
            l(&after) - l(&before)
        };
        for c in b0..a1 {
            x[c] += eps;
            let dc2 = self.duration_squared(&x, s, e, (b0, a1));
            g2[c] = (dc2 - d2) / eps;
            if d > 0.0 {
                gr[c] = (h_of(&x) / dc2.max(0.0).sqrt() - h / d) / eps * 1e-3;
            }
            x[c] = self.cells[c];
        }
        let sd2 = self.linear(&g2).1;
        if d2 - RESOLVED_Z * sd2 >= finest * finest
            && d2 - RESOLVED_Z * sd2 < (PAIR_SPREAD * finest).powi(2)
        {
            // A spread a pair of steps under two finest wavelets apart could give.
            m.shape = Shape::Unresolved;
        } else if d2 - RESOLVED_Z * sd2 >= finest * finest {
            m.shape = Shape::Ramp;
            m.duration_s = Some(d);
            m.duration_sd_s = Some(sd2 / (2.0 * d));
            m.mean_rate_m_per_s = Some(h / d * 1e-3);
            m.mean_rate_sd_m_per_s = Some(self.linear(&gr).1);
        } else {
            let bound = (d2 + RESOLVED_Z * sd2).max(finest * finest).sqrt();
            m.shape = Shape::Step;
            m.duration_upper_bound_s = Some(bound);
            m.abs_rate_lower_bound_m_per_s = Some(h.abs() / bound * 1e-3);
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Noiseless frames of 4096 samples, U = 5 (64 cells of 64 samples, τ = 64 samples).
    fn profile_of(depth: impl Fn(usize) -> f64) -> (Scalogram, Vec<f64>) {
        let x: Vec<f64> = (0..4096).map(depth).collect();
        (
            Scalogram::from_depths_mm(&x, 5, 1.0).unwrap(),
            vec![0.01; 63],
        )
    }

    /// The inverse transform gives the cells' means; a linear ramp over 16 cells (1024
    /// samples) measures D = 1024 samples (cell-aligned: the box correction is exact to
    /// the discretisation, 1 %) and h = 3 mm; a step inside a cell is step-like; a flat gap
    /// does not move, the ramp's does.
    #[test]
    fn ramp_step_and_gap_from_the_profile() {
        let ramp = |i: usize| 3.0 * ((i as f64 - 1024.0) / 1024.0).clamp(0.0, 1.0);
        let (s, sd) = profile_of(ramp);
        let p = Profile::new(&s, &sd, 4096);
        let mean = (0..4096).map(ramp).sum::<f64>() / 4096.0;
        for c in [0, 20, 40, 63] {
            let truth = (c * 64..(c + 1) * 64).map(ramp).sum::<f64>() / 64.0 - mean;
            assert!((p.cells[c] - truth).abs() < 1e-9, "cell {c}");
        }
        let m = p.measure(16, 32, 0, 64, 3.0);
        assert_eq!(m.shape, Shape::Ramp);
        assert!((m.height_mm.unwrap() - 3.0).abs() < 1e-9);
        assert!((m.duration_s.unwrap() / 1024.0 - 1.0).abs() < 0.01, "{m:?}");
        assert!((m.mean_rate_m_per_s.unwrap() / (3.0 / 1024.0 * 1e-3) - 1.0).abs() < 0.01);
        assert!(p.steps_at(24, (16, 32), 3.0) && !p.steps_at(44, (40, 48), 3.0));
        // Inside the ramp no run of 3 cells is a plateau: its slope is the ramp's.
        assert!((17..28).all(|a| p.plateau((0, 64), 16, (a, a + 3), 32, 3.0).is_none()));
        // Two steps of +1.5 mm at samples 1300 and 1600 (cells 20 and 25, 4.7 cells
        // apart): the three cells 21..24 between them are a plateau; with the second step
        // moved to 1400 (cell 21, 1.6 cells apart) no run is.
        let two = |second: usize| {
            profile_of(move |i| 1.5 * (u8::from(i >= 1300) + u8::from(i >= second)) as f64)
        };
        let (s, _) = two(1600);
        let p = Profile::new(&s, &sd, 4096);
        assert!(p.plateau((0, 64), 20, (21, 24), 26, 3.0).is_some());
        let (s, _) = two(1400);
        let p = Profile::new(&s, &sd, 4096);
        assert!((19..24).all(|a| p.plateau((0, 64), 18, (a, a + 3), 28, 3.0).is_none()));

        // A step with (almost) no noise: the bound is one finest wavelet.
        let (s, _) = profile_of(|i| if i >= 1000 { -2.0 } else { 0.0 });
        let sd = vec![1e-9; 63];
        let p = Profile::new(&s, &sd, 4096);
        let m = p.measure(14, 16, 0, 64, 3.0);
        assert_eq!(m.shape, Shape::Step, "{m:?}");
        assert!((m.height_mm.unwrap() + 2.0).abs() < 1e-9);
        assert_eq!(m.duration_upper_bound_s, Some(128.0));
        assert!((m.abs_rate_lower_bound_m_per_s.unwrap() - 2.0 / 128.0 * 1e-3).abs() < 1e-15);
        // With noise the bound widens, and the rate's bound follows it.
        let noisy = vec![0.01; 63];
        let q = Profile::new(&s, &noisy, 4096);
        let m = q.measure(14, 16, 0, 64, 3.0);
        let ub = m.duration_upper_bound_s.unwrap();
        assert!(
            m.shape == Shape::Step && (128.0..256.0).contains(&ub),
            "{m:?}"
        );
        assert!((m.abs_rate_lower_bound_m_per_s.unwrap() - 2.0 / ub * 1e-3).abs() < 1e-15);
        // At the frame's edge there is no level before: no height.
        assert_eq!(p.measure(0, 16, 0, 64, 3.0).shape, Shape::Edge);
    }
}
