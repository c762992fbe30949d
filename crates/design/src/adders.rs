//! `adders = "auto"`: the fewest shared adders whose pixel meets the laser rate on a liberty,
//! decided from measured timing, as a step of its own after the (pure) resolution.
//!
//! [`crate::resolve()`] never runs a tool: with `adders = "auto"` it leaves the choice open
//! ([`AdderStatus::Open`]) and resolves the pixel with a provisional A (the bit-true
//! registers do not depend on A or C, only the schedule does). The commands that build
//! hardware resolve with a timing oracle ([`AdderTiming`], implemented with yosys and OpenSTA
//! in `tofprobe-flow`, cached by the RTL's hash), and [`choose`] decides here, in pure code.
//!
//! A pixel with A adders needs K = ⌈P/A⌉ slots per pulse for its P operations, so it runs
//! at the slowest clock K·f_laser with C = K cycles per pulse. More adders for the same K
//! only cost area, so the candidates are the A where K changes, fewest first; the first
//! whose slack keeps the oracle's margin (10 % of the period) wins. The search is bounded
//! before any synthesis: a candidate whose clock exceeds [`SKIP_FACTOR`] × the fastest
//! *usable* f_max measured on the liberty (f_max less the margin; the oracle's cache, then
//! this search's own trials) cannot meet it — the pixel's critical path is one adder and its
//! operand mux whatever A is, so f_max changes by a few per cent with A (303 vs 302 MHz for
//! A = 1, 2 on osu018; 46.8, 42.3 and 44.9 MHz for A = 2, 8, 11 of the default at sky130
//! ss), not by a quarter — and is skipped without synthesis; and at most
//! [`MAX_ADDER_TRIALS`] candidates are synthesised. (With a factor of 2 on the bare f_max,
//! the default at sky130 ss spent its four syntheses on A = 1, 4, 5, 6 before A = 11.)

use serde::{Deserialize, Serialize};
use tofprobe_pixel::config::Choice;
use tofprobe_pixel::{PixelConfig, PixelContext, PixelError, PixelParams};

use crate::error::DesignError;

/// Candidates synthesised at most by one choice.
pub const MAX_ADDER_TRIALS: usize = 4;

/// A candidate whose clock exceeds this multiple of the fastest usable f_max (f_max less
/// the margin) measured on the liberty is skipped unsynthesised (see the module
/// documentation): f_max may grow by up to 25 % with A before a skip could be wrong.
pub const SKIP_FACTOR: f64 = 1.25;

/// What the oracle measured of one candidate pixel at its clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CandidateTiming {
    /// Measured f_max (MHz).
    pub f_max_mhz: f64,
    /// Slack as a percentage of the clock period.
    pub slack_percent: f64,
    /// Whether the slack keeps the oracle's margin.
    pub meets: bool,
}

/// Measures a candidate pixel's timing on one liberty (synthesis + static timing in
/// `tofprobe-flow`; a closed-form model in tests).
pub trait AdderTiming {
    /// The liberty's file name, for notes and errors.
    fn liberty_name(&self) -> String;
    /// The slack margin required, as a percentage of the period.
    fn margin_percent(&self) -> f64;
    /// The fastest f_max measured on this liberty before (any pixel), if known: a bound
    /// that lets [`choose`] skip hopeless candidates without synthesis.
    fn fastest_known_f_max_mhz(&self) -> Option<f64>;
    /// Times `candidate` at `clock_mhz`; the error text says what failed.
    fn time(&self, candidate: &PixelParams, clock_mhz: f64) -> Result<CandidateTiming, String>;
}

/// One candidate: A adders at C = ⌈P/A⌉ cycles per pulse, timed or skipped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdderTrial {
    /// A.
    pub adders: usize,
    /// C = K = ⌈P/A⌉.
    pub cycles_per_pulse: usize,
    /// C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Measured f_max (MHz); `None` when skipped without synthesis.
    pub f_max_mhz: Option<f64>,
    /// Slack as a percentage of the clock period (`None` when skipped).
    pub slack_percent: Option<f64>,
    /// slack ≥ the margin.
    pub meets: bool,
}

/// What `adders = "auto"` chose, and the evidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdderChoice {
    /// The chosen A.
    pub adders: usize,
    /// Its C = ⌈P/A⌉.
    pub cycles_per_pulse: usize,
    /// The liberty timed on (file name).
    pub liberty: String,
    /// The slack margin required (% of the period).
    pub margin_percent: f64,
    /// Every candidate considered, fewest adders first; the last is the chosen one.
    pub trials: Vec<AdderTrial>,
}

