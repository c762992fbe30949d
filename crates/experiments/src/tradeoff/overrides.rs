//! Knob settings as data: a configuration with some TOML keys replaced (`pixel.frac_bits =
//! 0`, `probe.rom_mode = "periodic"`, …), re-validated as a whole, so a sweep is a list of
//! (key, value) pairs and every setting goes through the same resolution as a user's file.

use tofprobe_design::{DesignError, Document, ProbeCache, ResolvedDesign, resolve_with};

use crate::error::ExperimentError;

/// `config` with each `(dotted.key, TOML value)` of `overrides` set (tables created as
/// needed), then resolved (probe designs reused from `cache`); `origin` names the result
/// in errors.
pub fn with_overrides(
    config: &Document,
    origin: &str,
    overrides: &[(&str, &str)],
    cache: &mut ProbeCache,
) -> Result<ResolvedDesign, ExperimentError> {
    let toml_err = |message: String| {
        ExperimentError::from(DesignError::Toml {
            origin: origin.to_string(),
            message,
        })
    };
    let mut doc = toml::Table::try_from(config).map_err(|e| toml_err(e.to_string()))?;
    for &(key, value) in overrides {
        // Parsing `v = <value>` gives the value its TOML type (integer, float, string).
        let parsed: toml::Table = toml::from_str(&format!("v = {value}"))
            .map_err(|e| toml_err(format!("override {key} = {value}: {e}")))?;
        let Some(v) = parsed.get("v").cloned() else {
            return Err(toml_err(format!("override {key} = {value}: no value")));
        };
        let mut parts: Vec<&str> = key.split('.').collect();
        let Some(leaf) = parts.pop() else {
            return Err(toml_err(format!("override key {key:?} is empty")));
        };
        let mut table = &mut doc;
        for part in parts {
            let entry = table
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            let Some(t) = entry.as_table_mut() else {
                return Err(toml_err(format!(
                    "override {key}: {part} is not a table in the configuration"
                )));
            };
            table = t;
        }
        table.insert(leaf.to_string(), v);
    }
    let cfg: Document = doc
        .try_into()
        .map_err(|e: toml::de::Error| toml_err(e.to_string().trim_end().to_string()))?;
    Ok(resolve_with(cfg, origin, cache)?)
}

/// `config` shortened to `pulses` (when it has more): the acquisition's N set directly and
/// any explicit `pixel.frame_pulses` cleared, so the ROM and the frame follow.
pub fn shortened(config: &Document, pulses: u64) -> Document {
    let mut c = config.clone();
    if c.pulses() > pulses {
        c.acquisition.pulses = Some(pulses);
        c.acquisition.duration_s = None;
        c.pixel.frame_pulses = None;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use tofprobe_design::{DEFAULT_ORIGIN, DEFAULT_TOML};

    fn default() -> Document {
        Document::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN).expect("default")
    }

    #[test]
    fn override_sets_typed_values_and_keeps_the_rest() {
        let base = default();
        let c = with_overrides(
            &base,
            "t",
            &[
                ("pixel.frac_bits", "4"),
                ("probe.rom_mode", "\"periodic\""),
                ("sensor.background_rate", "0.5"),
            ],
            &mut ProbeCache::default(),
        )
        .expect("valid")
        .document;
        assert_eq!(c.pixel.frac_bits, 4);
        assert_eq!(c.probe.rom_mode, tofprobe_dsp::sd::RomMode::Periodic);
        assert_eq!(c.sensor.background_rate, 0.5);
        assert_eq!(c.pixel.shift, base.pixel.shift);
        assert_eq!(c.scene, base.scene);
    }

    #[test]
    fn override_to_an_invalid_value_is_rejected_by_validation() {
        // C = 16 cycles cannot serve B = 32 bins on A = 2 adders (needs C ≥ 2B/A = 32).
        let e = with_overrides(
            &default(),
            "t",
            &[("pixel.bins", "32")],
            &mut ProbeCache::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("t"), "{e}");
        let e = with_overrides(
            &default(),
            "t",
            &[("pixel.no_such_knob", "1")],
            &mut ProbeCache::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("no_such_knob"), "{e}");
    }

    #[test]
    fn shortened_sets_pulses() {
        let c = shortened(&default(), 1000);
        assert_eq!(c.pulses(), 1000);
        assert_eq!(shortened(&c, 1 << 30).pulses(), 1000);
    }
}
