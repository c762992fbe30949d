//! The option that meets a corner the configured pixel misses: `tofprobe size`'s answer to
//! "the default meets its clock at every corner, or the report says which option does".
//!
//! A pixel with A adders runs K = ⌈P/A⌉ cycles per pulse, so its clock is K·f_laser: more
//! adders lower the clock the corner has to meet. For each corner whose slack is below the
//! margin ([`MARGIN_PERCENT`]), the candidates are the A where K drops below the
//! configured K, starting from the estimate K·f_laser ≤ (1 − margin)·f_max of the
//! configured netlist at that corner. The estimate is only a start: f_max moves with A
//! (the operand multiplexers shrink, the write-enable fan-out grows: on sky130 ss the B = 2
//! pixel measured 56.3, 48.7 and 46.4 MHz for A = 1, 2, 4), so each candidate is
//! synthesised (mapped on the library's typical corner, as every corner row is) and timed
//! at the corner; the first that keeps the margin is the answer, and at most
//! `max_trials` candidates are synthesised. A corner whose f_max is below
//! f_laser / (1 − margin) cannot be met by any A: the report says the laser rate it allows.

use crate::analysis::{Design, RtlProvider, analyse_point};
use crate::corners::{CornerTiming, MARGIN_PERCENT, time_cached};
use crate::error::Result;
use crate::liberty::Liberty;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One synthesised candidate at a missed corner.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CornerTrial {
    /// A.
    pub adders: u64,
    /// C = K = ⌈P/A⌉.
    pub cycles_per_pulse: u64,
    /// K·f_laser (MHz).
    pub clock_mhz: f64,
    /// f_max of this candidate's netlist at the corner (MHz).
    pub f_max_mhz: f64,
    /// Slack as a percentage of the period.
    pub slack_percent: f64,
    /// Slack ≥ the margin.
    pub meets_margin: bool,
}

/// The option found for one missed corner (JSON: `corner_options[]`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CornerOption {
    /// The corner's library (as in `timing_corners`).
    pub library: String,
    /// The corner's name.
    pub corner: String,
    /// The configured pixel's f_max at this corner (MHz).
    pub configured_f_max_mhz: f64,
    /// The A that keeps the margin, if a trial found one.
    pub adders: Option<u64>,
    /// Its C.
    pub cycles_per_pulse: Option<u64>,
    /// The candidates synthesised, in order.
    pub trials: Vec<CornerTrial>,
    /// The verdict in words.
    pub note: String,
}

/// Candidates synthesised at most per missed corner by default (`tofprobe size
/// --corner-trials`, and `tofprobe layout`'s search for a corner missed after routing).
pub const DEFAULT_TRIALS: usize = 3;

/// How a candidate is judged at a missed corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Criterion {
    /// The candidate's synthesis f_max at the corner is multiplied by this before it is
    /// judged: 1 for `size` (synthesis timing), the routed pixel's post-route / synthesis
    /// f_max at the corner for `layout` (its wires and clock tree, assumed to cost the
    /// candidate the same fraction).
    pub derate: f64,
    /// The slack kept, as a percentage of the period.
    pub margin_percent: f64,
}

impl Criterion {
    /// `size`'s: the synthesis f_max with [`MARGIN_PERCENT`] of slack (the margin a design
    /// keeps for placement, routing and clock skew).
    pub const SYNTHESIS: Criterion = Criterion {
        derate: 1.0,
        margin_percent: MARGIN_PERCENT,
    };

    /// `layout`'s: the synthesis f_max times `derate` (the routed pixel's post-route /
    /// synthesis f_max at the corner) with slack ≥ 0 (the wires are in the derate).
    pub fn post_route(derate: f64) -> Criterion {
        Criterion {
            derate,
            margin_percent: 0.0,
        }
    }
}

/// The candidate (A, K) pairs below `configured_k`, largest K first, starting at the
/// estimate from `f_max_mhz`: for each K the fewest adders ⌈P/K⌉ (its own K, ⌈P/A⌉, may be
/// smaller). Empty when even K = 1 misses the margin at `f_max_mhz`.
pub fn candidates(ops: u64, configured_k: u64, laser_hz: f64, f_max_mhz: f64) -> Vec<(u64, u64)> {
    candidates_with(ops, configured_k, laser_hz, f_max_mhz, MARGIN_PERCENT)
}

/// [`candidates`] keeping `margin_percent` of slack.
pub fn candidates_with(
    ops: u64,
    configured_k: u64,
    laser_hz: f64,
    f_max_mhz: f64,
    margin_percent: f64,
) -> Vec<(u64, u64)> {
    let usable_mhz = f_max_mhz * (1.0 - margin_percent / 100.0);
    let laser_mhz = laser_hz / 1e6;
    // NaN (no timing) compares false: no candidate.
    if ops == 0 || usable_mhz.is_nan() || usable_mhz < laser_mhz {
        return Vec::new();
    }
    let estimate = ((usable_mhz / laser_mhz).floor() as u64).max(1);
    let start = estimate.min(configured_k.saturating_sub(1)).max(1);
    let mut out: Vec<(u64, u64)> = Vec::new();
    for k in (1..=start).rev() {
        let a = ops.div_ceil(k);
        let own_k = ops.div_ceil(a);
        if out.last().is_none_or(|&(_, last)| own_k < last) {
            out.push((a, own_k));
        }
    }
    out
}

