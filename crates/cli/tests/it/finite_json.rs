//! No NaN or infinity in any command's `--json` (docs/reliability.md): `simulate`,
//! `tradeoff`, `bench scene`/`bench pixel`, `replay` (a real record) and `cosim` run through
//! the binary on extreme configurations — every bound of the amplitudes and rates, no
//! detections, one bin — and the shared check (`common::finite`) walks every number.
//! `size` and `reproduce --quick` are checked by their own tests (size.rs, reproduce.rs),
//! which already pay for their runs. Also: an empty record prints "none"/`null` rather than
//! 0.0000 µm, and the probe amplitude's printed bound is a value that is accepted.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::finite::{Walk, assert_finite_output};
use common::{default_text, edit};

/// A short windowed Fourier frame (N = 4096, B = 4) with `extra` edits.
fn short(extra: &[(&str, &str)]) -> String {
    let mut e = vec![
        ("duration_s = 1.0 ", "pulses = 4096 #"),
        ("rom_mode = \"periodic\"", "rom_mode = \"windowed\""),
        ("bins = 16 ", "bins = 4 "),
        ("cycles_per_pulse = 16 ", "cycles_per_pulse = 4 "),
    ];
    e.extend_from_slice(extra);
    edit(default_text(), &e)
}

/// The extreme configurations: each at a bound the resolution accepts.
fn extremes() -> Vec<(&'static str, String)> {
    vec![
        ("baseline", short(&[])),
        (
            "no detections (ρ_s = 0)",
            short(&[("signal_rate = 1.0", "signal_rate = 0.0")]),
        ),
        (
            "tiny signal (ρ_s = 1e-300)",
            short(&[("signal_rate = 1.0", "signal_rate = 1e-300")]),
        ),
        (
            "all background (ρ_s = 0, ρ_b = 100, its bound)",
            short(&[
                ("signal_rate = 1.0", "signal_rate = 0.0"),
                ("background_rate = 0.0", "background_rate = 100.0"),
            ]),
        ),
        (
            "smallest probe amplitude (0.01)",
            short(&[("amplitude = 0.5 ", "amplitude = 0.01 ")]),
        ),
        (
            // The bound the refusal prints (0.9 × 0.7775, rounded down).
            "largest probe amplitude (0.6997)",
            short(&[("amplitude = 0.5 ", "amplitude = 0.6997 ")]),
        ),
        ("one bin", short(&[("bins = 4 ", "bins = 1 ")])),
        (
            "no motion",
            short(&[("amplitude_mm = 0.1", "amplitude_mm = 0.0")]),
        ),
        (
            "motion filling the window (29 mm about 30 mm in [0, 60))",
            short(&[("amplitude_mm = 0.1", "amplitude_mm = 29.0")]),
        ),
        (
            "tone at 1e-300 Hz",
            short(&[("frequency_hz = 4500.0", "frequency_hz = 1e-300")]),
        ),
    ]
}

fn run_json(what: &str, args: &[&str], config: Option<&Path>) -> Walk {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    c.args(args);
    if let Some(p) = config {
        c.arg(p);
    }
    let o = c.output().expect("run tofprobe");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{what}: {args:?}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    assert_finite_output(&format!("{what}: {args:?}"), &o.stdout)
}

fn record() -> PathBuf {
    tofprobe_testkit::data::tttr_record("hydraharp_v20_t3.ptu")
}

#[test]
fn every_command_json_is_finite_on_extreme_configurations() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut runs, mut numbers, mut nulls) = (0, 0, 0);
    let mut tally = |w: Walk| {
        runs += 1;
        numbers += w.numbers;
        nulls += w.nulls;
    };
    for (i, (what, text)) in extremes().into_iter().enumerate() {
        let cfg = tmp.path().join(format!("x{i}.toml"));
        std::fs::write(&cfg, text).unwrap();
        tally(run_json(what, &["simulate", "--json"], Some(&cfg)));
        tally(run_json(what, &["tradeoff", "--json"], Some(&cfg)));
        let c = cfg.to_str().unwrap();
        tally(run_json(
            what,
            &[
                "bench",
                "pixel",
                "--config",
                c,
                "--pulses",
                "4096",
                "--cycle-pulses",
                "1000",
                "--json",
            ],
            None,
        ));
    }
    tally(run_json("scene bench", &["bench", "scene", "--json"], None));
    // The vendored record, fitted, and quantised by a configuration whose window misses
    // every photon (0 detections: the spectrum is absent, not 0).
    let rec = record();
    let r = rec.to_str().unwrap();
    tally(run_json("replay, fitted", &["replay", r, "--json"], None));
    let cfg = tmp.path().join("x0.toml");
    let w = run_json("replay, empty window", &["replay", r, "--json"], Some(&cfg));
    assert!(w.nulls >= 4, "an empty window's spectrum is null, not 0");
    tally(w);
    if Command::new("verilator").arg("--version").output().is_ok() {
        let out = tmp.path().join("cosim");
        let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(["cosim", "--frame-pulses", "1024", "--json", "--out"])
            .arg(&out)
            .arg(tmp.path().join("x1.toml"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        tally(assert_finite_output("cosim, no detections", &o.stdout));
        // The same design's RTL through `bench pixel --verilator` (its harness build shared
        // with the cosim above): both rates and a positive ratio, bit-exact.
        let c = tmp.path().join("x1.toml");
        let args = ["bench", "pixel", "--config", c.to_str().unwrap()];
        let more = [
            "--pulses",
            "4096",
            "--cycle-pulses",
            "1024",
            "--verilator",
            "--json",
        ];
        let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(args.iter().chain(&more))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        tally(assert_finite_output("bench pixel --verilator", &o.stdout));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["cosim_pass"], true, "{j}");
        // 2 + (1024·C + R + 2) + 1 cycles of the x1 pixel (C = 4, R = 8).
        assert_eq!(j["cosim_cycles"], 2 + (1024 * 4 + 8 + 2) + 1, "{j}");
        assert!(j["cycle_model_vs_verilator"].as_f64().unwrap() > 0.0, "{j}");
    } else {
        eprintln!("skipped cosim: no verilator");
    }
    eprintln!(
        "finite JSON: {runs} runs, {numbers} numbers checked, {nulls} documented nulls, 0 non-finite"
    );
}

