//! `tofprobe tradeoff` on a short frame: every level is reported with finite numbers, the
//! slow levels are marked as extrapolated, the float levels agree with each other and the
//! bit-true level with the float ΣΔ probing; `--out` writes the table and the Pareto plot.

use std::process::Command;

#[test]
fn tradeoff_reports_every_level() {
    let out = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["config", "--print-default"])
        .output()
        .expect("run");
    let n: u64 = 1 << 16;
    // A 1 mm tone on bin 30 of the 2^16-pulse frame, B = 4 (C = 4).
    let f = 30.0 * 10e6 / n as f64;
    let text = String::from_utf8(out.stdout)
        .expect("utf-8")
        .replacen("duration_s = 1.0", &format!("pulses = {n}"), 1)
        .replacen("amplitude_mm = 0.1", "amplitude_mm = 1.0", 1)
        .replacen("frequency_hz = 4500.0", &format!("frequency_hz = {f}"), 1)
        .replacen("bins = 16", "bins = 4", 1)
        .replacen("cycles_per_pulse = 16", "cycles_per_pulse = 4", 1);
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
    let amp = |name: &str| get(name)["amplitude_um"].as_f64().expect("amplitude");
    // The streamed selected-bin DFT equals the FFT at the same bins to rounding (1e-6 µm
    // on ~1000 µm: both are double-precision sums of the same 2^16 samples).
    assert!((amp("float full DFT") - amp("float selected-bin DFT")).abs() < 1e-6);
    // Bit-true vs float ΣΔ on the same ROM: the F = 8 fixed-point prefilter (≤ 2^−8 code
    // per sample, averaging down) and the two start-up transients of the prefilter from
    // the 30 mm static depth, which do not cancel exactly and shrink as 1/N: measured
    // 3.4 µm here (2^16 pulses), 0.03 µm at 10^7. 1% of the tone (10 µm) bounds it.
    assert!((amp("bit-true transaction") - amp("float ΣΔ probing")).abs() < 10.0);
    // The float DFT reads the 1 mm tone within 4× its noise floor (68 µm at 2^16 pulses).
    assert!((amp("float full DFT") - 1000.0).abs() < 272.0);
    assert_eq!(amp("closed form"), 1000.0);
    let md = std::fs::read_to_string(dir.join("tradeoff.md")).expect("table");
    assert!(md.contains("| cycle-accurate (extrapolated) |"), "{md}");
    let svg = std::fs::read_to_string(dir.join("pareto.svg")).expect("plot");
    assert!(svg.starts_with("<svg"));
}
