//! `[pixel] adders = "auto"` through the binary: the fewest adders whose pixel meets the
//! laser rate on the liberty with 10 % slack, from a measured f_max, chosen once by the
//! resolution so `config` and `rtl` agree; clear refusals when no A meets the rate and for
//! a liberty that cannot be timed. Tiny pixels (B = 1–2, 4096 pulses): a few seconds of
//! synthesis each, cached in the test's own directory.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{default_text, edit, have_tools};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-adders-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The default cut to a 4096-pulse frame with `bins` bins and the laser at `laser`,
/// `adders = "auto"` and `extra` added to `[pixel]`.
fn config(dir: &Path, name: &str, bins: u32, laser: &str, extra: &str) -> PathBuf {
    let text = edit(
        default_text(),
        &[
            ("duration_s = 1.0", "pulses = 4096"),
            ("bins = 16", &format!("bins = {bins}")),
            ("rom_depth = 20000", "rom_depth = 4096"),
            ("laser_rate_hz = 10e6", &format!("laser_rate_hz = {laser}")),
            ("adders = 2 ", &format!("adders = \"auto\"\n{extra}\n#")),
        ],
    );
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write config");
    p
}

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        // The test's own synthesis cache, not the user's.
        .env("TOFPROBE_CACHE", dir.join("cache"))
        .output()
        .expect("run tofprobe")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// B = 2 (P = 4 operations) at a 100 MHz laser: A = 1 needs C = 4, a 400 MHz clock, beyond
