//! `tofprobe size` on an `[array]` configuration (issue 27 point 4): the array section of
//! the JSON report against the readout contract's closed forms (docs/pixel-contract.md,
//! "Array"), the ROM's bits and estimates, the pitch, the timestamps, and the broadcast and
//! readout timing of the whole array (3 × 5 ≤ 64 pixels); a readout that does not fit the
//! frame rate refused with the bandwidth that would.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const DEFAULT: &str = include_str!("../../../../scenes/default.toml");

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("tofprobe-array-size-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A one-bin pixel (R = 2 registers), 4096-pulse frames and ROM, on a `rows` × `cols`
/// array with `extra` `[array]` keys.
fn config(dir: &Path, rows: usize, cols: usize, extra: &str) -> PathBuf {
    let mut text = DEFAULT
        .replacen("duration_s = 1.0", "pulses = 4096", 1)
        .replacen("bins = 16", "bins = 1", 1)
        .replacen("rom_depth = 20000", "rom_depth = 4096", 1);
    assert!(text.contains("bins = 1 ") && text.contains("rom_depth = 4096"));
    text += &format!(
        "\n[array]\nrows = {rows}\ncols = {cols}\npitch_um = 40.0\nmm_per_pixel = 1.0\n{extra}\n"
    );
    let p = dir.join(format!("array-{rows}x{cols}.toml"));
    std::fs::write(&p, text).expect("write config");
    p
}

fn size(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .arg("size")
        .args(args)
        .arg("--cache")
        .arg(cache)
        .output()
        .expect("run tofprobe")
}

fn num(v: &serde_json::Value, path: &[&str]) -> f64 {
    let mut x = v;
    for k in path {
        x = &x[*k];
    }
    x.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number: {x}"))
}

#[test]
fn a_three_by_five_array_is_sized_against_the_readout_contract() {
    if !crate::common::have_tools(&["yosys", "sta"]) {
        return;
    }
    let dir = scratch("3x5");
    let cfg = config(&dir, 3, 5, "");
    let out = size(
        &[
            cfg.to_str().unwrap(),
            "--no-sky130",
            "--json",
            "--sweep-bins",
            "1",
        ],
        common::shared_synth_cache(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let a = &v["array"];
    assert_eq!(a["pixels"], 15);
    let w = num(&v, &["design", "width"]);
    let regs = num(&v, &["design", "registers"]);
    assert_eq!(regs, 2.0, "one bin: I and Q");
    // Readout contract: b = W (the default), k = 1, g = 1; D = P·(R+1)·k·g + 1; a frame
    // N·C + D cycles at f_clk = C·f_laser.
    let r = &a["readout"];
    assert_eq!(num(r, &["bits_per_beat"]), w);
    let d = 15.0 * (regs + 1.0) + 1.0;
    assert_eq!(num(r, &["readout_cycles"]), d);
    let c = num(&v, &["design", "cycles_per_pulse"]);
    let f_clk = c * 10e6;
    assert_eq!(num(r, &["frame_cycles"]), 4096.0 * c + d);
    assert!((num(r, &["frame_rate_hz"]) - f_clk / (4096.0 * c + d)).abs() < 1e-9);
    assert_eq!(num(r, &["payload_bits_per_frame"]), 15.0 * 3.0 * w);
    // Timestamps: 15 pixels × 10^7 pulses/s × T = 7 bits (80 codes), below 100 Gbit/s.
    let t = &a["timestamps"];
    assert_eq!(num(t, &["array_bits_per_s"]), 15.0 * 1e7 * 7.0);
    assert_eq!(t["exceeds_paper_line"], false);
    // The ROM: L × 2B bits; the sky130 macro estimate at 534,277 µm² / 32,768 bits; as
    // logic, 1024 of its 4096 entries synthesised and the area scaled by 4 exactly.
    let rom = &a["rom"];
    assert_eq!(num(rom, &["bits"]), 4096.0 * 2.0);
    let sky = &rom["macro_estimates"][0];
    assert_eq!(sky["technology"], "sky130");
    assert!((num(sky, &["area_um2"]) - 8192.0 * 534_277.0 / 32_768.0).abs() < 1e-6);
    let logic = &rom["logic"][0];
    assert_eq!(num(logic, &["synthesised_depth"]), 1024.0);
    assert!(num(logic, &["synthesised_area_um2"]) > 0.0);
    assert_eq!(
        num(logic, &["area_um2"]),
        num(logic, &["synthesised_area_um2"]) * 4.0
    );
    // Pitch: √(area / 0.7 · (40/180)²) on osu018.
    let area = num(&v, &["area", "total_area_um2"]);
    let p = &a["pitch"][0];
    let want = (area / 0.7 * (40.0f64 / 180.0).powi(2)).sqrt();
    assert!((num(p, &["pitch_um"]) - want).abs() < 1e-9, "{p}");
    // Timing: 3 × 5 is timed whole; slack = period − delay at the pixel clock.
    let timing = a["timing"].as_array().expect("timing rows");
    assert_eq!(timing.len(), 1, "osu018 only (--no-sky130)");
    assert_eq!(timing[0]["netlist"], "whole 3 × 5");
    let period = 1e3 / num(&timing[0], &["clock_mhz"]);
    for path in ["broadcast", "readout"] {
        let delay = num(&timing[0], &[path, "delay_ns"]);
        assert!(delay > 0.0 && delay < period, "{path}: {delay} ns");
        let slack = num(&timing[0], &[path, "slack_ns"]);
        assert!((slack - (period - delay)).abs() < 1e-9);
    }
    // The totals: 15 pixels + the ROM macro (osu018's estimate) + the array's logic.
    let tot = &a["totals"][0];
    assert!((num(tot, &["pixels_um2"]) - 15.0 * area).abs() < 1e-6);
    let shared = num(&timing[0], &["shared_logic_um2"]);
    assert!(shared > 0.0);
    assert!(
        (num(tot, &["total_um2"])
            - (15.0 * area + num(&rom["macro_estimates"][1], &["area_um2"]) + shared))
            .abs()
            < 1e-6
    );
    double_buffer_is_the_register_file_again(&v, 15.0, false);
}

/// The double buffer's shadow (reported whether the option is on or off): (R+1)·W flops —
/// the registers, which the synthesised register file holds exactly, and the status word —
/// at the file's own area per flop, added to every pixel and to the array's total.
fn double_buffer_is_the_register_file_again(v: &serde_json::Value, pixels: f64, enabled: bool) {
    let db = &v["array"]["double_buffer"];
    assert_eq!(db["enabled"], enabled);
    let (r, w) = (
        num(v, &["design", "registers"]),
        num(v, &["design", "width"]),
    );
    let bits = r * w;
    assert_eq!(num(db, &["shadow_bits_per_pixel"]), (r + 1.0) * w);
    let a = &db["areas"][0];
    let rf = &v["area"]["split"]["register_file"];
    assert_eq!(
        num(a, &["register_file_flops"]),
        bits,
        "R·W flops in the file"
    );
    assert_eq!(num(rf, &["flops"]), bits);
    // The file's area per flop, times (R+1)·W.
    let shadow = num(rf, &["area_um2"]) * (r + 1.0) / r;
    assert!((num(a, &["shadow_um2"]) - shadow).abs() < 1e-6 * shadow);
    let flop = v["area"]["smallest_flop"][1].as_f64().expect("a flop");
    assert!((num(a, &["shadow_flops_only_um2"]) - (r + 1.0) * w * flop).abs() < 1e-6);
    assert!(num(a, &["shadow_flops_only_um2"]) < num(a, &["shadow_um2"]));
    let pixel = num(v, &["area", "total_area_um2"]);
    assert!((num(a, &["pixel_with_um2"]) - (pixel + shadow)).abs() < 1e-6);
    let total = num(&v["array"]["totals"][0], &["total_um2"]);
    assert!((num(a, &["array_total_um2"]) - total).abs() < 1e-6);
    assert!((num(a, &["array_total_with_um2"]) - (total + pixels * shadow)).abs() < 1e-3);
}

/// 4 × 4 SPADs as 2 × 2 superpixels of G = 2: the front end synthesised, the register bits
/// per SPAD a quarter of the plain pixel's, the area per SPAD (pixel + front end) / 4.
#[test]
fn a_superpixel_array_reports_memory_and_area_per_spad() {
    if !crate::common::have_tools(&["yosys", "sta"]) {
        return;
    }
    let dir = scratch("superpixel");
    let cfg = config(&dir, 4, 4, "superpixel = 2\ndouble_buffer = true");
    let out = size(
        &[
            cfg.to_str().unwrap(),
            "--no-sky130",
            "--json",
            "--sweep-bins",
            "1",
        ],
        common::shared_synth_cache(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let a = &v["array"];
    assert_eq!(a["pixels"], 4, "2 × 2 superpixels");
    assert_eq!(num(a, &["configured_pitch_um"]), 80.0, "2 × the 40 µm SPAD");
    let sp = &a["superpixel"];
    assert_eq!(
        (sp["side"].as_u64(), sp["spads_per_pixel"].as_u64()),
        (Some(2), Some(4))
    );
    assert_eq!(num(sp, &["spad_pitch_um"]), 40.0);
    // T = 7: k = 7 + 2·⌈log2 4⌉ = 11, a word of 12 bits.
    assert_eq!(
        (num(sp, &["shift"]), num(sp, &["table_bits"])),
        (11.0, 12.0)
    );
    let bits = num(&v, &["design", "registers"]) * num(&v, &["design", "width"]);
    assert_eq!(num(sp, &["plain_bits_per_spad"]), bits);
    assert_eq!(num(sp, &["bits_per_spad"]), bits / 4.0);
    let s = &sp["area"][0];
    let pixel = num(&v, &["area", "total_area_um2"]);
    let fe = num(s, &["front_end_um2"]);
    assert!(fe > 0.0 && num(s, &["front_end_cells"]) > 0.0, "{s}");
    assert_eq!(num(s, &["plain_per_spad_um2"]), pixel);
    assert!((num(s, &["per_spad_um2"]) - (pixel + fe) / 4.0).abs() < 1e-9);
    double_buffer_is_the_register_file_again(&v, 4.0, true);
    // The array RTL renders the superpixel: 2 × 2 SPADs per pixel behind one front end each.
    let out = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["rtl", cfg.to_str().unwrap(), "--out"])
        .arg(dir.join("rtl"))
        .output()
        .expect("run tofprobe");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let rtl = std::fs::read_to_string(dir.join("rtl/tofprobe_array.v")).unwrap();
    assert!(dir.join("rtl/tofprobe_superpixel.v").exists());
    assert!(rtl.contains("tofprobe_superpixel u_superpixel ("), "{err}");
}

#[test]
fn a_frame_rate_the_readout_cannot_reach_is_refused_with_the_bandwidth_that_would() {
    let dir = scratch("rate");
    // 4096 pulses at C cycles is ≈ 24 frames/s (C = 16); 1 Mbit/s cannot read 64 × 64 × 3
    // words of W bits between 20 frames a second.
    let cfg = config(
        &dir,
        64,
        64,
        "readout_bits = 1\nreadout_bits_per_s = 1e6\nframe_rate_hz = 20.0",
    );
    let out = size(
        &[cfg.to_str().unwrap(), "--no-sky130", "--json"],
        common::shared_synth_cache(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for part in ["array.frame_rate_hz", "readout_bits_per_s"] {
        assert!(err.contains(part), "`{part}` missing: {err}");
    }
    // A utilisation outside (0, 1] names the option.
    let ok = config(&dir, 2, 2, "");
    let out = size(
        &[ok.to_str().unwrap(), "--no-sky130", "--utilisation", "1.5"],
        common::shared_synth_cache(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("utilisation") && err.contains("1.5"), "{err}");
}
