//! `adders = "auto"`: the fewest shared adders whose pixel meets the laser rate on a liberty,
//! decided from measured timing, as part of the one resolution.
//!
//! A pixel with A adders needs K = ⌈P/A⌉ slots per pulse for its P operations, so it runs
//! at the slowest clock K·f_laser with C = K cycles per pulse. More adders for the same K
//! only cost area, so the candidates are the A where K changes, fewest first. Each
//! candidate's pixel is rendered, synthesised with the delay-driven script for its clock
//! and timed with OpenSTA (`tofprobe_eda::analysis`, cached by the RTL's hash, as the
//! size report's points are); the first whose slack keeps [`MARGIN_PERCENT`] of the
//! period wins. Typically two syntheses: A = 1 (P cycles: too fast a clock) and A = 2.

use std::path::{Path, PathBuf};

use serde::Serialize;
use tofprobe_eda::analysis::analyse_point;
use tofprobe_eda::corners::{CornerTiming, MARGIN_PERCENT};
use tofprobe_eda::fsutil::synth_cache_dir;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::signoff::OSU018_LIBERTY;
use tofprobe_pixel::config::Choice;
use tofprobe_pixel::{PixelConfig, PixelContext, PixelError, PixelParams};

use crate::error::DesignError;

/// One candidate: A adders at C = ⌈P/A⌉ cycles per pulse, timed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdderTrial {
    /// A.
    pub adders: usize,
    /// C = K = ⌈P/A⌉.
    pub cycles_per_pulse: usize,
    /// C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Measured f_max (MHz).
    pub f_max_mhz: f64,
    /// Slack as a percentage of the clock period.
    pub slack_percent: f64,
    /// slack ≥ [`MARGIN_PERCENT`] %.
    pub meets: bool,
}

/// What `adders = "auto"` chose, and the evidence.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdderChoice {
    /// The chosen A.
    pub adders: usize,
    /// Its C = ⌈P/A⌉.
    pub cycles_per_pulse: usize,
    /// The liberty timed on.
    pub liberty: PathBuf,
    /// The slack margin required (% of the period).
    pub margin_percent: f64,
    /// Every candidate timed, fewest adders first; the last is the chosen one.
    pub trials: Vec<AdderTrial>,
}

