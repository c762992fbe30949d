//! Events: the coefficients that stand out of the noise, grouped into transients with a
//! time, a sign, a measured height, duration and mean rate, and the paper's ramp-rate
//! estimator.
//!
//! # Grouping rule: one transition, one event
//! 1. A coefficient is *significant* when |w| > z·sd(w) ([`super::Thresholds`]).
//! 2. A significant coefficient with no significant descendant (a finer wavelet inside its
//!    support) is a *leaf*: the transient's finest significant localisation. Leaves never
//!    overlap. A significant coarser coefficient whose middle lies more than one finest
//!    wavelet from every leaf, where the depth steps (one finest wavelet after its middle
//!    against one before, by z sd), is a leaf over the finest wavelet around its middle: a
//!    step on a finest wavelet's border shows only in the coarser wavelet centred on it.
//! 3. Leaves whose supports touch or lie one finest wavelet apart form one group.
//! 4. Groups further apart are one group unless the cells between them are a *plateau*;
//!    a group is split at its strongest plateau of three cells (with at least one cell and
//!    one leaf each side), again until none is left. Cells [a, b) are a plateau between
//!    a transition on each side when their least-squares slope is within z sd of 0 while
//!    the slope from the level before the transition (up to one finest wavelet of cells)
//!    to their mean, and from it to the level after, each differ from theirs by more than
//!    z sd ([`super::profile`]). A ramp's depth keeps moving at its own slope, so a slow
//!    ramp whose finest coefficients sit near the threshold stays one event through the
//!    gaps in its leaves; two steps, or an impulse's rise and fall, with steady depth
//!    between them are two.
//!
//! # The resolution limit
//! Two transitions at least two finest wavelets (2·T_U, four cells) apart have at least
//! three whole cells of steady depth between them, a plateau: they are two events. Closer
//! transitions cannot be told from one ramp: two steps δ apart spread like a ramp of
//! √3·δ, so an event whose measured duration is not above 2√3·T_U (by 2 sd) is
//! *unresolved* (`Shape::Unresolved`): its height is measured, with no duration and no
//! single-ramp rate. Shown by crates/experiments/tests/it/transients.rs
//! (`transitions_two_finest_wavelets_apart_are_two_events`,
//! `transitions_closer_than_the_limit_are_one_unresolved_event`).
//! 5. A significant non-leaf coefficient joins the event of the leaves below it when they
//!    all belong to one event (the same transient seen at a coarser scale); when the
//!    leaves below it belong to several events it is listed as *spanning* (a coarse view of
//!    several transients) and joins none.
//!
//! An event's time is the span of its group and its leaves ([start, end), centre the midpoint);
//! its *peak* is its largest |w|, whose sign gives the direction: w > 0 is a depth
//! *decrease* (the paper's convention, the first half deeper than the second).
//!
//! # Measured height, duration and mean rate ([`super::profile`])
//! The height is the mean depth after the event minus before it; the duration is
//! measured at the finest scale's resolution and the mean rate is height / duration. An
//! event whose duration is not resolved (below one finest wavelet) is a *step*: it gets an
//! upper bound on its duration and a lower bound on |rate| instead. One convention:
//! every rate is dδ/dt, positive when the depth increases (the target recedes).
//!
//! An excursion (no significant net height: an impulse) reports its rise and fall with
//! their heights ([`super::profile`], "Excursions"). A step's, ramp's or unresolved
//! event's time is also fitted: the least-squares step/ramp of the cells between its
//! neighbours, with its Cramér–Rao sd (`fitted_time_s`, [`super::fit`], the same fit as an
//! array pixel's).
//!
//! # The paper's ramp rate (Suppl. S5)
//! A linear ramp δ(t) = r·t across a whole wavelet gives w = −r·T_u/4, so the paper
//! estimates the rate as r̂ = −4·w_{u′,v′}/T_u′ at the peak (`paper_rate_m_per_s`, the
//! negative of the paper's 4·w/(T/2^u′) in this crate's sign). A transient shorter than
//! the wavelet is averaged over it: a ramp of height h and duration D centred in a wavelet
//! of duration T_u gives |r̂| = (2h/T_u)·(1 − D/(2T_u)), not h/D (the paper's Fig. 12
//! reproduction, `tofprobe_experiments::paper::haar_figures`, shows both); `peak_wavelet_longer_than_event` says when that is so.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

