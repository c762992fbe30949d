//! The fuzzers' key list (`tofprobe_design::document::keys`) against an independent
//! enumeration: a document with every key set, serialised to TOML and walked table by
//! table. Every key found there is derived from the schema with values of its type, and
//! the `[array]` and `[pixel]` sections are derived exactly; a test-only document type with
//! a key of its own shows the key derived with its type, no list edited.

use std::collections::BTreeSet;

use serde::Deserialize;
use tofprobe_design::document::keys::{Key, keys, keys_of};
use tofprobe_design::{ArrayConfig, DEFAULT_ORIGIN, DEFAULT_TOML, Document, RateMap};
use tofprobe_pixel::RegisterFile;
use toml::Value;

/// The default document with every optional key set: `[array]` by a struct literal (a
/// field added to `ArrayConfig` does not compile here until it is set), `[pixel]`'s
/// optional keys given values.
fn full_document() -> Document {
    let mut doc = Document::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN).unwrap();
    doc.array = Some(ArrayConfig {
        rows: 2,
        cols: 2,
        pitch_um: 30.0,
        mm_per_pixel: Some(1.0),
        field_of_view_deg: Some(30.0),
        distance_mm: Some(1000.0),
        signal_map: Some(RateMap::Constant { value: 1.0 }),
        background_map: Some(RateMap::Constant { value: 0.0 }),
        readout_bits: Some(8),
        readout_bits_per_s: Some(1e9),
        frame_rate_hz: Some(100.0),
        double_buffer: true,
        superpixel: 2,
        level: tofprobe_design::array::ArrayLevel::Auto,
        auto_threshold: Some(0.25),
    });
    let mut t = toml::Value::try_from(&doc).unwrap();
    let pixel = t.get_mut("pixel").unwrap().as_table_mut().unwrap();
    for (k, v) in [
        ("haar_scales", Value::Integer(1)),
        ("timing_liberty", Value::String("osu018".into())),
        ("tdc_bits", Value::Integer(8)),
        ("register_frac_bits", Value::Integer(2)),
        ("width", Value::String("auto".into())),
        ("frame_pulses", Value::Integer(64)),
        ("rom_depth", Value::Integer(16)),
    ] {
        pixel.insert(k.into(), v);
    }
    t.try_into().unwrap()
}

/// `section.key` (`scene.motion.KIND.key` for a motion's) of every key of `doc`, walked in
/// its TOML form.
fn walked(doc: &Document) -> BTreeSet<String> {
    let t = toml::Value::try_from(doc).unwrap();
    let mut out = BTreeSet::new();
    for (section, body) in t.as_table().unwrap() {
        for (key, value) in body.as_table().into_iter().flatten() {
            if section == "scene" && key == "motion" {
                for m in value.as_array().unwrap() {
                    let m = m.as_table().unwrap();
                    let kind = m["kind"].as_str().unwrap();
                    out.extend(m.keys().map(|k| format!("scene.motion.{kind}.{k}")));
                }
            } else {
                out.insert(format!("{section}.{key}"));
            }
        }
    }
    out
}

fn path(k: &Key) -> String {
    match &k.kind {
        Some(kind) => format!("{}.{kind}.{}", k.section, k.key),
        None => format!("{}.{}", k.section, k.key),
    }
}

#[test]
fn every_key_of_a_full_document_is_derived_with_values_of_its_type() {
    let derived = keys();
    let names: BTreeSet<String> = derived.iter().map(path).collect();
    let doc = full_document();
    let seen = walked(&doc);
    let missing: Vec<_> = seen.difference(&names).collect();
    assert!(missing.is_empty(), "not derived: {missing:?}");
    for section in ["array", "pixel"] {
        let of = |s: &BTreeSet<String>| -> BTreeSet<String> {
            s.iter()
                .filter(|p| p.starts_with(&format!("{section}.")))
                .cloned()
                .collect()
        };
        assert_eq!(of(&names), of(&seen), "[{section}]");
    }
    assert_eq!(names.iter().filter(|p| p.starts_with("array.")).count(), 15);
    // Each key's values fit it alone, and a key has values of its type.
    for k in &derived {
        assert!(!k.values.is_empty(), "{}: no value of its type", path(k));
    }
    let values = |p: &str| &derived.iter().find(|k| path(k) == p).unwrap().values;
    let s = |x: &str| Value::String(x.into());
    assert!(values("pixel.register_file").contains(&s("latch")));
    assert!(values("pixel.adders").contains(&s("auto")));
    assert!(
        values("pixel.mode").contains(&s("haar")) || values("pixel.mode").contains(&s("fourier"))
    );
    assert!(values("array.double_buffer").contains(&Value::Boolean(true)));
    assert!(values("array.level").contains(&s("statistical")));
    assert!(values("array.pitch_um").contains(&Value::Float(1.5)));
    assert!(!values("array.rows").contains(&Value::Float(1.5)));
    assert!(
        values("array.signal_map")
            .iter()
            .any(|v| v.get("kind") == Some(&s("gradient")))
    );
    assert!(values("scene.motion.sine.amplitude_mm").contains(&Value::Float(0.5)));
    assert!(names.contains("scene.motion.edge.velocity_mm_per_s"));
}

/// A document type of this test's own with a new `[array]` key: it is derived, with the
/// values of its type, from the serde types alone.
#[test]
fn a_new_key_is_derived_with_its_type() {
    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Doc {
        #[serde(default)]
        array: Option<Array>,
    }
    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Array {
        rows: u32,
        test_only_knob: Option<f64>,
        test_only_kind: Option<RegisterFile>,
    }
    let k = keys_of::<Doc>();
    let names: Vec<String> = k.iter().map(path).collect();
    assert_eq!(
        names,
        ["array.rows", "array.test_only_knob", "array.test_only_kind"]
    );
    assert!(k[1].values.contains(&Value::Float(1.5)));
    assert!(!k[0].values.contains(&Value::Float(1.5)));
    assert!(k[2].values.contains(&Value::String("clock_gated".into())));
    assert!(!k[2].values.contains(&Value::Integer(1)));
}

/// The fuzzers' keys: every key outside `scene.motion`, and the default's own motion kind
/// (a sine) with every one of its keys — no other kind's.
#[test]
fn the_fuzzers_draw_every_key_and_the_default_motion_kinds_only() {
    use tofprobe_design::document::keys::keys_of_the_default;
    let all = keys();
    let fuzzed = keys_of_the_default();
    let outside = |k: &&Key| k.kind.is_none();
    assert_eq!(
        fuzzed.iter().filter(outside).count(),
        all.iter().filter(outside).count()
    );
    let kinds: BTreeSet<_> = fuzzed.iter().filter_map(|k| k.kind.clone()).collect();
    assert_eq!(kinds, BTreeSet::from(["sine".to_string()]), "{kinds:?}");
    let sine = |k: &&Key| k.kind.as_deref() == Some("sine");
    assert_eq!(
        fuzzed.iter().filter(sine).count(),
        all.iter().filter(sine).count()
    );
    assert!(all.iter().any(|k| k.kind.as_deref() == Some("step")));
}
