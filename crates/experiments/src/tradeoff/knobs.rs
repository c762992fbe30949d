//! The knobs within the bit-true level (issue 8, point 1): a list of settings — W, F, the
//! registers' fraction bits G, the prefilter's rounding, S, the ROM's depth L and mode, the
//! ΣΔ order and OSR, the number of bins — each applied to the scene as TOML overrides
//! ([`super::overrides`]), then measured like the levels table: the bit-true model's wall
//! time per simulated second (median of several runs) and its amplitude and noise floor against the float full DFT on the same bins, the scene's true
//! amplitude and the closed-form noise floor. A setting the configuration checks refuse
//! (e.g. W below the sizing) is a row with the refusal, not a failed command.

use serde::Serialize;
use tofprobe_io::markdown::Table;
use tofprobe_pixel::spectrum::bit_true_spectrum;

use tofprobe_design::{DesignError, Document, ProbeCache, ResolvedDesign};

use super::overrides::{shortened, with_overrides};
use super::timing::median_seconds;
use super::{LevelResult, measure_levels};
use crate::error::ExperimentError;
use crate::level::Level;
use crate::spectrum::setup;

/// One knob setting: the knob's name, the value shown, and the TOML keys it sets. A value
/// `{w_min}`, `{w_min+k}` or `{w_min-k}` is the width `width = "auto"` sizes for the
/// scene's frame, plus or minus k bits (the minimum depends on N, so a literal W would
/// not sit at the edge for every scene).
#[derive(Debug, Clone, Copy)]
pub struct KnobSetting {
    /// Knob name as in the paper (W, F, S, …).
    pub knob: &'static str,
    /// The value as shown in the table.
    pub value: &'static str,
    /// `(dotted.key, TOML value)` pairs applied to the scene.
    pub overrides: &'static [(&'static str, &'static str)],
}

const fn k(
    knob: &'static str,
    value: &'static str,
    overrides: &'static [(&'static str, &'static str)],
) -> KnobSetting {
    KnobSetting {
        knob,
        value,
        overrides,
    }
}

/// The settings of `sweep` whose knob is in `only` (all of them when `only` is empty); the
/// baseline is always kept, as every other row is read against it.
pub fn select(sweep: &[KnobSetting], only: &[String]) -> Vec<KnobSetting> {
    sweep
        .iter()
        .filter(|s| s.knob == "baseline" || only.is_empty() || only.iter().any(|o| o == s.knob))
        .copied()
        .collect()
}

/// The default sweep: one knob changed at a time from the scene as configured.
pub const DEFAULT_SWEEP: &[KnobSetting] = &[
    k("baseline", "as configured", &[]),
    k("W", "auto (the sizing)", &[("pixel.width", "\"auto\"")]),
    k("W", "sizing + 12", &[("pixel.width", "{w_min+12}")]),
    k("W", "sizing − 1", &[("pixel.width", "{w_min-1}")]),
    k("F", "0", &[("pixel.frac_bits", "0")]),
    k("F", "4", &[("pixel.frac_bits", "4")]),
    k("F", "12", &[("pixel.frac_bits", "12")]),
    // The registers' fraction bits G ≤ F (issue 16): each bit dropped narrows every
    // register by one; what it costs in amplitude is this row against the baseline.
    k("G", "0", &[("pixel.register_frac_bits", "0")]),
    k("G", "2", &[("pixel.register_frac_bits", "2")]),
    k("G", "4", &[("pixel.register_frac_bits", "4")]),
    k(
        "prefilter rounding",
        "nearest",
        &[("pixel.prefilter_rounding", "\"nearest\"")],
    ),
    k("S", "3", &[("pixel.shift", "3")]),
    k("S", "7", &[("pixel.shift", "7")]),
    k(
        "ROM mode, L",
        "periodic, 62500",
        &[
            ("probe.rom_mode", "\"periodic\""),
            ("probe.rom_depth", "62500"),
        ],
    ),
    k(
        "ROM mode, L",
        "periodic, 20000",
        &[
            ("probe.rom_mode", "\"periodic\""),
            ("probe.rom_depth", "20000"),
        ],
    ),
    k(
        "ROM mode, L",
        "windowed, N",
        &[("probe.rom_mode", "\"windowed\"")],
    ),
    k("ΣΔ order", "2", &[("probe.order", "2")]),
    k("ΣΔ order", "4", &[("probe.order", "4")]),
    k("OSR", "16", &[("probe.osr", "16.0")]),
    k("OSR", "64", &[("probe.osr", "64.0")]),
    k(
        "B",
        "4 (C = 4)",
        &[("pixel.bins", "4"), ("pixel.cycles_per_pulse", "4")],
    ),
    k("B", "auto", &[("pixel.bins", "\"auto\"")]),
    k(
        "B",
        "32 (C = 32)",
        &[("pixel.bins", "32"), ("pixel.cycles_per_pulse", "32")],
    ),
];

