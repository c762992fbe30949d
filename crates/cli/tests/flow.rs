//! `tofprobe flow` and the RTL commands' probe ROM, end to end on the embedded default:
//! the flow renders the configuration's ΣΔ ROM (periodic, L = 20,000: the 4.5 kHz tone on
//! bin 9), co-simulates clean on a 60,000-pulse frame (three ROM periods) and reports the
//! normalised spectrum; a windowed frame too short for the ΣΔ band falls back to the sign
//! probe and says so.

mod common;

use common::{tofprobe, windowed_default};
use std::path::PathBuf;
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-flow-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn have(tool: &str) -> bool {
    let ok = Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("\n*** SKIPPED: {tool} not installed (scripts/install-tools.sh) ***\n");
    }
    ok
}

#[test]
fn flow_on_the_default_uses_the_sigma_delta_rom_and_passes() {
    if !have("verilator") {
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
