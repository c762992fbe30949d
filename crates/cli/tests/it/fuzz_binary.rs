//! Mutated configurations through the binary (docs/reliability.md): a sample of the
//! property test that crates/design/tests/mutations.rs runs through the library (600
//! cases), here 40 cases through `config`, `simulate` and `rtl` as a user runs them. Each
//! run exits 0 or 2 within a time limit, prints no panic, and a refusal names a key of the
//! document together with the value given (or, for a cross-field refusal, another key of
//! the document by its dotted path). Deterministic: a fixed seed walks the same cases.
//! `TOFPROBE_BINARY_MUTATIONS=N` runs N cases. Half the mutations draw values of the key's
//! own type, from the schema (`tofprobe_design::document::keys`): every key, `[array]`'s
//! included, with no list here to keep.

use crate::common;
use tofprobe_testkit::fuzz::{dotted_paths, value_forms};

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::{default_text, edit};

use tofprobe_design::document::keys::{Key, keys_of_the_default};
use tofprobe_testkit::params::Rng;

/// TOML literals a mutation writes: zero, signs, extremes, non-finite values, wrong types.
const VALUES: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "16",
    "64",
    "1e5",
    "4294967296",
    "9223372036854775807",
    "0.0",
    "-0.0",
    "0.5",
    "0.999",
    "1.5",
    "7.99",
    "1e-300",
    "5e-324",
    "1e300",
    "inf",
    "-inf",
    "nan",
    "60.0",
    "\"x\"",
    "\"auto\"",
    "true",
    "[]",
    "\"haar\"",
    "\"windowed\"",
    "\"periodic\"",
];

/// The short windowed frame (N = 4096, B = 4; fast through `simulate`) with one to three
/// keys set from [`VALUES`] or to values of the key's own type (strings, `"auto"`, names,
/// lists, `[array]`: a key whose type the error table forgets, or a string key blamed for
/// another key's fault, shows up, issue 31); the text and the mutations (key, literal). A
/// mutation of `[array]` starts from a valid 2 × 2 array.
fn mutate(rng: &mut Rng, keys: &[Key]) -> (String, Vec<(String, String)>) {
    let base = edit(
        default_text(),
        &[
            ("duration_s = 1.0 ", "pulses = 4096 #"),
            ("rom_mode = \"periodic\"", "rom_mode = \"windowed\""),
            ("bins = 16 ", "bins = 4 "),
            ("cycles_per_pulse = 16 ", "cycles_per_pulse = 4 "),
        ],
    );
    let mut doc: toml::Table = toml::from_str(&base).unwrap();
    let mut muts = Vec::new();
    for _ in 0..1 + rng.next_u64() % 3 {
        let k = rng.pick(keys);
        let (table, key) = (k.section.as_str(), k.key.clone());
        let lit = if rng.next_u64().is_multiple_of(2) || k.values.is_empty() {
            rng.pick(VALUES).to_string()
        } else {
            rng.pick(&k.values).to_string()
        };
        if table == "array" && !doc.contains_key("array") {
            let array: toml::Table =
                toml::from_str("rows = 2\ncols = 2\npitch_um = 30.0\nmm_per_pixel = 1.0").unwrap();
            doc.insert("array".into(), toml::Value::Table(array));
        }
        let value = toml::from_str::<toml::Table>(&format!("v = {lit}"))
            .unwrap()
            .remove("v")
            .unwrap();
        let target = if table == "scene.motion" {
            let scene = doc.get_mut("scene").unwrap().as_table_mut().unwrap();
            scene.get_mut("motion").unwrap().as_array_mut().unwrap()[0]
                .as_table_mut()
                .unwrap()
        } else {
            doc.entry(table.to_string())
                .or_insert_with(|| toml::Value::Table(Default::default()))
                .as_table_mut()
                .unwrap()
        };
        target.insert(key.clone(), value);
        muts.push((key, lit));
    }
    (toml::to_string(&doc).unwrap(), muts)
}

/// Runs the binary with a time limit; (exit code, stderr). A run past the limit is killed
/// and reported as a hang.
fn run(args: &[&str], cfg: &Path, limit: Duration) -> Result<(Option<i32>, String), String> {
    // No EDA tool on the PATH: `rtl` with `adders = "auto"` is refused at once (naming
    // pixel.adders and the missing tool) instead of synthesising for minutes per case.
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    cmd.args(args).arg(cfg).env("PATH", "");
    common::run_limited(cmd, limit).map(|(code, err, _)| (code, err))
}

#[test]
fn mutated_configurations_through_the_binary_exit_0_or_2_and_name_their_field() {
    let cases: usize = std::env::var("TOFPROBE_BINARY_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let tmp = tempfile::tempdir().unwrap();
    let mut rng = Rng(0x0b1a_2026_1119);
    let keys = keys_of_the_default();
    let (mut runs, mut accepted, mut refused) = (0, 0, 0);
    let mut failures = Vec::new();
    for case in 0..cases {
        let (text, muts) = mutate(&mut rng, &keys);
        let cfg = tmp.path().join(format!("m{case}.toml"));
        std::fs::write(&cfg, &text).unwrap();
        let doc: toml::Table = toml::from_str(&text).unwrap();
        let out = tmp.path().join(format!("rtl{case}"));
        let rtl = ["rtl", "--out", out.to_str().unwrap()];
        for args in [&["config"][..], &["simulate"][..], &rtl[..]] {
            runs += 1;
            let (code, err) = match run(args, &cfg, Duration::from_secs(60)) {
                Ok(r) => r,
                Err(hang) => {
                    failures.push(format!("case {case} {muts:?}: {hang}"));
                    continue;
                }
            };
            if err.contains("panicked") || !matches!(code, Some(0 | 2)) {
                failures.push(format!(
                    "case {case} {args:?} {muts:?}: exit {code:?}: {err}"
                ));
                continue;
            }
            if code == Some(0) {
                accepted += 1;
                continue;
            }
            refused += 1;
            let named = muts.iter().any(|(key, lit)| {
                err.contains(key.as_str())
                    && (err.contains("exactly one of")
                        || value_forms(lit).iter().any(|f| {
                            err.contains(&tofprobe_io::text::clip(f, 60)[..f.len().min(57)])
                        }))
            }) || dotted_paths(&doc).iter().any(|p| err.contains(p.as_str()));
            if !named {
                failures.push(format!(
                    "case {case} {args:?} {muts:?}: names no field: {err}"
                ));
            }
        }
    }
    eprintln!(
        "binary mutations: {cases} cases, {runs} runs: {accepted} exit 0, {refused} exit 2 naming their field, {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