use super::analysis::{Coefficient, Scalogram};
use super::noise::Thresholds;
use super::profile::{PLATEAU_CELLS, Profile, Shape};
use super::{register_count, register_index};
use crate::error::DspError;

/// Family-wise false-alarm probability of one frame's events: the rate every caller
/// thresholds at (the array's event maps, the flow's transient analysis, the paper's
/// transient figures).
pub const FAMILY_RATE: f64 = 0.01;

/// Which way the depth moved over an event's peak wavelet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DepthChange {
    /// w > 0: deeper in the first half (the target approaches).
    Decrease,
    /// w < 0: deeper in the second half (the target recedes).
    Increase,
}

/// One detected transient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Start of the span of its finest significant wavelets (s from the frame start).
    pub start_s: f64,
    /// End of that span (s, exclusive).
    pub end_s: f64,
    /// Midpoint of the span (s).
    pub centre_s: f64,
    /// The largest |w| of the event.
    pub peak: Coefficient,
    /// |w|/sd of the peak.
    pub peak_z: f64,
    /// Duration of the peak's wavelet, T/2^u′ (s).
    pub wavelet_duration_s: f64,
    /// Sign of the peak.
    pub change: DepthChange,
    /// The paper's ramp-rate estimator at the peak, dδ/dt = −4·w/T_u′ (m/s; positive =
    /// depth increases): the transition averaged over the peak's wavelet, the event's rate
    /// only for a ramp covering that whole wavelet.
    pub paper_rate_m_per_s: f64,
    /// The peak's wavelet is longer than the event (its measured duration, or one finest
    /// wavelet for a step): the paper's rate is then not the event's.
    pub peak_wavelet_longer_than_event: bool,
    /// What the depth profile resolves ([`Shape`]).
    pub shape: Shape,
    /// Measured height: mean depth after minus before (mm; absent at the frame's edge).
    pub height_mm: Option<f64>,
    /// Its sd under the noise model (mm).
    pub height_sd_mm: Option<f64>,
    /// Measured duration of a resolved transition (s; `shape` = ramp).
    pub duration_s: Option<f64>,
    /// Its sd under the noise model (s, delta method).
    pub duration_sd_s: Option<f64>,
    /// Measured mean rate dδ/dt = height / duration (m/s; `shape` = ramp).
    pub mean_rate_m_per_s: Option<f64>,
    /// Its sd under the noise model (m/s, delta method).
    pub mean_rate_sd_m_per_s: Option<f64>,
    /// A step's duration is below this: one finest wavelet, or more when the noise
    /// allows a longer one (s; `shape` = step).
    pub duration_upper_bound_s: Option<f64>,
    /// A step's |dδ/dt| is above this: |height| / the duration's bound (m/s; `shape` =
    /// step).
    pub abs_rate_lower_bound_m_per_s: Option<f64>,
    /// The transition's time from the least-squares step/ramp fit of the cells between
    /// the event's neighbours ([`super::fit_transition`]'s implementation; `shape` = step,
    /// ramp or unresolved, where it is the centre of the one ramp fitted) (s from the
    /// frame start).
    pub fitted_time_s: Option<f64>,
    /// Its Cramér–Rao sd under the noise model (s).
    pub fitted_time_sd_s: Option<f64>,
    /// An excursion's rise: its cell's mean depth minus the level before (mm; `shape` =
    /// excursion; negative for a dip). Below a cell's duration it is the excursion's area
    /// over the cell: height × width / τ ([`super::profile`], "Excursions").
    pub rise_mm: Option<f64>,
    /// Its sd under the noise model (mm).
    pub rise_sd_mm: Option<f64>,
    /// An excursion's fall: the level after minus its cell's mean depth (mm).
    pub fall_mm: Option<f64>,
    /// Its sd under the noise model (mm).
    pub fall_sd_mm: Option<f64>,
    /// The cell the rise and fall are measured at, [start, end) (s).
    pub excursion_cell_s: Option<(f64, f64)>,
    /// The finest wavelet's duration T/2^U (s): transitions two of these apart are told
    /// apart (module doc).
    pub finest_wavelet_s: f64,
    /// Finest and coarsest scale among the event's coefficients.
    pub finest_scale: u32,
    pub coarsest_scale: u32,
    /// The event's significant coefficients as (u, v), register order.
    pub coefficients: Vec<(u32, usize)>,
}

