//! `tofprobe flow` and the RTL commands' probe ROM, end to end on the embedded default:
//! the flow renders the configuration's ΣΔ ROM (periodic, L = 20,000: the 4.5 kHz tone on
//! bin 9), co-simulates clean on a 60,000-pulse frame (three ROM periods) and reports the
//! normalised spectrum; a windowed frame too short for the ΣΔ band falls back to the sign
//! probe and says so.

use crate::common;

use common::{tofprobe, windowed_default};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-flow-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn flow_on_the_default_uses_the_sigma_delta_rom_and_passes() {
    if !common::have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("default");
    let out = tofprobe(&["flow", "--out", dir.to_str().unwrap(), "--no-size"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 60000 = the largest N ≤ 65536 with 4500 Hz · N / 10 MHz an integer (27).
    assert!(stdout.contains("flow PASS: N = 60000"), "{stdout}");
    assert!(stdout.contains("sizing skipped (--no-size)"), "{stdout}");
    let md = std::fs::read_to_string(dir.join("report.md")).expect("report");
    assert!(md.contains("ΣΔ probe ROM (periodic rectangular"), "{md}");
    assert!(md.contains("wrap clean"), "{md}");
    assert!(md.contains("| 0 | 9 | 4500.0 |"), "{md}");
    // The rendered ROM image is L = 20,000 entries deep (one `$readmemh` line each).
    let hex = std::fs::read_to_string(dir.join("rtl/tofprobe_probe_rom.hex")).expect("rom");
    let lines = hex
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .count();
    assert_eq!(lines, 20_000);
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

/// `flow --signoff` on a two-bin pixel's short frame (N = 64, 2 frames): the co-simulated
/// RTL is synthesised on osu018 and on sky130 (its PDK beside the checkout, as CI has it),
/// the netlists replay the flow's own vectors bit-exactly at gate level and are proven
/// equivalent; the report gets a sign-off section. A frame too long for gate level is
/// refused before any simulation, naming the option and the cycle count. (A broken netlist
/// failing both checks is crates/eda/tests/signoff.rs.)
#[test]
fn flow_signoff_on_a_short_frame() {
    if !common::have_tools(&["verilator", "iverilog", "yosys"]) {
        return;
    }
    let dir = scratch("signoff");
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("two.toml");
    // A 20,000-pulse frame (one ROM period), not the default's 10^7: registers 9 bits
    // narrower, so the two syntheses and equivalence proofs take 23 CPU-s, not 34.
    let text = include_str!("../../../../scenes/default.toml")
        .replacen("bins = 16", "bins = 2", 1)
        .replacen("duration_s = 1.0", "pulses = 20000", 1);
    assert!(
        text.contains("bins = 2 ") && text.contains("pulses = 20000"),
        "default changed"
    );
    std::fs::write(&cfg, text).unwrap();
    let out_dir = dir.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "flow",
            cfg.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--no-size",
            "--signoff",
        ];
        args.extend_from_slice(extra);
        tofprobe(&args)
    };
    let out = run(&["--frame-pulses", "64", "--frames", "2"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 2 + 2·(64·16 + 4 + 2) + 1 = 2063 cycles (4 registers: 2 bins × I, Q).
    for lib in [
        "sign-off osu018: PASS",
        "sign-off sky130_fd_sc_hd tt_025C_1v80: PASS",
    ] {
        assert!(stdout.contains(lib), "{lib} missing: {stdout}");
    }
    assert_eq!(
        stdout
            .matches("gate-level replay 2063 cycles, 2 frame(s) bit-exact")
            .count(),
        2,
        "{stdout}"
    );
    let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(
        md.contains("## Sign-off") && md.contains("equivalence proven"),
        "{md}"
    );

    let out = run(&["--frame-pulses", "60000"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--signoff") && err.contains("960009-cycle trace"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
