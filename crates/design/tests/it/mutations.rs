//! Mutated configurations through the one resolution (what `config`, `simulate` and `rtl`
//! all start from) and the RTL commands' parameters: no panic, every refusal names a field
//! of the document and echoes (a bounded form of) the value given, and what resolves also
//! gives RTL parameters. Deterministic: a fixed seed walks the same cases on every run.
//! `TOFPROBE_MUTATIONS=N` runs N cases instead of the CI's 600 (the audit in
//! docs/reliability.md used 5000).

use std::panic::{AssertUnwindSafe, catch_unwind};
use tofprobe_testkit::fuzz::{dotted_paths, value_forms};

use tofprobe_design::document::keys::{Key, keys_of_the_default};
use tofprobe_design::{DEFAULT_TOML, Document, ProbeCache, RtlOverrides, resolve_with, rtl_params};

use tofprobe_testkit::params::Rng;

/// A valid `[array]` for mutations of its keys (the default document has none).
const BASE_ARRAY: &str = "rows = 2\ncols = 2\npitch_um = 30.0\nmm_per_pixel = 1.0";

/// Values a mutation writes (TOML literals): zero, signs, extremes of f64 and u64,
/// subnormals, non-finite values, wrong types, a long string.
fn values() -> Vec<String> {
    let mut v: Vec<String> = [
        "0",
        "-1",
        "1",
        "2",
        "3",
        "7",
        "16",
        "64",
        "1000",
        "65536",
        "1e5",
        "10000000",
        "4294967296",
        "9223372036854775807",
        "0.0",
        "-0.0",
        "0.5",
        "0.999",
        "1.0",
        "1.5",
        "7.99",
        "1e-300",
        "5e-324",
        "1e300",
        "1.7976931348623157e308",
        "inf",
        "-inf",
        "nan",
        "1e-9",
        "60.0",
        "-60.0",
        "\"x\"",
        "\"auto\"",
        "true",
        "[]",
        "[1.0, 2.0]",
        "{}",
        "\"haar\"",
        "\"windowed\"",
        "\"periodic\"",
        "\"square\"",
        "\"step\"",
        "\"hann\"",
        "\"toolbox\"",
        "\"tofprobe\"",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    v.push(format!("\"{}\"", "y".repeat(100_000)));
    v
}

/// The default document with one to three keys set, half of them to `values()`, half to
/// values of the key's own type; returns the text and the mutations (table, key, literal).
fn mutate(rng: &mut Rng, keys: &[Key], vals: &[String]) -> (String, Vec<(String, String, String)>) {
    let mut doc: toml::Table = toml::from_str(DEFAULT_TOML).unwrap();
    let mut muts = Vec::new();
    for _ in 0..1 + rng.next_u64() % 3 {
        let k = rng.pick(keys);
        let (table, key) = (k.section.as_str(), k.key.clone());
        let (lit, value) = if rng.next_u64().is_multiple_of(2) && !k.values.is_empty() {
            let v = rng.pick(&k.values).clone();
            (v.to_string(), v)
        } else {
            let lit = rng.pick(vals).clone();
            let value = toml::from_str::<toml::Table>(&format!("v = {lit}"))
                .unwrap()
                .remove("v")
                .unwrap();
            (lit, value)
        };
        if table == "array" && !doc.contains_key("array") {
            let array: toml::Table = toml::from_str(BASE_ARRAY).unwrap();
            doc.insert("array".into(), toml::Value::Table(array));
        }
        let target = if table == "scene.motion" {
            let scene = doc.get_mut("scene").unwrap().as_table_mut().unwrap();
            let m = scene.get_mut("motion").unwrap().as_array_mut().unwrap();
            m[0].as_table_mut().unwrap()
        } else {
            doc.entry(table.to_string())
                .or_insert_with(|| toml::Value::Table(Default::default()))
                .as_table_mut()
                .unwrap()
        };
        if rng.next_u64().is_multiple_of(8) {
            if target.remove(&key).is_some() {
                muts.push((table.to_string(), key, "<removed>".to_string()));
            }
        } else {
            target.insert(key.clone(), value);
            muts.push((table.to_string(), key, lit));
        }
    }
    (toml::to_string(&doc).unwrap(), muts)
}

#[test]
fn mutated_configurations_resolve_or_name_their_field() {
    let cases: usize = std::env::var("TOFPROBE_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    let vals = values();
    let keys = keys_of_the_default();
    let mut rng = Rng(0x7f4a_7c15_2024);
    let mut cache = ProbeCache::default();
    let (mut ok, mut refused, mut panics) = (0, 0, 0);
    let mut failures: Vec<String> = Vec::new();
    for case in 0..cases {
        let (text, muts) = mutate(&mut rng, &keys, &vals);
        let run = catch_unwind(AssertUnwindSafe(|| {
            let doc = Document::from_toml_str(&text, "mutated.toml").map_err(Box::new)?;
            let d = resolve_with(doc, "mutated.toml", &mut cache).map_err(Box::new)?;
            rtl_params(&d, &RtlOverrides::default()).map_err(Box::new)?;
            Ok::<_, Box<tofprobe_design::DesignError>>(())
        }));
        let Ok(result) = run else {
            panics += 1;
            failures.push(format!("case {case}: PANIC on {muts:?}"));
            continue;
        };
        let Err(e) = result else {
            ok += 1;
            continue;
        };
        refused += 1;
        let msg = e.to_string();
        if msg.len() > 4000 {
            failures.push(format!(
                "case {case}: {} byte message for {muts:?}",
                msg.len()
            ));
        }
        // The message names one of the mutated keys (the document's own name for it)
        // together with its value, unless a mutation only removed a key.
        let named = muts.iter().any(|(_, key, lit)| {
            msg.contains(key.as_str())
                && (lit == "<removed>"
                    // `pulses` and `duration_s` together: both keys are named.
                    || msg.contains("exactly one of")
                    || value_forms(lit)
                        .iter()
                        .any(|f| msg.contains(&tofprobe_io::text::clip(f, 60)[..f.len().min(57)])))
        });
        // Or a cross-field refusal: it names another key of the document by its dotted path
        // (`probe.rom_depth = 20000 … a divisor of the frame N`).
        let doc: toml::Table = toml::from_str(&text).unwrap();
        let named = named || dotted_paths(&doc).iter().any(|p| msg.contains(p.as_str()));
        if !named {
            failures.push(format!(
                "case {case}: {muts:?}\n    -> {}",
                tofprobe_io::text::clip(&msg, 400)
            ));
        }
    }
    eprintln!(
        "mutations: {cases} cases, {ok} resolved, {refused} refused, {panics} panics, {} unattributed",
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {cases} cases fail:\n{}",
        failures.len(),
        failures
            .iter()
            .take(40)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}