impl AdderChoice {
    /// The note every command prints.
    pub fn note(&self) -> String {
        let lib = self.liberty.file_name().map_or_else(
            || self.liberty.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let chosen = self.trials.last().expect("a choice has its trial");
        let mut s = format!(
            "adders = \"auto\": A = {}, C = {} ({:.1} MHz) on {lib}: f_max {:.1} MHz, {:.1} % slack (margin {:.0} %)",
            self.adders,
            self.cycles_per_pulse,
            chosen.clock_mhz,
            chosen.f_max_mhz,
            chosen.slack_percent,
            self.margin_percent
        );
        for t in &self.trials[..self.trials.len() - 1] {
            s += &format!(
                "; A = {} would need {:.1} MHz (C = {}), f_max {:.1} MHz",
                t.adders, t.clock_mhz, t.cycles_per_pulse, t.f_max_mhz
            );
        }
        s
    }
}

fn key_error(value: &str, reason: impl ToString) -> PixelError {
    PixelError::invalid(
        "timing_liberty",
        format!("\"{value}\""),
        reason,
        "\"osu018\", \"sky130\" or the path of a liberty with timing",
    )
}

/// The liberty `pixel.timing_liberty` names (see [`PixelConfig::timing_liberty`]).
fn liberty(name: Option<&str>, cache: &Path) -> Result<Liberty, PixelError> {
    let path = match name.unwrap_or("osu018") {
        "osu018" => PathBuf::from(OSU018_LIBERTY),
        "sky130" => {
            let pdk = Sky130Pdk::discover(None)
                .map_err(|e| key_error("sky130", e))?
                .ok_or_else(|| {
                    key_error(
                        "sky130",
                        "no timed sky130_fd_sc_hd PDK found ($TOFPROBE_SKY130_PDK, ../shared/pdk/sky130_fd_sc_hd)",
                    )
                })?;
            pdk.typical(cache).map_err(|e| key_error("sky130", e))?
        }
        path => PathBuf::from(path),
    };
    let shown = name.unwrap_or("osu018");
    let lib = Liberty::load(&path).map_err(|e| key_error(shown, e))?;
    if !lib.has_timing {
        return Err(key_error(
            shown,
            format!(
                "{} has no timing groups: f_max cannot be measured on it",
                path.display()
            ),
        ));
    }
    Ok(lib)
}

/// Chooses A (and C) for `px`, whose `adders` is `"auto"`. Errors are `[pixel]` errors of
/// `origin` naming `adders` or `timing_liberty`.
pub fn choose(
    px: &PixelConfig,
    ctx: &PixelContext,
    origin: &str,
) -> Result<AdderChoice, DesignError> {
    let err = |e| DesignError::pixel(origin, e);
    let cache = synth_cache_dir(None);
    let lib = liberty(px.timing_liberty.as_deref(), &cache).map_err(err)?;
    // P from the pixel with one adder and as many cycles as its operations need at most.
    let with = |a: usize, c: usize| -> Result<PixelParams, DesignError> {
        let mut p = px.clone();
        p.adders = Choice::Value(a);
        p.cycles_per_pulse = c;
        p.resolve(ctx).map_err(err)
    };
    let ops = with(1, tofprobe_pixel::params::MAX_CYCLES_PER_PULSE)?.ops_per_pulse();
    let mut trials = Vec::new();
    let mut last_k = 0;
    for a in 1..=ops {
        let k = ops.div_ceil(a);
        if k == last_k {
            continue;
        }
        last_k = k;
        let params = with(a, k)?;
        let clock_mhz = k as f64 * ctx.laser_rate_hz / 1e6;
        let provider = GeneratedPixel {
            base: params.clone(),
        };
        let point = analyse_point(
            &provider,
            params.bins as u64,
            params.width,
            &lib,
            true,
            "clk",
            &cache,
            Some(1e6 / clock_mhz),
        )
        .map_err(|e| {
            err(PixelError::invalid(
                "adders",
                "\"auto\"",
                format!("timing the A = {a} pixel failed: {e}"),
                "an explicit number of adders",
            ))
        })?;
        let timing = point.timing.expect("a liberty with timing is timed");
        // The size report's verdict, so `size` and `adders = "auto"` judge slack alike.
        let verdict = CornerTiming::new(
            &lib.name,
            "typical",
            &lib.path,
            &timing,
            clock_mhz,
            ctx.laser_rate_hz,
        );
        let trial = AdderTrial {
            adders: a,
            cycles_per_pulse: k,
            clock_mhz,
            f_max_mhz: timing.f_max_mhz,
            slack_percent: verdict.slack_percent,
            meets: verdict.meets_margin,
        };
        let meets = trial.meets;
        trials.push(trial);
        if meets {
            return Ok(AdderChoice {
                adders: a,
                cycles_per_pulse: k,
                liberty: lib.path.clone(),
                margin_percent: MARGIN_PERCENT,
                trials,
            });
        }
    }
    let best = trials
        .iter()
        .max_by(|x, y| x.slack_percent.total_cmp(&y.slack_percent))
        .expect("P ≥ 1 gives a candidate");
    Err(err(PixelError::invalid(
        "adders",
        "\"auto\"",
        format!(
            "no number of adders meets the laser rate on {} with {MARGIN_PERCENT:.0} % slack: closest A = {} at {:.1} MHz (C = {}), f_max {:.1} MHz, {:.1} % slack",
            lib.path.display(),
            best.adders,
            best.clock_mhz,
            best.cycles_per_pulse,
            best.f_max_mhz,
            best.slack_percent
        ),
        "a slower laser (sensor.laser_rate_hz), a faster liberty, or an explicit A",
    )))
}
