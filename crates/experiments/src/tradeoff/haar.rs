//! The trade-off ladder of a Haar pixel: float Haar (the held record through the one float
//! front end, transformed in f64), bit-true transaction model, cycle-accurate model and
//! (with `--verilator`) the RTL, all on the same photon record and frame, each timed per
//! simulated second and scored by
//! - the coefficient error: max |Δw| (mm) against the float Haar of the same held record;
//! - the event time error: the largest distance from a float-Haar event's centre to this
//!   level's nearest event centre, and from each of the scene's transients' centres to the
//!   nearest event centre (ms).
//!
//! The cycle model runs the whole frame when it has at most [`CYCLE_FULL_MAX`] pulses
//! (scored on its own readout); a longer frame is timed on [`super::CYCLE_FRAME`] pulses
//! and extrapolated, its readout there checked bit-exact against the transaction model's,
//! and scored as the transaction model. The Verilator RTL is co-simulated against the
//! cycle model on the shortened frame (a pass is bit-exact), timed bare and extrapolated.

use std::time::Instant;

use serde::Serialize;
use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_dsp::haar::{EventReport, Scalogram};
use tofprobe_io::markdown::Table;
use tofprobe_pixel::{CycleModel, PixelError, PixelParams, ReadoutCollector, Sequencer};

use super::CYCLE_FRAME;
use crate::error::ExperimentError;
use crate::level::Level;
use crate::records::{detection_record, held_record};
use crate::transients::{
    HaarAnalysis, analyse_registers, analyse_scalogram, bit_true_registers, haar_params,
    true_transients,
};

/// Longest frame the cycle-accurate level runs whole (2^20 pulses ≈ 7·10^6 edges at U = 6).
pub const CYCLE_FULL_MAX: u64 = 1 << 20;

/// One Haar fidelity level's measurement.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct HaarLevel {
    /// Level name.
    pub level: String,
    /// Wall seconds per simulated second (f_s pulses); `None` when the level did not run.
    pub seconds_per_sim_second: Option<f64>,
    /// True when timed on a shortened frame and scaled up.
    pub extrapolated: bool,
    /// max |w − w_float| over the coefficients (mm).
    pub coefficient_err_mm: Option<f64>,
    /// Events detected.
    pub events: Option<usize>,
    /// Largest distance from a float-Haar event centre to this level's nearest (ms).
    pub event_time_err_vs_float_ms: Option<f64>,
    /// Largest distance from a scene transient's centre to the nearest event centre (ms).
    pub event_time_err_vs_true_ms: Option<f64>,
    /// How the level was scored, or why it did not run.
    pub note: String,
}

/// The Haar ladder of one configuration.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct HaarSceneResult {
    /// Where the configuration came from.
    pub origin: String,
    /// Pulses N of the frame.
    pub pulses: u64,
    /// U.
    pub scales: u32,
    /// Centres of the scene's transients (ms).
    pub true_transients_ms: Vec<f64>,
    /// One row per level.
    pub levels: Vec<HaarLevel>,
}

fn centres(e: &EventReport) -> Vec<f64> {
    e.events.iter().map(|e| e.centre_s).collect()
}