/// One knob setting's measurement (`rejected` set and the numbers `None` when refused).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct KnobRow {
    /// Knob name.
    pub knob: String,
    /// Value shown.
    pub value: String,
    /// The configuration checks' refusal, if any.
    pub rejected: Option<String>,
    /// Resolved accumulator width W, bits.
    pub width_bits: Option<u32>,
    /// Resolved number of bins B.
    pub bins: Option<usize>,
    /// Resolved ROM depth L, entries.
    pub rom_depth_entries: Option<usize>,
    /// Bit-true wall seconds per simulated second (median of `reps` runs).
    pub bit_true_seconds_per_sim_second: Option<f64>,
    /// Bit-true tone amplitude, µm.
    pub amplitude_um: Option<f64>,
    /// Bit-true noise floor (mean amplitude over the noise bins), µm.
    pub noise_um: Option<f64>,
    /// Float full DFT tone amplitude on the same bins, µm.
    pub float_dft_amplitude_um: Option<f64>,
    /// Float full DFT noise floor on the same bins, µm.
    pub float_dft_noise_um: Option<f64>,
    /// |bit-true − float DFT| amplitude, µm.
    pub amplitude_err_vs_dft_um: Option<f64>,
    /// |bit-true − true| amplitude, µm.
    pub amplitude_err_vs_true_um: Option<f64>,
    /// Bit-true noise floor / float DFT noise floor − 1.
    pub noise_rel_err_vs_dft: Option<f64>,
    /// Bit-true noise floor / closed-form noise floor − 1.
    pub noise_rel_err_vs_closed_form: Option<f64>,
}

/// A knob sweep of one scene.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct KnobSweep {
    /// Where the scene came from.
    pub origin: String,
    /// Pulses per frame of the sweep.
    pub pulses: u64,
    /// True when the sweep's frame is shorter than the scene's.
    pub shortened: bool,
    /// Timing repetitions per setting (the median is reported).
    pub reps: usize,
    /// True amplitude of the scene's strongest in-band tone, µm.
    pub true_amplitude_um: Option<f64>,
    /// One row per setting, in sweep order.
    pub rows: Vec<KnobRow>,
}

/// Runs `settings` on `design` shortened to at most `pulses`, timing the bit-true model
/// `reps` times per setting.
pub fn sweep(
    design: &ResolvedDesign,
    settings: &[KnobSetting],
    pulses: u64,
    reps: usize,
) -> KnobSweep {
    let (config, origin) = (&design.document, design.origin.as_str());
    let base = shortened(config, pulses);
    let mut cache = ProbeCache::default();
    let w_min = with_overrides(&base, origin, &[("pixel.width", "\"auto\"")], &mut cache)
        .map(|d| d.pixel.width)
        .map_err(|e| e.to_string());
    let mut true_amp = None;
    let rows = settings
        .iter()
        .map(|s| {
            let mut row = KnobRow {
                knob: s.knob.to_string(),
                value: s.value.to_string(),
                rejected: None,
                width_bits: None,
                bins: None,
                rom_depth_entries: None,
                bit_true_seconds_per_sim_second: None,
                amplitude_um: None,
                noise_um: None,
                float_dft_amplitude_um: None,
                float_dft_noise_um: None,
                amplitude_err_vs_dft_um: None,
                amplitude_err_vs_true_um: None,
                noise_rel_err_vs_dft: None,
                noise_rel_err_vs_closed_form: None,
            };
            let res = resolve(s.overrides, &w_min).and_then(|ov| {
                let ov: Vec<(&str, &str)> = ov.iter().map(|(k, v)| (*k, v.as_str())).collect();
                measure_row(&base, origin, s, &ov, reps, &mut cache, &mut row)
            });
            match res {
                Ok(t) => {
                    if true_amp.is_none() {
                        true_amp = t;
                    }
                }
                Err(e) => row.rejected = Some(e.to_string()),
            }
            row
        })
        .collect();
    KnobSweep {
        origin: origin.to_string(),
        pulses: base.pulses(),
        shortened: base.pulses() < config.pulses(),
        reps: reps.max(1),
        true_amplitude_um: true_amp,
        rows,
    }
}

