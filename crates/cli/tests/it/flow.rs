//! `tofprobe flow` through the binary, its smoke test (what the flow decides and reports is
//! tested in crates/flow/tests/it/command.rs): a two-bin pixel's short frame exits 0, prints
//! its PASS line and writes the report and the RTL; a frame count out of range exits 2
//! naming `--frames`, and `--signoff` on a frame too long for gate level exits 2 naming
//! `--signoff` before any tool runs. And the RTL commands' probe ROM: a windowed frame too short for the
//! ΣΔ band falls back to the sign probe and says so.

use crate::common;

use common::{tofprobe, windowed_default};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-flow-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn flow_on_a_short_frame_writes_its_report_and_rtl() {
    if !common::have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("smoke");
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("two.toml");
    let text = include_str!("../../../../scenes/default.toml").replacen("bins = 16", "bins = 2", 1);
    assert!(text.contains("bins = 2 "), "default changed");
    std::fs::write(&cfg, text).unwrap();
    let out_dir = dir.join("out");
    let run = |frames: &str| {
        tofprobe(&[
            "flow",
            cfg.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--no-size",
            "--frame-pulses",
            "64",
            "--frames",
            frames,
        ])
    };
    let out = run("2");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("flow PASS: N = 64, "), "{stdout}");
    assert!(stdout.contains("sizing skipped (--no-size)"), "{stdout}");
    assert!(out_dir.join("report.md").is_file());
    assert!(out_dir.join("rtl/tofprobe_pixel.v").is_file());
    let out = run("0");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--frames = 0"), "{err}");
    // `--signoff` reaches the library: a frame too long for gate level is refused before
    // any simulation or synthesis, naming the option and the trace's length (sign-off
    // itself is crates/flow/tests/it/command.rs).
    let out = tofprobe(&[
        "flow",
        cfg.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--no-size",
        "--signoff",
        "--frame-pulses",
        "60000",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--signoff") && err.contains("960009-cycle trace"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn vectors_on_a_frame_too_short_for_the_band_fall_back_to_the_sign_probe() {
    let dir = scratch("short");
    // A windowed ROM is one frame deep: L = N = 64 (the default's periodic ROM would stay
    // 20,000 deep and the frame read its first 64 entries).
    let text = windowed_default();
    std::fs::create_dir_all(&dir).expect("dir");
    let cfg = dir.join("windowed.toml");
    std::fs::write(&cfg, text).expect("write");
    let out = tofprobe(&[
        "vectors",
        cfg.to_str().unwrap(),
        "--out",
        dir.join("v").to_str().unwrap(),
        "--frame-pulses",
        "64",
        "--frames",
        "1",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    // OSR 32 at L = 64: the band f_s/64 holds no bin (k < 1).
    assert!(
        stdout.contains("sign-of-cosine probe ROM (L = 64)")
            && stdout.contains("holds 0 bin(s) at L = 64"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