impl Event {
    /// One line of text (times in ms): where, which way, the measured transition (which
    /// estimator each figure is), and the paper's estimator.
    pub fn text_line(&self) -> String {
        let measured = match self.shape {
            Shape::Ramp => format!(
                "ramp: height {:+.3} ± {:.3} mm over {:.3} ± {:.3} ms, measured mean rate dδ/dt = height/duration = {:+.3} ± {:.3} m/s",
                self.height_mm.unwrap_or(f64::NAN),
                self.height_sd_mm.unwrap_or(f64::NAN),
                self.duration_s.unwrap_or(f64::NAN) * 1e3,
                self.duration_sd_s.unwrap_or(f64::NAN) * 1e3,
                self.mean_rate_m_per_s.unwrap_or(f64::NAN),
                self.mean_rate_sd_m_per_s.unwrap_or(f64::NAN),
            ),
            Shape::Step => format!(
                "step-like (no finite duration resolved): height {:+.3} ± {:.3} mm, duration < {:.3} ms, |dδ/dt| > {:.3} m/s",
                self.height_mm.unwrap_or(f64::NAN),
                self.height_sd_mm.unwrap_or(f64::NAN),
                self.duration_upper_bound_s.unwrap_or(f64::NAN) * 1e3,
                self.abs_rate_lower_bound_m_per_s.unwrap_or(f64::NAN),
            ),
            Shape::Excursion => {
                let (a, b) = self.excursion_cell_s.unwrap_or((f64::NAN, f64::NAN));
                format!(
                    "excursion: rise {:+.3} ± {:.3} mm then fall {:+.3} ± {:.3} mm at the cell {:.3}–{:.3} ms (its mean: one shorter than the cell is higher by cell/width), no significant net height ({:+.3} ± {:.3} mm), no rate",
                    self.rise_mm.unwrap_or(f64::NAN),
                    self.rise_sd_mm.unwrap_or(f64::NAN),
                    self.fall_mm.unwrap_or(f64::NAN),
                    self.fall_sd_mm.unwrap_or(f64::NAN),
                    a * 1e3,
                    b * 1e3,
                    self.height_mm.unwrap_or(f64::NAN),
                    self.height_sd_mm.unwrap_or(f64::NAN),
                )
            }
            Shape::Edge => "at the frame's edge: height, duration and rate not measured".into(),
            Shape::Unresolved => format!(
                "unresolved: height {:+.3} ± {:.3} mm over {:.3}–{:.3} ms, one ramp or several transitions closer than two finest wavelets ({:.3} ms), no single-ramp rate",
                self.height_mm.unwrap_or(f64::NAN),
                self.height_sd_mm.unwrap_or(f64::NAN),
                self.start_s * 1e3,
                self.end_s * 1e3,
                2.0 * self.finest_wavelet_s * 1e3,
            ),
        };
        let fitted = match (self.fitted_time_s, self.fitted_time_sd_s) {
            (Some(t), Some(sd)) => format!("; fitted time {:.4} ± {:.4} ms", t * 1e3, sd * 1e3),
            _ => String::new(),
        };
        format!(
            "{:.3} ms ({:.3}–{:.3} ms): depth {}; {measured}{fitted}; peak w({},{}) = {:+.4} mm ({:.1} sd) at scale {} ({:.3} ms wavelets, scales {}..{}), paper's estimator −4w/T_u = {:+.3} m/s{}",
            self.centre_s * 1e3,
            self.start_s * 1e3,
            self.end_s * 1e3,
            match self.change {
                DepthChange::Decrease => "decreases",
                DepthChange::Increase => "increases",
            },
            self.peak.u,
            self.peak.v,
            self.peak.value_mm,
            self.peak_z,
            self.peak.u,
            self.wavelet_duration_s * 1e3,
            self.coarsest_scale,
            self.finest_scale,
            self.paper_rate_m_per_s,
            if self.peak_wavelet_longer_than_event {
                " (averaged over a wavelet longer than the event: not its rate)"
            } else {
                ""
            },
        )
    }
}

