//! `tofprobe tradeoff` on an `[array]` configuration (issue 48): the plate-mode example
//! shrunk to 8 × 8 pixels and 2 ROM periods; exit 0, one JSON object whose `array_scenes`
//! lists the four array levels with finite times and accuracy keys naming their unit,
//! and the level named in `simulate --out`'s summary.

use crate::common::tofprobe;

fn config(dir: &std::path::Path, level: &str) -> std::path::PathBuf {
    let text = include_str!("../../../../scenes/plate-mode.toml")
        .replacen("rows = 32", "rows = 8", 1)
        .replacen("cols = 32", "cols = 8", 1)
        .replacen("mm_per_pixel = 10.0", "mm_per_pixel = 40.0", 1)
        .replacen("pulses = 1000000", "pulses = 40000", 1)
        + &format!("level = \"{level}\"\n");
    let cfg = dir.join(format!("plate8-{level}.toml"));
    std::fs::write(&cfg, text).expect("write");
    cfg
}

#[test]
fn tradeoff_lists_the_array_levels_with_time_and_accuracy() {
    let dir = tempfile::tempdir().expect("dir");
    let cfg = config(dir.path(), "bit-true");
    let res = tofprobe(&["tradeoff", "--json", cfg.to_str().unwrap()]);
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&res.stdout).expect("one JSON object");
    let scene = &v["array_scenes"][0];
    assert_eq!(scene["rows"], 8);
    let levels = scene["levels"].as_array().expect("levels");
    let names: Vec<&str> = levels
        .iter()
        .map(|l| l["level"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["bit-true", "statistical", "closed-form", "auto"]);
    // Auto runs the plate's moving pixels bit-true: all but those on a nodal line.
    let (bt, au) = (&levels[0]["bit_true_pixels"], &levels[3]["bit_true_pixels"]);
    assert_eq!(bt, 64);
    assert!(au.as_u64().is_some_and(|n| n > 32 && n <= 64), "{au}");
    assert_eq!(levels[1]["bit_true_pixels"], 0);
    for l in levels {
        for key in [
            "seconds",
            "pixel_pulses_per_s",
            "amplitude_rms_error_um",
            "amplitude_error_ratio",
            "phase_rms_error_deg",
            "noise_floor_ratio",
            "mac",
            "noise_ks_statistic",
            "noise_ks_p_value",
        ] {
            let x = l[key].as_f64().unwrap_or(f64::NAN);
            assert!(x.is_finite() && x >= 0.0, "{}: {key} = {x}", l["level"]);
        }
    }
    // The statistical level is as close to bit-true as bit-true's own spread (the ratio's
    // sd over 64 pixels is ≈ 0.1); the closed form has no noise floor.
    let st = &levels[1];
    assert!(st["amplitude_error_ratio"].as_f64().unwrap() < 1.5, "{st}");
    assert!(levels[2]["noise_floor_ratio"].as_f64().unwrap() < 0.3);
}

#[test]
fn simulate_names_the_level_in_the_summary_and_the_uff_header() {
    let dir = tempfile::tempdir().expect("dir");
    let out = dir.path().join("set");
    let cfg = config(dir.path(), "statistical");
    let res = tofprobe(&[
        "simulate",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["level"], "statistical");
    assert_eq!(summary["level_pixels"]["statistical"], 64);
    assert_eq!(summary["level_pixels"]["bit-true"], 0);
    assert!(out.join("level.npy").is_file() && out.join("level.svg").is_file());
    let uff = std::fs::read_to_string(out.join("vibration.uff")).unwrap();
    assert!(uff.contains("(statistical)"));
    // A level that does not exist: bad input's exit code 2, the allowed names listed.
    let cfg = config(dir.path(), "fastest");
    let res = tofprobe(&["config", cfg.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&res.stderr);
    assert!(
        res.status.code() == Some(2)
            && ["bit-true", "statistical", "closed-form", "auto"]
                .iter()
                .all(|n| err.contains(n)),
        "{err}"
    );
    // `auto_threshold` through the binary: the plate moves every pixel of this array by
    // more than the default K = 0.5 noise sds (all 64 run bit-true then, measured), by
    // less than K = 10, which runs all 64 statistical; beside any other level the key is
    // refused (exit 2) naming it and the level that takes it.
    let auto = dir.path().join("auto10.toml");
    let text = std::fs::read_to_string(config(dir.path(), "auto")).unwrap();
    std::fs::write(&auto, text + "auto_threshold = 10.0\n").unwrap();
    let out0 = dir.path().join("set0");
    let res = tofprobe(&[
        "simulate",
        auto.to_str().unwrap(),
        "--out",
        out0.to_str().unwrap(),
    ]);
    assert!(
        res.status.success(),
        "{}",
        String::from_utf8_lossy(&res.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out0.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["level_pixels"]["bit-true"], 0, "{summary}");
    assert_eq!(summary["level_pixels"]["statistical"], 64, "{summary}");
    let bad = dir.path().join("bad-k.toml");
    let text = std::fs::read_to_string(config(dir.path(), "statistical")).unwrap();
    std::fs::write(&bad, text + "auto_threshold = 1.0\n").unwrap();
    let res = tofprobe(&["config", bad.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&res.stderr);
    assert!(
        res.status.code() == Some(2)
            && err.contains("array.auto_threshold = 1 applies only with array.level = \"auto\""),
        "{err}"
    );
}