/// How a design's A was set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AdderStatus {
    /// `pixel.adders` is a number.
    Explicit,
    /// `adders = "auto"`, not yet timed: the pixel carries a provisional A (the model's
    /// results do not depend on it); the hardware commands decide it.
    Open {
        /// The provisional A the pixel was resolved with.
        provisional: usize,
    },
    /// `adders = "auto"`, decided from measured timing.
    Chosen(AdderChoice),
}

impl AdderStatus {
    /// The choice, once made.
    pub fn choice(&self) -> Option<&AdderChoice> {
        match self {
            AdderStatus::Chosen(c) => Some(c),
            _ => None,
        }
    }
}

/// The note every command prints for an open choice.
pub fn open_note(provisional: usize) -> String {
    format!(
        "adders = \"auto\": open — the hardware commands (rtl, vectors, cosim, flow, size, \
         tradeoff, layout, or `config --time-adders`) choose A from measured timing; the \
         model's registers do not depend on A (provisional A = {provisional})"
    )
}

impl AdderChoice {
    /// The note every command prints.
    pub fn note(&self) -> String {
        let chosen = self.trials.last().expect("a choice has its trial");
        let mut s = format!(
            "adders = \"auto\": A = {}, C = {} ({:.1} MHz) on {}: f_max {:.1} MHz, {:.1} % slack (margin {:.0} %)",
            self.adders,
            self.cycles_per_pulse,
            chosen.clock_mhz,
            self.liberty,
            chosen.f_max_mhz.unwrap_or(f64::NAN),
            chosen.slack_percent.unwrap_or(f64::NAN),
            self.margin_percent
        );
        for t in &self.trials[..self.trials.len() - 1] {
            match t.f_max_mhz {
                Some(f) => {
                    s += &format!(
                        "; A = {} would need {:.1} MHz (C = {}), f_max {f:.1} MHz",
                        t.adders, t.clock_mhz, t.cycles_per_pulse
                    )
                }
                None => {
                    s += &format!(
                        "; A = {} would need {:.1} MHz (C = {}), skipped: over {SKIP_FACTOR}× the fastest usable f_max measured",
                        t.adders, t.clock_mhz, t.cycles_per_pulse
                    )
                }
            }
        }
        s
    }
}

/// The pixel of `px` with A adders at C cycles per pulse.
fn with(
    px: &PixelConfig,
    ctx: &PixelContext,
    a: usize,
    c: usize,
) -> Result<PixelParams, PixelError> {
    let mut p = px.clone();
    p.adders = Choice::Value(a);
    p.cycles_per_pulse = c;
    p.resolve(ctx)
}

/// The provisional A of an open choice: the default's 2 adders (one per lane) when that
/// schedule fits, else the fewest that fit in the longest schedule.
pub fn provisional(px: &PixelConfig, ctx: &PixelContext) -> Result<(usize, usize), PixelError> {
    let ops = with(px, ctx, 1, tofprobe_pixel::params::MAX_CYCLES_PER_PULSE)?.ops_per_pulse();
    let max_c = tofprobe_pixel::params::MAX_CYCLES_PER_PULSE;
    let a = if ops.div_ceil(2) <= max_c {
        2.min(ops.max(1))
    } else {
        ops.div_ceil(max_c)
    };
    Ok((a, ops.div_ceil(a).max(1)))
}