/// The events of one frame and how they were found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventReport {
    /// Family-wise false-alarm probability per static frame.
    pub family_rate: f64,
    /// The two-sided z threshold per coefficient.
    pub z: f64,
    /// Number of significant coefficients.
    pub significant: usize,
    /// The events, by start time.
    pub events: Vec<Event>,
    /// Significant coefficients above several events, as (u, v).
    pub spanning: Vec<(u32, usize)>,
}

impl EventReport {
    /// Text lines: a header, then one line per event.
    pub fn text(&self) -> String {
        let mut s = format!(
            "{} event(s): {} significant coefficient(s) at |w| > {:.2} sd (false-alarm probability {} per frame){}\n",
            self.events.len(),
            self.significant,
            self.z,
            self.family_rate,
            if self.spanning.is_empty() {
                String::new()
            } else {
                format!(", {} spanning several events", self.spanning.len())
            }
        );
        for (i, e) in self.events.iter().enumerate() {
            let _ = writeln!(s, "event {}: {}", i + 1, e.text_line());
        }
        s
    }
}

/// A group of leaves: first cell, end cell, registers.
type Group = (usize, usize, Vec<usize>);

/// Splits each group at its best plateau (rule 4), again until none is left: a run of
/// [`PLATEAU_CELLS`] cells inside the group with at least one cell on each side and a leaf
/// (by its centre) on each side.
fn split_at_plateaus(
    profile: &Profile,
    mut groups: Vec<Group>,
    span: &dyn Fn(usize) -> (usize, usize),
    z: f64,
) -> Vec<Group> {
    let mut i = 0;
    while i < groups.len() {
        let (gs, ge) = (groups[i].0, groups[i].1);
        let free = (
            if i == 0 { 0 } else { groups[i - 1].1 },
            groups.get(i + 1).map_or(profile.len(), |g| g.0),
        );
        let centre = |r: usize| {
            let (a, b) = span(r);
            a + b
        };
        let best = (gs + 1..(ge + 1).saturating_sub(PLATEAU_CELLS + 1))
            .filter(|&a| {
                let cut = 2 * a + PLATEAU_CELLS;
                let left = groups[i].2.iter().filter(|&&r| centre(r) < cut).count();
                left > 0 && left < groups[i].2.len()
            })
            .filter_map(|a| {
                let run = (a, a + PLATEAU_CELLS);
                profile.plateau(free, gs, run, ge, z).map(|q| (a, q))
            })
            .max_by(|x, y| x.1.total_cmp(&y.1));
        match best {
            Some((a, _)) => {
                let cut = 2 * a + PLATEAU_CELLS;
                let (l, r): (Vec<usize>, Vec<usize>) =
                    groups[i].2.iter().partition(|&&r| centre(r) < cut);
                groups[i] = (gs, a, l);
                groups.insert(i + 1, (a + PLATEAU_CELLS, ge, r));
            }
            None => i += 1,
        }
    }
    groups
}