/// The overrides with `{w_min±k}` replaced by the sized width ± k.
fn resolve(
    overrides: &[(&'static str, &'static str)],
    w_min: &Result<u32, String>,
) -> Result<Vec<(&'static str, String)>, ExperimentError> {
    overrides
        .iter()
        .map(|&(key, value)| {
            let Some(inner) = value
                .strip_prefix("{w_min")
                .and_then(|r| r.strip_suffix('}'))
            else {
                return Ok((key, value.to_string()));
            };
            let w = match w_min {
                Ok(w) => i64::from(*w),
                Err(e) => {
                    return Err(DesignError::Toml {
                        origin: format!("{key} = {value}"),
                        message: format!("cannot size W: {e}"),
                    }
                    .into());
                }
            };
            let delta: i64 = if inner.is_empty() {
                0
            } else {
                inner.parse().map_err(|_| DesignError::Toml {
                    origin: format!("{key} = {value}"),
                    message: format!(
                        "knob value {value}: expected {{w_min}}, {{w_min+k}} or {{w_min-k}}"
                    ),
                })?
            };
            Ok((key, (w + delta).max(0).to_string()))
        })
        .collect()
}

fn measure_row(
    base: &Document,
    origin: &str,
    s: &KnobSetting,
    overrides: &[(&str, &str)],
    reps: usize,
    cache: &mut ProbeCache,
    row: &mut KnobRow,
) -> Result<Option<f64>, ExperimentError> {
    let label = format!("{origin} with {} = {}", s.knob, s.value);
    let design = with_overrides(base, &label, overrides, cache)?;
    let su = setup(&design)?;
    row.width_bits = Some(su.params.width);
    row.bins = Some(su.params.bins);
    row.rom_depth_entries = Some(su.params.rom_depth);
    let r = measure_levels(
        &design,
        &su,
        &[Level::ClosedForm, Level::FullDft, Level::BitTrue],
    )?;
    let level = |level: Level| -> Result<&LevelResult, ExperimentError> {
        r.level(level).ok_or_else(|| {
            DesignError::Toml {
                origin: label.clone(),
                message: format!("level {level} missing from the measurement"),
            }
            .into()
        })
    };
    let cf = level(Level::ClosedForm)?;
    let dft = level(Level::FullDft)?;
    let bt = level(Level::BitTrue)?;
    row.amplitude_um = bt.amplitude_um;
    row.noise_um = Some(bt.noise_um);
    row.float_dft_amplitude_um = dft.amplitude_um;
    row.float_dft_noise_um = Some(dft.noise_um);
    row.amplitude_err_vs_dft_um = bt.amplitude_err_vs_dft_um;
    row.amplitude_err_vs_true_um = bt.amplitude_err_vs_true_um;
    row.noise_rel_err_vs_dft = Some(bt.noise_rel_err_vs_dft);
    row.noise_rel_err_vs_closed_form = (cf.noise_um > 0.0).then(|| bt.noise_um / cf.noise_um - 1.0);
    let source = design.photon_source()?;
    let lsb = design.sensor().tdc_lsb_mm();
    let secs = median_seconds(reps, || {
        bit_true_spectrum(&su.params, &su.rom, &source, lsb)
            .map(|_| ())
            .map_err(|source| ExperimentError::from(DesignError::pixel(&label, source)))
    })?;
    let sim_seconds = r.pulses as f64 / design.sensor().laser_rate_hz;
    row.bit_true_seconds_per_sim_second = Some(secs / sim_seconds);
    Ok(r.true_amplitude_um)
}

