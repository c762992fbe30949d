//! The Pareto front of area per bin against tone error, and the recommendation: of the
//! options that meet their clock on every timed library and whose worst-seed tone error
//! is within the target, the one with the least total area on the front's library.

use serde::Serialize;

use super::OptionRow;
use crate::error::ExperimentError;

/// The recommended option.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Recommendation {
    /// Option name.
    pub option: String,
    /// The `[pixel]` keys it sets, `(dotted.key, TOML value)`.
    pub overrides: Vec<(String, String)>,
    /// The library its area is read on.
    pub library: String,
    /// Its total area there (µm²).
    pub total_area_um2: f64,
    /// The baseline's total area there (µm²).
    pub baseline_area_um2: Option<f64>,
    /// Area per bin (µm², the model's slope).
    pub per_bin_um2: f64,
    /// Worst-seed tone error (µm).
    pub tone_error_um: f64,
    /// The target it meets (µm).
    pub target_error_um: f64,
    /// Smallest slack over the timed libraries (% of the period).
    pub min_slack_percent: Option<f64>,
}

fn per_bin(r: &OptionRow, lib: usize) -> f64 {
    r.libraries[lib].model.per_bin_um2
}

/// Marks `on_front` on every row no other row dominates in (area per bin on library
/// `lib`, mean tone error): a row is dominated when another is no worse in both and
/// strictly better in one.
pub fn mark(rows: &mut [OptionRow], lib: usize) {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (per_bin(r, lib), r.tone_error_um.mean))
        .collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (a, e) = pts[i];
        r.on_front = !pts
            .iter()
            .enumerate()
            .any(|(j, &(a2, e2))| j != i && a2 <= a && e2 <= e && (a2 < a || e2 < e));
    }
}

/// The recommendation, or an error that names the closest option and by how much it
/// misses (the accuracy target, or the clock when no option meets it).
pub fn recommend(
    rows: &[OptionRow],
    lib: usize,
    target_um: f64,
) -> Result<Recommendation, ExperimentError> {
    let timed: Vec<&OptionRow> = rows.iter().filter(|r| r.meets_clock).collect();
    let min_slack = |r: &OptionRow| {
        r.libraries
            .iter()
            .filter_map(|l| l.timing.as_ref().map(|t| t.slack_percent))
            .reduce(f64::min)
    };
    if timed.is_empty() {
        let best = rows
            .iter()
            .max_by(|a, b| {
                min_slack(a)
                    .unwrap_or(f64::MIN)
                    .total_cmp(&min_slack(b).unwrap_or(f64::MIN))
            })
            .map(|r| match min_slack(r) {
                Some(s) => format!("{} keeps {s:.1} %", r.option.name),
                None => format!("{} (untimed)", r.option.name),
            });
        return Err(ExperimentError::option(
            "option",
            "every option",
            &format!(
                "an option that keeps {} % slack at C·f_laser on every library; closest: {}; more adders or a lower laser rate",
                tofprobe_eda::corners::MARGIN_PERCENT,
                best.unwrap_or_else(|| "none measured".into())
            ),
        ));
    }
    let fit: Vec<&&OptionRow> = timed
        .iter()
        .filter(|r| r.tone_error_um.max <= target_um)
        .collect();
    let Some(best) = fit.iter().min_by(|a, b| {
        a.libraries[lib]
            .total_area_um2
            .total_cmp(&b.libraries[lib].total_area_um2)
    }) else {
        let closest = timed
            .iter()
            .min_by(|a, b| a.tone_error_um.max.total_cmp(&b.tone_error_um.max))
            .expect("timed is not empty");
        return Err(ExperimentError::option(
            "target-error-um",
            target_um,
            &format!(
                "a tone error some option reaches: the closest is {} at {:.3} µm (worst of {} seeds), {:.3} µm above the target; try --target-error-um {:.3}",
                closest.option.name,
                closest.tone_error_um.max,
                closest.tone_error_um.per_seed.len(),
                closest.tone_error_um.max - target_um,
                (closest.tone_error_um.max * 1000.0).ceil() / 1000.0
            ),
        ));
    };
    let baseline = rows
        .iter()
        .find(|r| r.option.name == "baseline")
        .map(|r| r.libraries[lib].total_area_um2);
    Ok(Recommendation {
        option: best.option.name.clone(),
        overrides: best.option.overrides.clone(),
        library: best.libraries[lib].library.clone(),
        total_area_um2: best.libraries[lib].total_area_um2,
        baseline_area_um2: baseline,
        per_bin_um2: per_bin(best, lib),
        tone_error_um: best.tone_error_um.max,
        target_error_um: target_um,
        min_slack_percent: min_slack(best),
    })
}