/// osu018's ≈ 340 MHz for this pixel; A = 2 needs 200 MHz and meets it. `config` says so
/// with both f_max figures, and `rtl` renders the chosen A = 2, C = 2 pixel.
#[test]
fn fewest_adders_that_meet_the_laser_rate() {
    if !have_tools(&["yosys", "sta"]) {
        return;
    }
    let dir = scratch("fast");
    let cfg = config(&dir, "fast.toml", 2, "100e6", "");
    let cfg = cfg.to_str().unwrap();
    // `config` alone is the pure resolution: the choice stays open, no tool runs.
    let out = run(&dir, &["config", cfg]);
    let t = text(&out);
    assert!(
        out.status.success() && t.contains("adders = \"auto\": open"),
        "{t}"
    );
    assert!(!dir.join("cache").exists(), "config synthesised: {t}");
    let out = run(&dir, &["config", "--time-adders", cfg]);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    let note = t
        .lines()
        .find(|l| l.contains("adders = \"auto\""))
        .unwrap_or_else(|| panic!("no adders note: {t}"));
    assert!(
        note.contains("A = 2, C = 2 (200.0 MHz)")
            && note.contains("A = 1 would need 400.0 MHz (C = 4)"),
        "{note}"
    );
    // The f_max figures are measured, and they bracket the two clocks: A = 1's below 400
    // MHz + 10 %, A = 2's at least 200 MHz + 10 %.
    let fmax: Vec<f64> = note
        .match_indices("f_max ")
        .map(|(i, _)| {
            note[i + 6..]
                .split_whitespace()
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    assert_eq!(fmax.len(), 2, "{note}");
    assert!(fmax[0] >= 200.0 / 0.9 && fmax[1] < 400.0 / 0.9, "{note}");

    let rtl = dir.join("rtl");
    let out = run(&dir, &["rtl", cfg, "--out", rtl.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let pixel = std::fs::read_to_string(rtl.join("tofprobe_pixel.v")).expect("pixel rendered");
    assert!(
        pixel.contains("A=2, C=2"),
        "{}",
        &pixel[..pixel.len().min(800)]
    );
}

/// A 1 GHz laser: even one operation per cycle (A = P, C = 1) needs 1 GHz, beyond osu018;
/// the refusal names the key, the closest A and its slack, and what would work — after one
/// synthesis: A = 1 (2 GHz) measures f_max ≈ 340 MHz, and A = 2 (1 GHz) is more than twice
/// that, so it is skipped unsynthesised. A liberty key naming nothing usable is refused
/// naming `timing_liberty`.
#[test]
fn impossible_rates_and_untimed_liberties_are_refused() {
    if !have_tools(&["yosys", "sta"]) {
        return;
    }
    let dir = scratch("refused");
    let cfg = config(&dir, "ghz.toml", 1, "1e9", "");
    let out = run(&dir, &["config", "--time-adders", cfg.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(2), "{t}");
    for part in [
        "pixel.adders",
        "\"auto\"",
        "closest A = 1 at 2000.0 MHz (C = 2)",
        "1 candidate(s) skipped unsynthesised: even C = 1 needs 1000.0 MHz",
        "sensor.laser_rate_hz",
    ] {
        assert!(t.contains(part), "`{part}` missing: {t}");
    }
    assert!(!t.contains("panicked"), "{t}");

    // A liberty without timing groups (cells and areas only).
    let lib = dir.join("area-only.lib");
    std::fs::write(
        &lib,
        "library (area_only) {\n  cell (INV) { area : 1 ; pin (A) { direction : input ; }\n    pin (Y) { direction : output ; function : \"!A\" ; } }\n}\n",
    )
    .unwrap();
    for (value, expect) in [
        (lib.to_str().unwrap().to_string(), "has no timing groups"),
        (
            dir.join("missing.lib").to_str().unwrap().to_string(),
            "missing.lib",
        ),
    ] {
        let cfg = config(
            &dir,
            "lib.toml",
            1,
            "10e6",
            &format!("timing_liberty = {value:?}"),
        );
        let out = run(&dir, &["config", "--time-adders", cfg.to_str().unwrap()]);
        let t = text(&out);
        assert_eq!(out.status.code(), Some(2), "{t}");
        assert!(
            t.contains("pixel.timing_liberty") && t.contains(expect),
            "{t}"
        );
    }
}

/// The resolution is pure: `config` on an `adders = "auto"` document runs no EDA tool —
/// with a PATH that holds no yosys and no sta it resolves at once and says the choice is
/// open — and so does `simulate` (the registers do not depend on A). The hardware command
/// `rtl` is where the choice is made, so it needs the tools and names the missing one.
#[test]
fn checking_an_auto_design_runs_no_tool() {
    let dir = scratch("pure");
    let cfg = config(&dir, "pure.toml", 2, "100e6", "");
    let empty = dir.join("no-tools");
    std::fs::create_dir_all(&empty).unwrap();
    let bare = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(args)
            .env("PATH", &empty)
            .env("TOFPROBE_CACHE", dir.join("cache"))
            .output()
            .expect("run tofprobe")
    };
    let t0 = std::time::Instant::now();
    let out = bare(&["config", cfg.to_str().unwrap()]);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("adders = \"auto\": open"), "{t}");
    // A synthesis takes seconds; the pure resolution of this small design well under one.
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
    assert!(!dir.join("cache").exists(), "a tool ran: {t}");
    let out = bare(&["simulate", cfg.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", text(&out));
    let out = bare(&[
        "rtl",
        cfg.to_str().unwrap(),
        "--out",
        dir.join("rtl").to_str().unwrap(),
    ]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(2), "{t}");
    assert!(t.contains("yosys"), "{t}");
    assert!(!dir.join("rtl").exists(), "{t}");
}

/// `timing_liberty = "sky130:ss"`: `adders = "auto"` judged at the slowest corner (issue
/// 30 point 5). B = 2 at a 25 MHz laser: on tt one adder (C = 4, 100 MHz) keeps > 50 %
/// slack; at ss (1.40 V, −40 °C) that pixel runs ≈ 56 MHz, and A = 2 (50 MHz, ≈ 49 MHz
/// measured) fails too, so the choice is A = 4 (C = 1, 25 MHz). The ss note names the ss
/// liberty and the f_max of each candidate it rejected, each below its clock + 10 %. An
/// unknown corner is refused naming the key and the corners there are. Four tiny
/// syntheses (≈ 30 s cold).
#[test]
fn the_slowest_corner_judges_the_adders() {
    if !have_tools(&["yosys", "sta"]) {
        return;
    }
    let pdk = tofprobe_eda::pdk::vendored();
    let pdk = pdk.to_str().unwrap();
    let dir = scratch("corner");
    let note = |name: &str, lib: &str| -> (Output, String) {
        let cfg = config(&dir, name, 2, "25e6", &format!("timing_liberty = {lib:?}"));
        let out = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(["config", "--time-adders", cfg.to_str().unwrap()])
            .env("TOFPROBE_CACHE", dir.join("cache"))
            .env("TOFPROBE_SKY130_PDK", pdk)
            .output()
            .expect("run tofprobe");
        let t = text(&out);
        (out, t)
    };
    let (out, t) = note("tt.toml", "sky130:tt");
    assert!(out.status.success(), "{t}");
    assert!(
        t.contains("A = 1, C = 4 (100.0 MHz) on sky130_fd_sc_hd__tt_025C_1v80"),
        "{t}"
    );
    let (out, t) = note("ss.toml", "sky130:ss");
    assert!(out.status.success(), "{t}");
    let line = t
        .lines()
        .find(|l| l.contains("adders = \"auto\""))
        .unwrap_or_else(|| panic!("no adders note: {t}"));
    assert!(
        line.contains("A = 4, C = 1 (25.0 MHz) on sky130_fd_sc_hd__ss_n40C_1v40"),
        "{line}"
    );
    // The rejected candidates' f_max, measured: below 100 and 50 MHz (+ 10 % margin).
    for (cand, clock) in [
        ("A = 1 would need 100.0 MHz", 100.0),
        ("A = 2 would need 50.0 MHz", 50.0),
    ] {
        let i = line
            .find(cand)
            .unwrap_or_else(|| panic!("`{cand}` missing: {line}"));
        let f: f64 = line[i..]
            .split("f_max ")
            .nth(1)
            .and_then(|r| r.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no f_max after `{cand}`: {line}"));
        assert!(f > 0.0 && f < clock / 0.9, "{cand}: f_max {f}");
    }
    let (out, t) = note("xx.toml", "sky130:xx");
    assert_eq!(out.status.code(), Some(2), "{t}");
    assert!(
        t.contains("pixel.timing_liberty")
            && t.contains("no corner `xx`")
            && t.contains("ss_n40C_1v40"),
        "{t}"
    );
}