/// The advice for an option found: every `[pixel]` key it sets (the adders and the cycles
/// per pulse they allow: the adders alone keep the configured C and its clock), the clock
/// that implies, and its area against the configured pixel's on the same library.
#[allow(clippy::too_many_arguments)]
pub fn advice(
    d: &Design,
    row: &CornerTiming,
    (adders, cycles): (u64, u64),
    criterion: Criterion,
    area_um2: f64,
    configured_area_um2: f64,
    map_on: &str,
) -> String {
    let laser_mhz = d.laser_rate_hz / 1e6;
    let judged = if criterion.derate == 1.0 {
        format!("with ≥ {:.0} % slack", criterion.margin_percent)
    } else {
        format!(
            "after routing (its synthesis f_max × {:.3}, the routed pixel's post-route / synthesis ratio at this corner) with ≥ {:.0} % slack",
            criterion.derate, criterion.margin_percent
        )
    };
    format!(
        "A = {adders} adders (C = {cycles}, {:.1} MHz) meet {} {} {judged}, where the configured A = {} (C = {}, {:.1} MHz) misses it: set `[pixel] adders = {adders}` and `[pixel] cycles_per_pulse = {cycles}` (the clock C·f_laser = {cycles} × {laser_mhz} MHz = {:.1} MHz); area {:.0} µm² against the configured {:.0} µm² ({:+.1} %, synthesis on {map_on})",
        cycles as f64 * laser_mhz,
        row.library,
        row.corner,
        d.adders,
        d.cycles_per_pulse,
        d.cycles_per_pulse as f64 * laser_mhz,
        cycles as f64 * laser_mhz,
        area_um2,
        configured_area_um2,
        100.0 * (area_um2 / configured_area_um2 - 1.0),
    )
}

