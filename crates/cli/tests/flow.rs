//! `tofprobe flow` and the RTL commands' probe ROM, end to end on the embedded default:
//! the flow renders the configuration's ΣΔ ROM (L = N, the short frame that puts the
//! 4.5 kHz tone on bin 27), co-simulates clean and reports the normalised spectrum; a frame
//! too short for the ΣΔ band falls back to the sign probe and says so.

use std::path::PathBuf;
use std::process::{Command, Output};

fn tofprobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .output()
        .expect("run tofprobe")
}

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
    assert!(md.contains("ΣΔ probe ROM (windowed blackman"), "{md}");
    assert!(md.contains("| 0 | 27 | 4500.0 |"), "{md}");
    // The rendered ROM image is L = N = 60000 entries deep (one `$readmemh` line each).
    let hex = std::fs::read_to_string(dir.join("rtl/tofprobe_probe_rom.hex")).expect("rom");
    let lines = hex
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .count();
    assert_eq!(lines, 60_000);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn vectors_on_a_frame_too_short_for_the_band_fall_back_to_the_sign_probe() {
    let dir = scratch("short");
    let out = tofprobe(&[
        "vectors",
        "--out",
        dir.to_str().unwrap(),
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
