//! `tofprobe tradeoff` through the binary, one smoke case per way of calling it: on a short
//! frame every level is reported with finite numbers, the slow level marked as
//! extrapolated, and `--out` writes the table and the Pareto plot as one set; the study's
//! options reach the library (`--knobs --knob W --skips` on a tiny frame: the sweep holds
//! the baseline and W only, the skips four stages; `--imputation` its pulses and seeds; an
//! unknown `--knob` exits 2 naming the knobs). What the numbers mean is tested where the
//! study is, crates/experiments/tests/it/study.rs.

use crate::common;

use common::short_tone_frame;
use std::process::Command;

#[test]
fn tradeoff_reports_every_level() {
    let n: u64 = 1 << 16;
    // A 1 mm tone on bin 30 of the 2^16-pulse windowed frame, B = 4 (C = 4).
    let text = short_tone_frame(n);
    let dir = std::env::temp_dir().join(format!("tofprobe-tradeoff-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let cfg = dir.join("short.toml");
    std::fs::write(&cfg, text).expect("write");
    let res = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["tradeoff", cfg.to_str().unwrap(), "--json", "--out"])
        .arg(&dir)
        .output()
        .expect("run");
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
    // `--out` writes one set, whole (tofprobe_io::OutputSet): no stage or temporary left.
    let left = common::listing(&dir);
    assert!(
        left.contains(&"tradeoff.md".to_string())
            && left.contains(&"pareto.svg".to_string())
            && left.iter().all(|n| !n.starts_with('.')),
        "{left:?}"
    );
    let v: serde_json::Value = serde_json::from_slice(&res.stdout).expect("one JSON object");
    let levels = v["scenes"][0]["levels"].as_array().expect("levels");
    let get = |name: &str| {
        levels
            .iter()
            .find(|l| l["level"] == name)
            .unwrap_or_else(|| panic!("level {name}"))
    };
    let names = [
        "closed form",
        "float full DFT",
        "float selected-bin DFT",
        "float ΣΔ probing",
        "bit-true transaction",
        "cycle-accurate",
    ];
    for name in names {
        let l = get(name);
        let t = l["seconds_per_sim_second"].as_f64().expect("time");
        assert!(t.is_finite() && t > 0.0, "{name}: {t}");
        assert_eq!(l["extrapolated"].as_bool(), Some(name == "cycle-accurate"));
        assert!(l["noise_um"].as_f64().is_some_and(f64::is_finite), "{name}");
    }
    let md = std::fs::read_to_string(dir.join("tradeoff.md")).expect("table");
    assert!(md.contains("| cycle-accurate (extrapolated) |"), "{md}");
    let svg = std::fs::read_to_string(dir.join("pareto.svg")).expect("plot");
    assert!(svg.starts_with("<svg"));
}

/// The default scene shortened to `n` pulses with a 1 mm tone on bin 30, B = 4 (C = 4).
fn tiny_config(dir: &std::path::Path, n: u64) -> std::path::PathBuf {
    let text = short_tone_frame(n);
    std::fs::create_dir_all(dir).expect("dir");
    let cfg = dir.join("tiny.toml");
    std::fs::write(&cfg, text).expect("write");
    cfg
}

#[test]
fn the_study_options_reach_the_library() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cfg = tiny_config(dir.path(), 1 << 12);
    let cfg = cfg.to_str().expect("UTF-8");
    let res = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args([
            "tradeoff", cfg, "--json", "--knobs", "--knob", "W", "--skips",
        ])
        .args(["--sweep-pulses", "4096", "--reps", "1", "--imputation"])
        .args(["--imputation-pulses", "1048576", "--imputation-seeds", "2"])
        .output()
        .expect("run");
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&res.stdout).expect("one JSON object");
    let rows = v["knobs"][0]["rows"].as_array().expect("knob rows");
    assert_eq!(v["knobs"][0]["pulses"].as_u64(), Some(4096));
    assert!(
        rows.iter()
            .all(|r| r["knob"] == "baseline" || r["knob"] == "W")
            && rows.iter().any(|r| r["knob"] == "W"),
        "{rows:?}"
    );
    assert_eq!(v["skips"][0]["stages"].as_array().map(Vec::len), Some(4));
    assert_eq!(v["imputation"]["pulses"].as_u64(), Some(1 << 20));
    assert_eq!(v["imputation"]["seeds"].as_u64(), Some(2));

    let res = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["tradeoff", cfg, "--knobs", "--knob", "Q"])
        .output()
        .expect("run");
    assert_eq!(res.status.code(), Some(2));
    let err = String::from_utf8_lossy(&res.stderr);
    assert!(
        err.contains("--knob") && err.contains("Q") && err.contains("W, "),
        "{err}"
    );
}