/// The check can fail: NaN and infinity (written by serde_json as null) under a key that
/// is not a documented absent figure, and a non-finite number, are caught.
#[test]
fn the_check_catches_a_null_figure() {
    let bad = serde_json::json!({"detections": 3, "bins": [{"frequency_hz": f64::NAN}]});
    let r = std::panic::catch_unwind(|| common::finite::assert_finite("bad", &bad));
    assert!(r.is_err());
    let ok = serde_json::json!({"mean_depth_mm": null, "x": [1.5, 2]});
    assert_eq!(common::finite::assert_finite("ok", &ok).numbers, 2);
}

/// A record without detections has no spectrum: `simulate` and `replay` say so (text) and
/// give `null` (JSON) instead of 0.0000 µm; with detections the same figures are numbers.
#[test]
fn an_empty_record_says_so_instead_of_printing_zero() {
    let tmp = tempfile::tempdir().unwrap();
    let empty = tmp.path().join("empty.toml");
    std::fs::write(&empty, short(&[("signal_rate = 1.0", "signal_rate = 0.0")])).unwrap();
    let full = tmp.path().join("full.toml");
    std::fs::write(&full, short(&[])).unwrap();
    let sim = |cfg: &Path, json: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
        c.arg("simulate").arg(cfg);
        if json {
            c.arg("--json");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let text = sim(&empty, false);
    assert!(text.contains("none (no detections in the frame)"), "{text}");
    assert!(
        text.contains("mean depth         none (no detections)"),
        "{text}"
    );
    assert!(
        !text
            .lines()
            .any(|l| l.contains("0.0000") && (l.contains("um") || l.contains("mm"))),
        "a zero figure printed for an empty record:\n{text}"
    );
    let v: serde_json::Value = serde_json::from_str(&sim(&empty, true)).unwrap();
    let bt = &v["bit_true"];
    assert!(bt["noise_estimate_um"].is_null(), "{bt}");
    for b in bt["bins"].as_array().unwrap() {
        assert!(
            b["amplitude_um"].is_null() && b["phase_deg"].is_null(),
            "{b}"
        );
        assert!(b["frequency_hz"].as_f64().is_some_and(|f| f > 0.0), "{b}");
    }
    // With detections the same figures are numbers: the check above can fail.
    let v: serde_json::Value = serde_json::from_str(&sim(&full, true)).unwrap();
    assert!(
        v["bit_true"]["noise_estimate_um"]
            .as_f64()
            .is_some_and(|x| x > 0.0)
    );
    assert!(sim(&full, false).contains("noise estimate"));

    let rec = record();
    // The short configuration's 0–400 ps window misses every photon of the record.
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .arg("replay")
        .arg(&rec)
        .arg(&full)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("detections: 0 in the window"), "{text}");
    assert!(
        text.contains("bit-true spectrum: none (no detections in the window)"),
        "{text}"
    );
    assert!(!text.contains("0.0000 µm"), "{text}");
}

/// The refusal of a too-large probe amplitude prints a bound that is itself accepted
/// (0.69975 used to print as 0.6998, which was refused).
#[test]
fn the_printed_amplitude_bound_is_a_value_that_works() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = tmp.path().join("a.toml");
    std::fs::write(&cfg, short(&[("amplitude = 0.5 ", "amplitude = 0.99 ")])).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .arg("config")
        .arg(&cfg)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    let bound = err
        .split("amplitude <= ")
        .nth(1)
        .and_then(|r| r.split(|c: char| c != '.' && !c.is_ascii_digit()).next())
        .unwrap_or_else(|| panic!("no bound in: {err}"));
    assert!(err.contains("0.01 <= amplitude"), "{err}");
    std::fs::write(
        &cfg,
        short(&[("amplitude = 0.5 ", &format!("amplitude = {bound} "))]),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .arg("config")
        .arg(&cfg)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "the printed bound {bound} is refused: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}