/// The Markdown table of a sweep.
pub fn markdown(s: &KnobSweep) -> String {
    let mut out = format!(
        "### Knobs within the bit-true level: {} (N = {}{}, bit-true time = median of {} runs{})\n\n",
        s.origin,
        s.pulses,
        if s.shortened { ", shortened frame" } else { "" },
        s.reps,
        s.true_amplitude_um
            .map(|a| format!(", true amplitude {a:.2} µm"))
            .unwrap_or_default()
    );
    let f = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_else(|| "–".into());
    let pct = |x: Option<f64>| {
        x.map(|v| format!("{:+.1}%", v * 100.0))
            .unwrap_or_else(|| "–".into())
    };
    let u = |x: Option<usize>| x.map(|v| v.to_string()).unwrap_or_else(|| "–".into());
    let mut t = Table::left([
        "knob",
        "value",
        "W",
        "B",
        "L",
        "bit-true s per simulated s",
        "amplitude µm",
        "err vs DFT µm",
        "err vs true µm",
        "noise µm",
        "noise vs DFT",
        "noise vs closed form",
    ]);
    for r in &s.rows {
        if let Some(why) = &r.rejected {
            t.row_spanning([
                r.knob.to_string(),
                r.value.to_string(),
                format!("rejected: {}", why.replace('|', "/").replace('\n', " ")),
            ]);
            continue;
        }
        t.row([
            r.knob.to_string(),
            r.value.to_string(),
            r.width_bits
                .map(|w| w.to_string())
                .unwrap_or_else(|| "–".into()),
            u(r.bins),
            u(r.rom_depth_entries),
            r.bit_true_seconds_per_sim_second
                .map(|t| format!("{t:.3e}"))
                .unwrap_or_else(|| "–".into()),
            f(r.amplitude_um),
            f(r.amplitude_err_vs_dft_um),
            f(r.amplitude_err_vs_true_um),
            f(r.noise_um),
            pct(r.noise_rel_err_vs_dft),
            pct(r.noise_rel_err_vs_closed_form),
        ]);
    }
    out += &t.render();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_sweep_covers_every_knob_of_the_issue() {
        for knob in ["W", "F", "S", "ROM mode, L", "ΣΔ order", "OSR", "B"] {
            assert!(
                DEFAULT_SWEEP.iter().filter(|s| s.knob == knob).count() >= 2,
                "{knob}"
            );
        }
        assert_eq!(DEFAULT_SWEEP[0].knob, "baseline");
        assert!(DEFAULT_SWEEP[0].overrides.is_empty());
    }

    #[test]
    fn select_keeps_the_baseline_and_the_named_knobs() {
        let s = select(DEFAULT_SWEEP, &["F".to_string()]);
        assert_eq!(s[0].knob, "baseline");
        assert!(s[1..].iter().all(|k| k.knob == "F"));
        assert_eq!(
            s.len(),
            1 + DEFAULT_SWEEP.iter().filter(|k| k.knob == "F").count()
        );
        assert_eq!(select(DEFAULT_SWEEP, &[]).len(), DEFAULT_SWEEP.len());
    }

    #[test]
    fn width_placeholders_resolve_against_the_sizing() {
        let ov = resolve(
            &[("pixel.width", "{w_min-1}"), ("pixel.shift", "3")],
            &Ok(39),
        )
        .expect("resolves");
        assert_eq!(ov[0].1, "38");
        assert_eq!(ov[1].1, "3");
        assert_eq!(
            resolve(&[("pixel.width", "{w_min+12}")], &Ok(39)).expect("ok")[0].1,
            "51"
        );
        assert!(resolve(&[("pixel.width", "{w_min*2}")], &Ok(39)).is_err());
    }
}