/// Finds the events of a scalogram under per-coefficient thresholds (module doc's rule).
pub fn detect_events(s: &Scalogram, t: &Thresholds) -> Result<EventReport, DspError> {
    let k = register_count(s.scales);
    if t.sd_mm.len() != k || s.coefficients.len() != k {
        return Err(DspError::out_of_range(
            "thresholds",
            format!("{} per-coefficient sd", t.sd_mm.len()),
            format!("= 2^(U+1) − 1 = {k} (one per coefficient of the scalogram)"),
        ));
    }
    let n = usize::try_from(s.pulses)
        .map_err(|_| DspError::out_of_range("pulses", s.pulses, "≤ usize::MAX"))?;
    let sig: Vec<bool> = s
        .coefficients
        .iter()
        .enumerate()
        .map(|(r, c)| c.value_mm.abs() > t.threshold_mm(r))
        .collect();
    // Descendant significance, bottom-up.
    let mut below = vec![false; k];
    for u in (0..s.scales).rev() {
        for v in 0..(1usize << u) {
            let (a, b) = (
                register_index(u + 1, 2 * v),
                register_index(u + 1, 2 * v + 1),
            );
            below[register_index(u, v)] = sig[a] || sig[b] || below[a] || below[b];
        }
    }
    let profile = Profile::new(s, &t.sd_mm, n);
    // Supports in profile cells (half finest wavelets).
    let support = |r: usize| {
        let c = &s.coefficients[r];
        profile.cells_of(c.u, c.v)
    };
    let mut leaves: Vec<usize> = (0..k).filter(|&r| sig[r] && !below[r]).collect();
    // Rule 2b: a significant coarser coefficient whose middle lies away from every leaf,
    // where the depth steps, is a leaf of the finest wavelet around its middle.
    let near_leaf = |m: usize| {
        leaves.iter().any(|&l| {
            let (a, b) = support(l);
            a <= m + 2 && m <= b + 2
        })
    };
    let middles: Vec<usize> = (0..k)
        .filter(|&r| sig[r] && below[r])
        .filter(|&r| {
            let (a, b) = support(r);
            let m = (a + b) / 2;
            !near_leaf(m) && profile.steps_at(m, (a, b), t.z)
        })
        .collect();
    leaves.extend(&middles);
    let span = |r: usize| {
        let (a, b) = support(r);
        if middles.contains(&r) {
            ((a + b) / 2 - 1, (a + b) / 2 + 1)
        } else {
            (a, b)
        }
    };
    leaves.sort_by_key(|&r| span(r).0);
    // Groups of leaves (first cell, end cell, registers): touching leaves (rule 3), and
    // groups whose gap the depth moves across (rule 4).
    let mut groups: Vec<Group> = Vec::new();
    for &r in &leaves {
        let (st, e) = span(r);
        let prev_end = groups.len().checked_sub(2).map_or(0, |i| groups[i].1);
        match groups.last_mut() {
            Some(g)
                if st <= g.1 + 2
                    || profile
                        .plateau((prev_end, profile.len()), g.0, (g.1, st), e, t.z)
                        .is_none() =>
            {
                g.1 = g.1.max(e);
                g.2.push(r);
            }
            _ => groups.push((st, e, vec![r])),
        }
    }
    let mut groups = split_at_plateaus(&profile, groups, &span, t.z);
    // The cells an event is shown over: its group's and its leaves' (a transition split
    // off at a plateau may end inside the plateau's first or last cell).
    let shown: Vec<(usize, usize)> = groups
        .iter()
        .map(|g| {
            g.2.iter()
                .map(|&r| span(r))
                .fold((g.0, g.1), |(a, b), (c, d)| (a.min(c), b.max(d)))
        })
        .collect();
    let mut spanning = Vec::new();
    for r in (0..k).filter(|&r| sig[r] && below[r] && !middles.contains(&r)) {
        let (st, e) = support(r);
        // Groups with a leaf inside [st, e).
        let hits: Vec<usize> = groups
            .iter()
            .enumerate()
            .filter(|(_, g)| {
                g.2.iter().any(|&l| {
                    let (ls, le) = span(l);
                    ls >= st && le <= e
                })
            })
            .map(|(i, _)| i)
            .collect();
        match hits.as_slice() {
            [one] => groups[*one].2.push(r),
            _ => spanning.push((s.coefficients[r].u, s.coefficients[r].v)),
        }
    }
    let events = (0..groups.len())
        .map(|i| {
            let (st, e) = (groups[i].0, groups[i].1);
            let prev_end = if i == 0 { 0 } else { groups[i - 1].1 };
            let next_start = groups.get(i + 1).map_or(profile.len(), |g| g.0);
            let mut regs = groups[i].2.clone();
            regs.sort_unstable();
            let peak_r = regs
                .iter()
                .copied()
                .reduce(|a, b| {
                    if s.coefficients[b].value_mm.abs() > s.coefficients[a].value_mm.abs() {
                        b
                    } else {
                        a
                    }
                })
                .unwrap_or(regs[0]);
            let peak = s.coefficients[peak_r];
            let d = peak.duration_s();
            let m = profile.measure(st, e, prev_end, next_start, t.z);
            // One transition's fit over the cells between the neighbours.
            let fit = matches!(m.shape, Shape::Step | Shape::Ramp | Shape::Unresolved)
                .then(|| profile.fit(prev_end, next_start))
                .flatten()
                .filter(|f| f.time_sd_s.is_finite());
            let longer = match m.shape {
                Shape::Ramp => m.duration_s.is_some_and(|x| d > x),
                // Not resolved by the finest wavelets: every wavelet is longer.
                Shape::Step => true,
                Shape::Excursion | Shape::Edge | Shape::Unresolved => {
                    d > profile.time_s(e) - profile.time_s(st)
                }
            };
            Event {
                start_s: profile.time_s(shown[i].0),
                end_s: profile.time_s(shown[i].1),
                centre_s: 0.5 * (profile.time_s(shown[i].0) + profile.time_s(shown[i].1)),
                peak,
                peak_z: peak.value_mm.abs() / t.sd_mm[peak_r],
                wavelet_duration_s: d,
                change: if peak.value_mm > 0.0 {
                    DepthChange::Decrease
                } else {
                    DepthChange::Increase
                },
                paper_rate_m_per_s: -4.0 * peak.value_mm / d * 1e-3,
                peak_wavelet_longer_than_event: longer,
                shape: m.shape,
                height_mm: m.height_mm,
                height_sd_mm: m.height_sd_mm,
                duration_s: m.duration_s,
                mean_rate_m_per_s: m.mean_rate_m_per_s,
                duration_sd_s: m.duration_sd_s,
                mean_rate_sd_m_per_s: m.mean_rate_sd_m_per_s,
                duration_upper_bound_s: m.duration_upper_bound_s,
                abs_rate_lower_bound_m_per_s: m.abs_rate_lower_bound_m_per_s,
                fitted_time_s: fit.map(|f| f.time_s),
                fitted_time_sd_s: fit.map(|f| f.time_sd_s),
                rise_mm: m.rise_mm,
                rise_sd_mm: m.rise_sd_mm,
                fall_mm: m.fall_mm,
                fall_sd_mm: m.fall_sd_mm,
                excursion_cell_s: m.excursion_cell_s,
                finest_wavelet_s: s.wavelet_duration_s(s.scales),
                finest_scale: regs.iter().map(|&r| s.coefficients[r].u).max().unwrap_or(0),
                coarsest_scale: regs.iter().map(|&r| s.coefficients[r].u).min().unwrap_or(0),
                coefficients: regs
                    .iter()
                    .map(|&r| (s.coefficients[r].u, s.coefficients[r].v))
                    .collect(),
            }
        })
        .collect();
    Ok(EventReport {
        family_rate: t.family_rate,
        z: t.z,
        significant: sig.iter().filter(|&&b| b).count(),
        events,
        spanning,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::haar::noise::HaarNoise;

    fn frame(depth: impl Fn(usize) -> f64, n: usize, u: u32) -> Scalogram {
        let x: Vec<f64> = (0..n).map(depth).collect();
        Scalogram::from_depths_mm(&x, u, 1e7).unwrap()
    }

    /// A noiseless step of +2 mm at sample 300 of 1024 (U = 5): its leaves are the finest
    /// wavelet holding it, the event spans that wavelet, every coarser coefficient whose
    /// support holds the step joins it, the depth increases and w < 0.
    #[test]
    fn a_step_is_one_event_at_its_wavelet() {
        let n = 1024;
        let s = frame(|i| if i >= 300 { 2.0 } else { 0.0 }, n, 5);
        let t = Thresholds::new(&HaarNoise::new(0.05, 1.0).unwrap(), n, 5, 0.01).unwrap();
        let r = detect_events(&s, &t).unwrap();
        assert_eq!(r.events.len(), 1, "{}", r.text());
        let e = &r.events[0];
        // Finest wavelets are 32 samples: 300 lies in v = 9 (288..320).
        assert_eq!((e.start_s, e.end_s), (288e-7, 320e-7));
        assert_eq!(e.change, DepthChange::Increase);
        assert!(e.peak.value_mm < 0.0 && e.paper_rate_m_per_s > 0.0);
        assert_eq!((e.coarsest_scale, e.finest_scale), (0, 5));
        assert_eq!(e.coefficients.len(), 6);
        assert!(r.spanning.is_empty());
        // The fitted time is the step's, to the golden section's 1e-6 pulse (the span's
        // centre, 304 samples, would miss by 4 pulses), and the line shows it.
        let ft = e.fitted_time_s.unwrap();
        assert!((ft - 300e-7).abs() < 1e-13, "{}", e.text_line());
        assert!(
            e.text_line().contains("fitted time 0.0300 ±"),
            "{}",
            e.text_line()
        );
        // The line names the event; a broken threshold (huge sd) finds nothing.
        assert!(r.text().contains("event 1: 0.030 ms"), "{}", r.text());
        let t_big = Thresholds::new(&HaarNoise::new(100.0, 1.0).unwrap(), n, 5, 0.01).unwrap();
        assert!(detect_events(&s, &t_big).unwrap().events.is_empty());
    }

    /// A noiseless impulse of +2 mm over samples 300..304, inside cell 18 (288..304 of
    /// 16-sample cells at U = 5): one excursion whose rise is the cell mean's +2·4/16 =
    /// +0.5 mm and fall −0.5 mm (exact: the levels are 0), at that cell, with no fitted
    /// time; one "excursion" height (≈ 0) or the impulse's 2 mm would fail.
    #[test]
    fn an_impulse_reports_its_rise_and_fall() {
        let n = 1024;
        let s = frame(|i| if (300..304).contains(&i) { 2.0 } else { 0.0 }, n, 5);
        let t = Thresholds::new(&HaarNoise::new(0.05, 1.0).unwrap(), n, 5, 0.01).unwrap();
        let r = detect_events(&s, &t).unwrap();
        assert_eq!(r.events.len(), 1, "{}", r.text());
        let e = &r.events[0];
        assert_eq!(e.shape, Shape::Excursion, "{}", r.text());
        assert!((e.rise_mm.unwrap() - 0.5).abs() < 1e-9, "{}", r.text());
        assert!((e.fall_mm.unwrap() + 0.5).abs() < 1e-9, "{}", r.text());
        assert!(e.rise_sd_mm.unwrap() > 0.0 && e.fall_sd_mm.unwrap() > 0.0);
        assert_eq!(e.excursion_cell_s, Some((288e-7, 304e-7)));
        assert!(e.fitted_time_s.is_none());
        assert!(r.text().contains("rise +0.500"), "{}", r.text());
    }

    /// Two steps far apart (down at 100, up at 900 of 1024) are two events; the
    /// coefficients above both (scale 0) are spanning; a decrease gives w > 0.
    #[test]
    fn separate_transients_are_separate_events() {
        let n = 1024;
        let s = frame(|i| if (100..900).contains(&i) { -1.0 } else { 0.0 }, n, 5);
        let t = Thresholds::new(&HaarNoise::new(0.05, 1.0).unwrap(), n, 5, 0.01).unwrap();
        let r = detect_events(&s, &t).unwrap();
        assert_eq!(r.events.len(), 2, "{}", r.text());
        assert_eq!(r.events[0].change, DepthChange::Decrease);
        assert!(r.events[0].peak.value_mm > 0.0);
        assert_eq!(r.events[1].change, DepthChange::Increase);
        assert!(r.spanning.contains(&(0, 0)));
        assert!(r.events[0].end_s <= r.events[1].start_s);
    }

    /// A linear ramp over a whole wavelet: r̂ = −4w/T_u = dδ/dt exactly (the halves' means
    /// differ by r·T_u/2 for equal halves; 1e-9 relative covers the sampling offset).
    #[test]
    fn ramp_rate_convention() {
        let n = 4096;
        let fs = 1e7;
        let rate = 50.0; // m/s = 50 mm/ms = 5e-3 mm per pulse
        let s = frame(|i| rate * 1e3 * i as f64 / fs, n, 3);
        let t = Thresholds::new(&HaarNoise::new(0.01, 1.0).unwrap(), n, 3, 0.01).unwrap();
        let r = detect_events(&s, &t).unwrap();
        for e in &r.events {
            assert!(
                (e.paper_rate_m_per_s / rate - 1.0).abs() < 1e-9,
                "{}",
                e.text_line()
            );
        }
        assert!(!r.events.is_empty());
        let mut bad = t.clone();
        bad.sd_mm.pop();
        assert!(detect_events(&s, &bad).is_err());
    }
}
