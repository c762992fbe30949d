//! The built `tofprobe` binary end to end: help, the embedded default, a small simulation
//! checked against closed forms, and every kind of bad input (clear `error:` message,
//! exit status 2, never a panic).

use crate::common;

use common::{default_text, edit, tofprobe};
use std::path::PathBuf;
use std::process::Command;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The default configuration with `from` replaced by `to` (must occur).
fn edited_default(from: &str, to: &str) -> String {
    edit(default_text(), &[(from, to)])
}

/// Runs `args` and asserts a clean failure whose message contains every part.
fn fails_with(args: &[&str], parts: &[&str]) {
    let out = tofprobe(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for p in parts {
        assert!(err.contains(p), "{args:?}: `{err}` lacks `{p}`");
    }
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write config");
    p.to_string_lossy().into_owned()
}

#[test]
fn help_on_every_command() {
    for args in [
        vec!["--help"],
        vec!["simulate", "--help"],
        vec!["config", "--help"],
        vec!["bench", "--help"],
        vec!["bench", "scene", "--help"],
    ] {
        let out = tofprobe(&args);
        assert!(out.status.success(), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Usage"),
            "{args:?}"
        );
    }
}

#[test]
fn default_is_the_papers_fig8_case() {
    let out = tofprobe(&["config"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // 1 s at 10 MHz, 400 ps / 5 ps = 80 codes (7 bits), σ_I = 50 ps = 7.5 mm.
    for part in ["10000000 pulses", "80 TDC codes", "7 bits", "jitter 7.5 mm"] {
        assert!(text.contains(part), "{text}");
    }
}

#[test]
fn every_example_scene_is_valid() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).expect("scenes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let out = tofprobe(&["config", path.to_str().expect("path")]);
            assert!(
                out.status.success(),
                "{path:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            n += 1;
        }
    }
    assert!(n >= 5, "only {n} example scenes");
}

#[test]
fn simulate_json_summary() {
    let dir = scratch("simulate");
    let text = edited_default("duration_s = 1.0", "pulses = 200000");
    let text = text.replacen("background_rate = 0.0", "background_rate = 0.3", 1);
    let path = write(&dir, "small.toml", &text);
    let out = tofprobe(&["simulate", &path, "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let n = v["pulses"].as_u64().expect("pulses");
    assert_eq!(n, 200_000);
    let det = v["detections"].as_u64().expect("detections") as f64;
    let bg = v["background_wins"].as_u64().expect("background_wins") as f64;
    // ρ_s = 1 (signal 4σ inside the window: P(out) = 6e-5, negligible here): every pulse
    // detects; background wins with probability 1 − e^(−ρ_b/2) = 0.1393 (mid-window).
    // Binomial SE with N = 2·10^5: 7.7e-4; tolerance 5 SE.
    assert!((det / n as f64 - 1.0).abs() < 1e-3, "detections {det}");
    let p = 1.0 - (-0.15f64).exp();
    assert!(
        (bg / n as f64 - p).abs() < 5.0 * (p * (1.0 - p) / n as f64).sqrt(),
        "bg {bg}"
    );
    let mean = v["mean_depth_mm"].as_f64().expect("mean");
    // First-photon mixture, to first order in λ = ρ_b/60 mm: background wins (p = 0.139)
    // need a background photon before the signal at s, so they sit uniformly on [0, s]
    // weighted by s: mean (μ² + σ²)/(2μ) = 15.9 mm; surviving signal photons are biased
    // early by λσ² = 0.28 mm. Mean ≈ 0.861·29.72 + 0.139·15.9 = 27.8 mm. SE of the mean
    // 0.03 mm; 0.25 mm also covers the second-order terms of the estimate.
    assert!((mean - 27.8).abs() < 0.25, "mean {mean}");
    let sigma = v["sigma_depth_mm"].as_f64().expect("sigma");
    assert!(sigma > 7.5 && sigma < 17.3, "sigma {sigma}");
    assert!(v["seconds"].as_f64().expect("seconds") >= 0.0);
    // 200,000 = 10 periods of the default's periodic ROM, whose wrap is clean (1.8e-2 of
    // the in-band quantisation error, limit 0.05).
    let bt = &v["bit_true"];
    assert_eq!(bt["rom_mode"].as_str(), Some("periodic"));
    assert_eq!(bt["rom_depth"].as_u64(), Some(20_000));
    assert_eq!(bt["rom_wrap_clean"].as_bool(), Some(true));
    let ratio = bt["rom_wrap_error_ratio"].as_f64().expect("ratio");
    assert!(ratio > 0.0 && ratio <= 0.05, "{ratio}");
}

#[test]
fn bench_scene_json_has_unit_named_keys() {
    let out = tofprobe(&["bench", "scene", "--pulses", "200000", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert!(v["signal_only_pulses_per_s"].as_f64().expect("rate") > 0.0);
    assert!(v["mixed_pulses_per_s"].as_f64().expect("rate") > 0.0);
    for k in [
        "signal_only_speedup_vs_reference",
        "mixed_speedup_vs_reference",
    ] {
        assert!(v[k].as_f64().expect("ratio") > 0.0, "{k}");
    }
    assert!(v["speedup_pass"].is_boolean());
    assert!(v["pass"].is_boolean());
    // One row per ISA this CPU runs, narrowest first, each naming its ISA and judging
    // its own targets; the top level is the widest row.
    let supported: Vec<&str> = tofprobe_io::isa::Isa::supported()
        .iter()
        .map(|i| i.name())
        .collect();
    let rows = v["isas"].as_array().expect("isas");
    let names: Vec<&str> = rows.iter().map(|r| r["isa"].as_str().unwrap()).collect();
    assert_eq!(names, supported);
    assert_eq!(v["isa"], *supported.last().unwrap());
    for r in rows {
        assert!(r["mixed_speedup_vs_reference"].as_f64().unwrap() > 0.0);
        assert!(r["speedup_pass"].is_boolean());
    }
    // `--isa` and TOFPROBE_ISA measure one; a name that is not an ISA is refused with the
    // allowed names, and so is an ISA this CPU lacks, naming what it lacks.
    let one = tofprobe(&[
        "bench", "scene", "--pulses", "70000", "--json", "--isa", "scalar",
    ]);
    assert!(one.status.success());
    let o: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
    assert_eq!(
        (o["isa"].as_str(), o["isas"].as_array().map(Vec::len)),
        (Some("scalar"), Some(1))
    );
    let allowed = "allowed: \"scalar\", \"avx2\", \"avx512\"";
    fails_with(
        &["bench", "scene", "--isa", "avx1024"],
        &["--isa = \"avx1024\"", allowed],
    );
    let env = std::process::Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["bench", "scene", "--pulses", "70000"])
        .env("TOFPROBE_ISA", "sse9")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&env.stderr);
    assert_eq!(env.status.code(), Some(2), "{err}");
    assert!(
        err.contains("TOFPROBE_ISA = \"sse9\"") && err.contains(allowed),
        "{err}"
    );
    if let Some(lacking) = tofprobe_io::isa::Isa::ALL.iter().find(|i| !i.available()) {
        fails_with(
            &["bench", "scene", "--isa", lacking.name()],
            &["this CPU lacks", lacking.features()],
        );
    }
    fails_with(
        &["bench", "scene", "--pulses", "10"],
        &["--pulses = 10", "pulses >= 65536"],
    );
}

#[test]
fn bad_files() {
    let dir = scratch("files");
    fails_with(
        &["simulate", "/no/such/file.toml"],
        &["/no/such/file.toml", "No such file"],
    );
    let d = dir.to_string_lossy().into_owned();
    fails_with(&["simulate", &d], &["is a directory"]);
    let p = dir.join("latin1.toml");
    std::fs::write(&p, b"[sensor]\n# caf\xe9\n").expect("write");
    fails_with(
        &["simulate", p.to_str().expect("path")],
        &["not valid UTF-8", "offset 14"],
    );
}

#[test]
fn bad_values() {
    let dir = scratch("values");
    let cases = [
        (
            "laser_rate_hz = 10e6",
            "laser_rate_hz = -10e6",
            &["sensor.laser_rate_hz", "-10000000", "0 < laser_rate_hz"][..],
        ),
        (
            "signal_rate = 1.0",
            "signal_rate = 1.2",
            &["sensor.signal_rate", "1.2", "0 <= signal_rate <= 1"][..],
        ),
        (
            "background_rate = 0.0",
            "background_rate = -0.5",
            &["sensor.background_rate", "-0.5", "0 <= background_rate"][..],
        ),
        (
            "depth_mm = 30.0",
            "depth_mm = 90.0",
            &[
                "outside the timing window",
                "window_start_ps + window_length_ps >=",
            ][..],
        ),
        (
            "duration_s = 1.0",
            "pulses = 0",
            &["acquisition.pulses", "= 0", "1 <= pulses"][..],
        ),
    ];
    for (i, (from, to, parts)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("bad{i}.toml"), &edited_default(from, to));
        fails_with(&["simulate", &path], parts);
    }
}

#[test]
fn toml_errors_keep_line_and_column() {
    let dir = scratch("toml");
    // Unknown key (a typo) in [sensor]: rejected, with its line.
    let typo = edited_default("jitter_ps = 50.0", "jitter_sp = 50.0");
    let line = typo
        .lines()
        .position(|l| l.starts_with("jitter_sp"))
        .expect("line")
        + 1;
    let path = write(&dir, "typo.toml", &typo);
    fails_with(
        &["simulate", &path],
        &["jitter_sp", &format!("line {line}")],
    );
    // Syntax error.
    let path = write(&dir, "syntax.toml", "[sensor\nlaser_rate_hz = 1\n");
    fails_with(&["simulate", &path], &["line 1, column"]);
    // Unknown motion kind.
    let path = write(
        &dir,
        "kind.toml",
        &edited_default("kind = \"sine\"", "kind = \"saw\""),
    );
    fails_with(&["simulate", &path], &["saw", "line"]);
}

/// `tofprobe … | head`: a reader that has gone away is not an error. The reader here
/// (`true`) exits before tofprobe starts writing, so the write meets a closed pipe; the
/// command must exit with the shell's SIGPIPE status (141) and no panic report.
#[test]
fn a_closed_stdout_pipe_exits_quietly() {
    let script = format!(
        "{{ sleep 0.3; '{}' config --print-default; echo \"status=$?\" >&2; }} | true",
        env!("CARGO_BIN_EXE_tofprobe")
    );
    let out = Command::new("sh")
        .args(["-c", &script])
        .output()
        .expect("sh runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("status=141"), "{err}");
}