/// Chooses A (and C) for `px`, whose `adders` is `"auto"`, with `timing` measuring the
/// candidates. Errors are `[pixel]` errors of `origin` naming `adders`.
pub fn choose(
    px: &PixelConfig,
    ctx: &PixelContext,
    origin: &str,
    timing: &dyn AdderTiming,
) -> Result<AdderChoice, DesignError> {
    let err = |e| DesignError::pixel(origin, e);
    // P from the pixel with one adder and as many cycles as its operations need at most.
    let ops = with(px, ctx, 1, tofprobe_pixel::params::MAX_CYCLES_PER_PULSE)
        .map_err(err)?
        .ops_per_pulse();
    let liberty = timing.liberty_name();
    let margin = timing.margin_percent();
    let mut bound = timing.fastest_known_f_max_mhz();
    let usable = |f_max: f64| f_max * (1.0 - margin / 100.0);
    let mut trials: Vec<AdderTrial> = Vec::new();
    let mut timed = 0;
    let mut capped = false;
    let mut last_k = 0;
    for a in 1..=ops {
        let k = ops.div_ceil(a);
        if k == last_k {
            continue;
        }
        last_k = k;
        let clock_mhz = k as f64 * ctx.laser_rate_hz / 1e6;
        if bound.is_some_and(|b| clock_mhz > SKIP_FACTOR * usable(b)) {
            trials.push(AdderTrial {
                adders: a,
                cycles_per_pulse: k,
                clock_mhz,
                f_max_mhz: None,
                slack_percent: None,
                meets: false,
            });
            continue;
        }
        if timed == MAX_ADDER_TRIALS {
            capped = true;
            break;
        }
        let params = with(px, ctx, a, k).map_err(err)?;
        let t = timing.time(&params, clock_mhz).map_err(|e| {
            err(PixelError::invalid(
                "adders",
                "\"auto\"",
                format!("timing the A = {a} pixel failed: {e}"),
                "an explicit number of adders",
            ))
        })?;
        timed += 1;
        bound = Some(bound.map_or(t.f_max_mhz, |b| b.max(t.f_max_mhz)));
        trials.push(AdderTrial {
            adders: a,
            cycles_per_pulse: k,
            clock_mhz,
            f_max_mhz: Some(t.f_max_mhz),
            slack_percent: Some(t.slack_percent),
            meets: t.meets,
        });
        if t.meets {
            return Ok(AdderChoice {
                adders: a,
                cycles_per_pulse: k,
                liberty,
                margin_percent: margin,
                trials,
            });
        }
    }
    let skipped = trials.iter().filter(|t| t.f_max_mhz.is_none()).count();
    let best = trials
        .iter()
        .filter(|t| t.slack_percent.is_some())
        .max_by(|x, y| {
            x.slack_percent
                .unwrap_or(f64::MIN)
                .total_cmp(&y.slack_percent.unwrap_or(f64::MIN))
        });
    let closest = match best {
        Some(b) => format!(
            "closest A = {} at {:.1} MHz (C = {}), f_max {:.1} MHz, {:.1} % slack",
            b.adders,
            b.clock_mhz,
            b.cycles_per_pulse,
            b.f_max_mhz.unwrap_or(f64::NAN),
            b.slack_percent.unwrap_or(f64::NAN)
        ),
        None => "no candidate was timed".to_string(),
    };
    let how = match (capped, skipped) {
        (true, _) => format!(
            "; the search stopped after {MAX_ADDER_TRIALS} syntheses (A > {} not tried)",
            trials.last().map_or(0, |t| t.adders)
        ),
        (false, 0) => String::new(),
        (false, n) => format!(
            "; {n} candidate(s) skipped unsynthesised: even C = 1 needs {:.1} MHz, over {SKIP_FACTOR}× the fastest usable f_max measured ({:.1} MHz less {margin:.0} %)",
            ctx.laser_rate_hz / 1e6,
            bound.unwrap_or(f64::NAN)
        ),
    };
    Err(err(PixelError::invalid(
        "adders",
        "\"auto\"",
        format!(
            "no number of adders meets the laser rate on {liberty} with {margin:.0} % slack: {closest}{how}"
        ),
        "a slower laser (sensor.laser_rate_hz), a faster liberty, or an explicit A",
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// A liberty on which every pixel's f_max is `f_max` MHz, counting syntheses.
    struct Flat {
        f_max: f64,
        known: Option<f64>,
        calls: Cell<usize>,
    }

    impl AdderTiming for Flat {
        fn liberty_name(&self) -> String {
            "flat.lib".into()
        }
        fn margin_percent(&self) -> f64 {
            10.0
        }
        fn fastest_known_f_max_mhz(&self) -> Option<f64> {
            self.known
        }
        fn time(&self, _: &PixelParams, clock_mhz: f64) -> Result<CandidateTiming, String> {
            self.calls.set(self.calls.get() + 1);
            let slack_percent = (1.0 - clock_mhz / self.f_max) * 100.0;
            Ok(CandidateTiming {
                f_max_mhz: self.f_max,
                slack_percent,
                meets: slack_percent >= 10.0,
            })
        }
    }

    fn default_pixel() -> (PixelConfig, PixelContext) {
        let d = crate::Document::from_toml_str(crate::DEFAULT_TOML, "t").unwrap();
        (d.pixel.clone(), d.pixel_context())
    }

    /// The default (P = 32 at 10 MHz) on a 300 MHz liberty: A = 1 needs 320 MHz and fails,
    /// A = 2 needs 160 MHz and meets: two syntheses, as the closed form says.
    #[test]
    fn fewest_adders_whose_clock_keeps_the_margin() {
        let (px, ctx) = default_pixel();
        let t = Flat {
            f_max: 300.0,
            known: None,
            calls: Cell::new(0),
        };
        let c = choose(&px, &ctx, "t", &t).unwrap();
        assert_eq!((c.adders, c.cycles_per_pulse), (2, 16));
        assert_eq!(t.calls.get(), 2);
        assert!(
            c.note().contains("A = 1 would need 320.0 MHz"),
            "{}",
            c.note()
        );
    }

    /// A laser no adder count can serve is refused after one synthesis (every other
    /// candidate needs more than twice the f_max it measured), and with a known bound from
    /// the cache before any synthesis.
    #[test]
    fn hopeless_lasers_are_refused_without_walking_every_candidate() {
        let (px, mut ctx) = default_pixel();
        ctx.laser_rate_hz = 2e9;
        let t = Flat {
            f_max: 300.0,
            known: None,
            calls: Cell::new(0),
        };
        let e = choose(&px, &ctx, "t", &t).unwrap_err().to_string();
        assert_eq!(t.calls.get(), 1, "{e}");
        assert!(
            e.contains("adders") && e.contains("skipped unsynthesised"),
            "{e}"
        );
        let cached = Flat {
            f_max: 300.0,
            known: Some(300.0),
            calls: Cell::new(0),
        };
        assert!(choose(&px, &ctx, "t", &cached).is_err());
        assert_eq!(cached.calls.get(), 0);
    }

    /// A liberty slower than the bound predicts stops after MAX_ADDER_TRIALS syntheses.
    #[test]
    fn the_search_is_capped() {
        let (px, ctx) = default_pixel();
        // Every candidate's f_max is 0.85 × its own clock (it misses the 10 % margin by
        // 5 %): the bound (the first, fastest f_max, 272 MHz) keeps C = 16, 11 and 8 in
        // reach, so the four syntheses are spent on C = 32, 16, 11, 8.
        let t = Table {
            f_max: &|clock| 0.85 * clock,
            calls: Cell::new(0),
        };
        let e = choose(&px, &ctx, "t", &t).unwrap_err().to_string();
        assert_eq!(t.calls.get(), MAX_ADDER_TRIALS, "{e}");
        assert!(
            e.contains("stopped after") && e.contains("A > 4 not tried"),
            "{e}"
        );
    }

    /// The default on sky130 ss as measured (f_max 46.0 MHz at A = 1, 43.0 at A = 7, 42.3
    /// at A = 8, 44.9 at A = 11): A = 1 is timed, C = 16 … 6 are skipped (over 1.25 ×
    /// 0.9 × 46.0 = 51.8 MHz), C = 5 and 4 miss, C = 3 (A = 11, 30 MHz) meets — the
    /// option `size` reports for that corner, found within the four syntheses. (With the
    /// old rule, 2 × the bare f_max, A = 4, 5, 6 (C = 8, 7, 6) took the syntheses after A = 1 and A = 11
    /// was never reached; a liberty that misses at A = 11 too is `the_search_is_capped`'s.)
    #[test]
    fn the_default_at_the_slow_corner_reaches_eleven_adders() {
        let (px, ctx) = default_pixel();
        let t = Table {
            f_max: &|clock| match clock as u64 {
                320 => 46.0,
                50 => 43.0,
                40 => 42.3,
                30 => 44.9,
                _ => 44.0,
            },
            calls: Cell::new(0),
        };
        let c = choose(&px, &ctx, "t", &t).unwrap();
        assert_eq!((c.adders, c.cycles_per_pulse), (11, 3), "{}", c.note());
        assert_eq!(t.calls.get(), 4, "{}", c.note());
    }

    /// An oracle whose f_max is a function of the candidate's clock (MHz).
    struct Table<'a> {
        f_max: &'a dyn Fn(f64) -> f64,
        calls: Cell<usize>,
    }

    impl AdderTiming for Table<'_> {
        fn liberty_name(&self) -> String {
            "table.lib".into()
        }
        fn margin_percent(&self) -> f64 {
            10.0
        }
        fn fastest_known_f_max_mhz(&self) -> Option<f64> {
            None
        }
        fn time(&self, _: &PixelParams, clock_mhz: f64) -> Result<CandidateTiming, String> {
            self.calls.set(self.calls.get() + 1);
            let f_max_mhz = (self.f_max)(clock_mhz);
            let slack_percent = (1.0 - clock_mhz / f_max_mhz) * 100.0;
            Ok(CandidateTiming {
                f_max_mhz,
                slack_percent,
                meets: slack_percent >= 10.0,
            })
        }
    }
}