/// max over `targets` of the distance to the nearest of `found` (ms); `None` if either is
/// empty.
fn worst_nearest_ms(targets: &[f64], found: &[f64]) -> Option<f64> {
    if targets.is_empty() || found.is_empty() {
        return None;
    }
    Some(
        targets
            .iter()
            .map(|t| {
                found
                    .iter()
                    .map(|f| (f - t).abs())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
            * 1e3,
    )
}

fn max_abs_diff(a: &Scalogram, b: &Scalogram) -> f64 {
    a.coefficients
        .iter()
        .zip(&b.coefficients)
        .map(|(x, y)| (x.value_mm - y.value_mm).abs())
        .fold(0.0, f64::max)
}

/// The cycle model's registers after one frame of `stimuli` (sign-extended readout).
pub fn cycle_registers(p: &PixelParams, stimuli: &[Option<u32>]) -> Result<Vec<i64>, PixelError> {
    let seq = Sequencer::new(p, stimuli, None)?.with_status_cycle();
    let mut cm = CycleModel::new(p)?;
    let mut rc = ReadoutCollector::new(p.registers(), p.width);
    let mut first = None;
    for pins in seq {
        let o = cm.step(&pins);
        if let Some(r) = rc.push(&o) {
            first.get_or_insert(r.words);
        }
    }
    first.ok_or_else(|| PixelError::mismatch("cycle-model readout", "none", "one frame"))
}

/// Measures the Haar levels on `design` (a Haar pixel); with `verilator`, the RTL too.
pub fn measure_haar(
    design: &ResolvedDesign,
    verilator: bool,
) -> Result<HaarSceneResult, ExperimentError> {
    let p = haar_params(design)?.clone();
    let origin = design.origin.as_str();
    let px_err = |e| ExperimentError::from(DesignError::pixel(origin, e));
    let source = design.photon_source()?;
    let n = p.frame_pulses;
    let fs = design.sensor().laser_rate_hz;
    let sim_seconds = n as f64 / fs;
    let truth: Vec<f64> = true_transients(design)
        .iter()
        .map(|(a, b)| 0.5 * (a + b))
        .collect();

    // Float Haar: the held record (mm) through the one float front end, then the f64 Haar.
    let t = Instant::now();
    let detections = detection_record(&source, n);
    let depths = held_record(&source, &detections, 0.0)?;
    let float_s = Scalogram::from_depths_mm(&depths, p.haar_scales, fs)?;
    let float_secs = t.elapsed().as_secs_f64();
    drop(depths);
    // Its events under the pixel's thresholds (same noise model, same N and U).
    let reference: HaarAnalysis = analyse_scalogram(design, float_s)?;
    let float_centres = centres(&reference.events);
    let score = |level: Level,
                 secs: Option<f64>,
                 extrapolated: bool,
                 a: Option<&HaarAnalysis>,
                 note: String| {
        let c = a.map(|a| centres(&a.events));
        HaarLevel {
            level: level.name().to_string(),
            seconds_per_sim_second: secs.map(|s| s / sim_seconds),
            extrapolated,
            coefficient_err_mm: a.map(|a| max_abs_diff(&a.scalogram, &reference.scalogram)),
            events: a.map(|a| a.events.events.len()),
            event_time_err_vs_float_ms: c
                .as_ref()
                .and_then(|c| worst_nearest_ms(&float_centres, c)),
            event_time_err_vs_true_ms: c.as_ref().and_then(|c| worst_nearest_ms(&truth, c)),
            note,
        }
    };

    // The Haar ladder of the level registry, cheapest first. The bit-true transaction
    // model streams the photon source itself (the same record); the bit-exact levels
    // after it are checked against its registers.
    let (regs, bt_secs) = bit_true_registers(&p, &source, n).map_err(px_err)?;
    let bt = analyse_registers(design, &regs, n)?;
    let mut levels = Vec::new();
    for level in Level::haar_ladder(verilator) {
        match level {
            Level::FloatHaar => levels.push(score(
                level,
                Some(float_secs),
                false,
                Some(&reference),
                "f64 Haar of the held record (mm); the reference".into(),
            )),
            Level::BitTrue => levels.push(score(
                level,
                Some(bt_secs),
                false,
                Some(&bt),
                "integer registers, normalised".into(),
            )),
            Level::Cycle => {
                // The whole frame if short enough, else a shortened one.
                let short_n = if n <= CYCLE_FULL_MAX {
                    n
                } else {
                    CYCLE_FRAME.min(n)
                };
                let mut short = p.clone();
                short.frame_pulses = short_n;
                let stim = &detections[..short_n as usize];
                let t = Instant::now();
                let cregs = cycle_registers(&short, stim).map_err(px_err)?;
                let c_secs = t.elapsed().as_secs_f64() * n as f64 / short_n as f64;
                if short_n == n {
                    let ca = analyse_registers(design, &cregs, n)?;
                    let same = if cregs == regs {
                        "equal to"
                    } else {
                        "DIFFERENT from"
                    };
                    levels.push(score(
                        level,
                        Some(c_secs),
                        false,
                        Some(&ca),
                        format!("its readout, {same} the transaction model's registers"),
                    ));
                } else {
                    let mut tm = tofprobe_pixel::TransactionModel::new(&short).map_err(px_err)?;
                    tm.run(stim, None, 0).map_err(px_err)?;
                    if tm.readout().words != cregs {
                        return Err(px_err(PixelError::mismatch(
                            "cycle-accurate Haar registers",
                            "different",
                            "the transaction model's on the same frame",
                        )));
                    }
                    levels.push(score(
                        level,
                        Some(c_secs),
                        true,
                        Some(&bt),
                        format!("timed on {short_n} pulses, bit-exact with the transaction model there; scored as it"),
                    ));
                }
            }
            Level::Rtl => levels.push(verilator_level(&p, &detections, n, &bt, &score)),
            other => {
                return Err(ExperimentError::option(
                    "level",
                    other.name(),
                    "a level of the Haar ladder",
                ));
            }
        }
    }
    Ok(HaarSceneResult {
        origin: origin.to_string(),
        pulses: n,
        scales: p.haar_scales,
        true_transients_ms: truth.iter().map(|t| t * 1e3).collect(),
        levels,
    })
}

/// Builds a level's row: (name, wall s, extrapolated, its analysis, note).
type Scorer<'a> = dyn Fn(Level, Option<f64>, bool, Option<&HaarAnalysis>, String) -> HaarLevel + 'a;

/// The Verilator RTL on a shortened frame; a harness refusal (e.g. more than 64
/// registers) is a row saying why, not a failed ladder.
fn verilator_level(
    p: &PixelParams,
    detections: &[Option<u32>],
    n: u64,
    bt: &HaarAnalysis,
    score: &Scorer,
) -> HaarLevel {
    let mut rtl = p.clone();
    rtl.frame_pulses = CYCLE_FRAME.min(n);
    let work = std::env::temp_dir().join(format!("tofprobe-tradeoff-haar-{}", std::process::id()));
    let mut o = tofprobe_cosim::CosimOptions::new(&work);
    o.frames = 1;
    o.measure_bare = true;
    o.profile = tofprobe_cosim::BuildProfile::Speed;
    o.stimulus = Some(detections[..rtl.frame_pulses as usize].to_vec());
    // Removed after the run, and by an interrupt during it (tofprobe_io::live).
    let live = tofprobe_io::live::register(tofprobe_io::live::Kind::Temporary, &work);
    let r = tofprobe_cosim::cosim(&rtl, &o);
    let _ = std::fs::remove_dir_all(&work);
    drop(live);
    match r {
        Ok(rep) if rep.pass => {
            let secs = rep.bare_seconds.unwrap_or(rep.verilator_seconds);
            let per_pulse = secs / rep.pulses.max(1) as f64;
            score(
                Level::Rtl,
                Some(per_pulse * n as f64),
                true,
                Some(bt),
                format!(
                    "co-simulated bit-exact with the cycle model on {} pulses; scored as it",
                    rtl.frame_pulses
                ),
            )
        }
        Ok(rep) => score(
            Level::Rtl,
            None,
            true,
            None,
            format!(
                "co-simulation FAILED: {} mismatches; run `tofprobe cosim`",
                rep.outcome.mismatches
            ),
        ),
        Err(e) => score(Level::Rtl, None, true, None, format!("not run: {e}")),
    }
}

/// The Markdown table of one Haar scene.
pub fn markdown(r: &HaarSceneResult) -> String {
    let truth = if r.true_transients_ms.is_empty() {
        "none".to_string()
    } else {
        r.true_transients_ms
            .iter()
            .map(|t| format!("{t:.3} ms"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut t = Table::left([
        "level",
        "wall s per simulated s",
        "max abs(Δw) vs float Haar mm",
        "events",
        "event time err vs float ms",
        "vs true ms",
        "note",
    ]);
    let f = |x: Option<f64>, p: usize| x.map_or_else(|| "–".into(), |v| format!("{v:.p$}"));
    for l in &r.levels {
        t.row([
            super::level_label(&l.level, l.extrapolated),
            l.seconds_per_sim_second
                .map_or_else(|| "–".into(), |v| format!("{v:.3e}")),
            l.coefficient_err_mm
                .map_or_else(|| "–".into(), |v| format!("{v:.2e}")),
            l.events.map_or_else(|| "–".into(), |e| e.to_string()),
            f(l.event_time_err_vs_float_ms, 3),
            f(l.event_time_err_vs_true_ms, 3),
            l.note.clone(),
        ]);
    }
    format!(
        "### {} (Haar, N = {}, U = {}, scene transients at {truth})\n\n{t}",
        r.origin, r.pulses, r.scales
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coefficient error sees one code: register 0 (scale 0, N = 16 samples) off by one
    /// code of 0.75 mm reads 0.75/16 mm.
    #[test]
    fn coefficient_error_sees_one_code() {
        let regs = vec![5i64; 7];
        let a = Scalogram::from_registers(&regs, 16, 2, 0.75, 1e6).unwrap();
        let mut broken = regs.clone();
        broken[0] += 1;
        let b = Scalogram::from_registers(&broken, 16, 2, 0.75, 1e6).unwrap();
        assert_eq!(max_abs_diff(&a, &a), 0.0);
        assert_eq!(max_abs_diff(&a, &b), 0.75 / 16.0);
    }

    #[test]
    fn nearest_distances() {
        assert_eq!(worst_nearest_ms(&[1.0, 5.0], &[1.5e0, 4.0]), Some(1000.0));
        assert_eq!(worst_nearest_ms(&[], &[1.0]), None);
        assert_eq!(worst_nearest_ms(&[1.0], &[]), None);
    }
}