/// Finds the option for `row` (a corner the configured pixel misses), synthesising at
/// most `max_trials` candidates from `provider`, each mapped on `map_on` (the row's
/// library at its typical corner) and timed again at the row's corner unless it is that
/// library's own, judged by `criterion`; `configured_area_um2` is the configured pixel's
/// area on `map_on`, which the advice compares the option's with.
#[allow(clippy::too_many_arguments)]
pub fn find(
    provider: &dyn RtlProvider,
    d: &Design,
    row: &CornerTiming,
    map_on: &Liberty,
    clock: &str,
    cache: &Path,
    max_trials: usize,
    criterion: Criterion,
    configured_area_um2: f64,
) -> Result<CornerOption> {
    let mut trials = Vec::new();
    let mut found = None;
    let all = candidates_with(
        d.ops_per_pulse,
        d.cycles_per_pulse,
        d.laser_rate_hz,
        row.f_max_mhz,
        criterion.margin_percent,
    );
    for &(a, k) in all.iter().take(max_trials) {
        let Some(variant) = provider.with_adders(a, k)? else {
            break;
        };
        let clock_mhz = k as f64 * d.laser_rate_hz / 1e6;
        let point = analyse_point(
            variant.as_ref(),
            d.bins,
            d.width,
            map_on,
            true,
            clock,
            cache,
            Some(1e6 / clock_mhz),
        )?;
        let mut sta = match (&point.timing, row.library == map_on.name) {
            (Some(t), true) => t.clone(),
            _ => time_cached(&point.synthesis, &row.liberty, &row.corner, clock)?,
        };
        if criterion.derate != 1.0 {
            sta.f_max_mhz *= criterion.derate;
            sta.critical_path_ns = 1e3 / sta.f_max_mhz;
        }
        let t = CornerTiming::new(
            &row.library,
            &row.corner,
            &row.liberty,
            &sta,
            clock_mhz,
            d.laser_rate_hz,
        );
        let meets = t.slack_ns >= 1e3 / clock_mhz * criterion.margin_percent / 100.0;
        trials.push(CornerTrial {
            adders: a,
            cycles_per_pulse: k,
            clock_mhz,
            f_max_mhz: t.f_max_mhz,
            slack_percent: t.slack_percent,
            meets_margin: meets,
        });
        if meets {
            found = Some((a, k, point.synthesis.total_area_um2));
            break;
        }
    }
    let laser_mhz = d.laser_rate_hz / 1e6;
    let note = match found {
        Some((a, k, area)) => advice(
            d,
            row,
            (a, k),
            criterion,
            area,
            configured_area_um2,
            &map_on.name,
        ),
        None if all.is_empty() => format!(
            "no number of adders meets {} {}: its f_max {:.1} MHz is below f_laser / (1 − {:.0} %) = {:.1} MHz even at C = 1; the laser rate it allows is {:.2} MHz",
            row.library,
            row.corner,
            row.f_max_mhz,
            criterion.margin_percent,
            laser_mhz / (1.0 - criterion.margin_percent / 100.0),
            row.f_max_mhz * (1.0 - criterion.margin_percent / 100.0)
        ),
        None => format!(
            "none of the {} candidate(s) synthesised meets {} {} (the search stops after {max_trials}); try more adders than A = {}",
            trials.len(),
            row.library,
            row.corner,
            trials.last().map_or(d.adders, |t| t.adders)
        ),
    };
    Ok(CornerOption {
        library: row.library.clone(),
        corner: row.corner.clone(),
        configured_f_max_mhz: row.f_max_mhz,
        adders: found.map(|f| f.0),
        cycles_per_pulse: found.map(|f| f.1),
        trials,
        note,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn candidates_start_at_the_estimate_and_drop_k() {
        // The default: P = 32 operations, K = 16 at 10 MHz; sky130 ss f_max 46.8 MHz leaves
        // 42.1 MHz with the margin, so K ≤ 4 (A = 8), then K = 3 (A = 11), 2 (16), 1 (32).
        assert_eq!(
            candidates(32, 16, 10e6, 46.8),
            vec![(8, 4), (11, 3), (16, 2), (32, 1)]
        );
        // B = 2 at 25 MHz: P = 4, configured K = 4 (100 MHz); f_max 56.3 → 50.7 MHz usable,
        // K ≤ 2 (A = 2), then K = 1 (A = 4).
        assert_eq!(candidates(4, 4, 25e6, 56.3), vec![(2, 2), (4, 1)]);
        // An estimate above the configured K (the configured pixel missed by the margin
        // only on a slower netlist): start one below the configured K.
        assert_eq!(candidates(32, 16, 10e6, 500.0)[0], (3, 11));
        // K values whose fewest adders give a smaller K are not repeated: P = 5, K = 4 and
        // K = 3 both take A = 2 (its K is 3).
        assert_eq!(candidates(5, 5, 1e6, 1000.0), vec![(2, 3), (3, 2), (5, 1)]);
        // f_max below f_laser / 0.9: nothing meets, at any A.
        assert!(candidates(32, 16, 10e6, 11.0).is_empty());
        assert!(candidates(32, 16, 10e6, f64::NAN).is_empty());
        // Without a margin (a post-route judgement) the same f_max allows K ≤ 4 still
        // (46.8 MHz / 10 MHz), and at 40.1 MHz it starts at K = 4 where 10 % would give 3.
        assert_eq!(candidates_with(32, 16, 10e6, 46.8, 0.0)[0], (8, 4));
        assert_eq!(candidates_with(32, 16, 10e6, 40.1, 0.0)[0], (8, 4));
        assert_eq!(candidates(32, 16, 10e6, 40.1)[0], (11, 3));
    }

    fn default_design() -> Design {
        Design {
            bins: 16,
            width: 39,
            registers: 32,
            ops_per_pulse: 32,
            adders: 2,
            cycles_per_pulse: 16,
            laser_rate_hz: 10e6,
        }
    }

    fn ss_row() -> CornerTiming {
        let sta = crate::sta::Timing {
            critical_path_ns: 21.37,
            f_max_mhz: 1e3 / 21.37,
            startpoint: "a".into(),
            endpoint: "b".into(),
            path_cells: 9,
        };
        CornerTiming::new(
            "sky130_fd_sc_hd__ss_n40C_1v40",
            "ss_n40C_1v40",
            Path::new("ss.lib"),
            &sta,
            160.0,
            10e6,
        )
    }

    #[test]
    fn the_advice_names_every_key_the_clock_and_the_area() {
        // The case: A = 11 meets ss only with C = 3, i.e. a 30 MHz clock; setting
        // the adders alone would keep C = 16 and 160 MHz. The area figures are the
        // synthesised ones (141,000 against 100,000 µm²: +41.0 %).
        let note = advice(
            &default_design(),
            &ss_row(),
            (11, 3),
            Criterion::SYNTHESIS,
            141_000.0,
            100_000.0,
            "sky130_fd_sc_hd__tt_025C_1v80",
        );
        for want in [
            "set `[pixel] adders = 11` and `[pixel] cycles_per_pulse = 3`",
            "3 × 10 MHz = 30.0 MHz",
            "area 141000 µm² against the configured 100000 µm² (+41.0 %",
            "with ≥ 10 % slack",
            "configured A = 2 (C = 16, 160.0 MHz)",
        ] {
            assert!(note.contains(want), "{want:?} in {note}");
        }
        // After routing the judgement states its derate and keeps no margin.
        let routed = advice(
            &default_design(),
            &ss_row(),
            (8, 4),
            Criterion::post_route(0.902),
            120_000.0,
            100_000.0,
            "osu018_stdcells",
        );
        assert!(
            routed.contains("after routing (its synthesis f_max × 0.902")
                && routed.contains("with ≥ 0 % slack")
                && routed.contains("(+20.0 %"),
            "{routed}"
        );
    }
}
