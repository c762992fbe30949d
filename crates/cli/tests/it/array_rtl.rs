//! The array in silicon (docs/pixel-contract.md "Array"): `tofprobe flow` on a 4 × 4 array
//! renders, co-simulates bit-exact and reports; `tofprobe cosim` on 3 × 5 (Haar, a 5-bit
//! port) and 8 × 8 arrays under Verilator and a 2 × 2 under Icarus is bit-exact at the
//! array's ports; each array mutant is caught at the cycle the faulty array model predicts,
//! named by pixel (r, c) and word; bad readouts are refused naming the key.
//!
//! Cold cost: three Verilator builds (4 × 4, 3 × 5, 8 × 8 small pixels; ≈ 20, 20 and 60 s on
//! two cores) and five Icarus runs (< 1 s each); rebuilt only when the RTL changes.

use std::path::Path;

use tofprobe_array::rtl_driver::run;
use tofprobe_array::rtl_model::ArrayModel;
use tofprobe_design::{Chip, Document, RomPurpose, RtlOverrides, resolve};
use tofprobe_flow::array::vectors::scene_detections;
use tofprobe_flow::array::{ArrayCosimOptions, ArraySimulator, cosim_array};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::array_vectors::exercise;

use crate::common::{default_text, edit, have_tools, tofprobe};

/// A small-pixel array configuration: B = 2 (R = 4), C = 4, 20,000 pulses (Haar U = 2,
/// R = 7, 16,384 pulses); `extra` is
/// appended to its `[array]`.
fn config(rows: u32, cols: u32, haar: bool, extra: &str) -> String {
    let mut t = edit(
        default_text(),
        &[
            (
                "duration_s = 1.0",
                if haar {
                    "pulses = 16384"
                } else {
                    "pulses = 20000"
                },
            ),
            ("bins = 16", "bins = 2"),
            ("cycles_per_pulse = 16", "cycles_per_pulse = 4"),
        ],
    );
    if haar {
        t = edit(
            t,
            &[("mode = \"fourier\"", "mode = \"haar\"\nhaar_scales = 2")],
        );
        // Haar has no prefilter: its keys go.
        t = edit(
            t,
            &[
                ("shift = 5", ""),
                ("frac_bits = 8", ""),
                ("adders = 2", "adders = 1"),
            ],
        );
    }
    format!(
        "{t}\n[array]\nrows = {rows}\ncols = {cols}\npitch_um = 30.0\nmm_per_pixel = 1.0\n{extra}"
    )
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

fn stdout(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The issue's "Done when": `tofprobe flow` on a 4 × 4 array renders, co-simulates bit-exact
/// and reports (the readout at the configured frame and the timestamp comparison); the
/// directory is a whole set.
#[test]
fn flow_on_a_4x4_array_renders_cosimulates_and_reports() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "a44.toml", &config(4, 4, false, ""));
    let out = dir.path().join("flow");
    let o = tofprobe(&[
        "flow",
        &cfg,
        "--out",
        out.to_str().unwrap(),
        "--frame-pulses",
        "16",
    ]);
    let text = stdout(&o);
    assert!(o.status.success() && text.contains("flow PASS"), "{text}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    for want in [
        "a 4 × 4 array of Fourier pixels",
        "**PASS**",
        "0 mismatches",
        // 16 pixels × 5 words, N = 20,000 at C = 4: 80,000 + 16·5 + 1 cycles per frame.
        "16 pixels",
        "a frame every 80081 cycles",
        "Reading every timestamp out instead: 16 pixels × 1.000e7 pulses/s × T = 7 bits",
    ] {
        assert!(md.contains(want), "{want}: {md}");
    }
    let names: Vec<String> = std::fs::read_dir(out.join("rtl"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().any(|n| n == "tofprobe_array.v") && names.iter().any(|n| n == "tofprobe.core"),
        "{names:?}"
    );
    let core = std::fs::read_to_string(out.join("rtl/tofprobe.core")).unwrap();
    assert!(
        core.contains("toplevel: tofprobe_array")
            && core.contains("tofprobe:tofprobe:tofprobe_array"),
        "{core}"
    );
    let check = tofprobe(&["check-set", out.to_str().unwrap()]);
    assert!(check.status.success(), "{}", stdout(&check));
}

/// 3 × 5 Haar on a 5-bit port (W = 23: 5 beats per word) and 8 × 8 Fourier (one build),
/// two frames each, bit-exact under Verilator.
#[test]
fn verilator_is_bit_exact_on_odd_and_large_arrays() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, text, n) in [
        ("a35.toml", config(3, 5, true, "readout_bits = 5\n"), "16"),
        ("a88.toml", config(8, 8, false, ""), "16"),
    ] {
        let cfg = write(dir.path(), name, &text);
        let out = dir.path().join(format!("{name}-out"));
        let o = tofprobe(&[
            "cosim",
            &cfg,
            "--frame-pulses",
            n,
            "--frames",
            "2",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        let text = stdout(&o);
        assert!(o.status.success(), "{name}: {text}");
        let j = crate::common::last_json(&o);
        assert_eq!(j["pass"], true, "{name}: {j}");
        assert_eq!(j["mismatches"], 0, "{name}: {j}");
        let (rows, cols) = (j["rows"].as_u64().unwrap(), j["cols"].as_u64().unwrap());
        // Each pixel's R + 1 words, k beats each: Haar U = 2 → 7 registers of W = 23 bits
        // (8-bit operands summed over N = 2^14 pulses: 8 + 14 + 1), k = ceil(23 / 5) = 5;
        // Fourier B = 2 → 4 registers, k = 1.
        let want = if rows == 3 { 15 * 8 * 5 } else { 64 * 5 };
        assert_eq!(j["beats_per_frame"], want, "{name}: {j}");
        let _ = cols;
    }
}

fn small_design(rows: u32, cols: u32) -> tofprobe_design::ResolvedDesign {
    let text = config(rows, cols, false, "");
    resolve(Document::from_toml_str(&text, "a.toml").unwrap(), "a.toml").unwrap()
}

/// Beyond the whole-array line: a 64 × 64 array (4096 pixels: its whole build would take
/// Verilator tens of minutes) co-simulated as its far-corner 2 × 2 tile, whose readout
/// slots are the last four rows' last pixels, with the whole array's sequencer and readout
/// timing: bit-exact under Verilator, the tile's beats where the whole array's formula puts
/// them.
#[test]
fn a_tile_of_a_64x64_array_is_bit_exact_with_the_whole_readout() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "a64.toml", &config(64, 64, false, ""));
    let out = dir.path().join("t64");
    let o = tofprobe(&[
        "cosim",
        &cfg,
        "--frame-pulses",
        "16",
        "--tile",
        "62,62,2,2",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    let j = crate::common::last_json(&o);
    assert_eq!(
        (j["pass"].as_bool(), j["mismatches"].as_u64()),
        (Some(true), Some(0)),
        "{j}"
    );
    // 4096 slots of 5 cycles + 1: the whole array's readout.
    assert_eq!(j["readout_cycles"], 4096 * 5 + 1, "{j}");
    // 2 + 16·4 + 20,481 cycles + the 6 of the tail.
    assert_eq!(j["cycles"], 2 + 64 + 20_481 + 6, "{j}");
    let readout = std::fs::read_to_string(out.join("vectors/readout.txt")).unwrap();
    let rows: Vec<&str> = readout.lines().filter(|l| l.starts_with("0 ")).collect();
    assert_eq!(rows.len(), 4, "{readout}");
    assert!(
        rows[0].starts_with("0 62 62:") && rows[3].starts_with("0 63 63:"),
        "{readout}"
    );
}

/// A 2 × 2 array under Icarus is bit-exact; each array mutant is caught, at the first
/// cycle where the array model carrying the same fault differs from the correct one, and
/// the report names what the array was doing there.
#[test]
fn icarus_is_bit_exact_and_every_array_mutant_is_caught_where_predicted() {
    if !have_tools(&["iverilog", "vvp"]) {
        return;
    }
    let design = small_design(2, 2);
    let dir = tempfile::tempdir().unwrap();
    let mut o = ArrayCosimOptions::new(&dir.path().join("good"));
    (o.frame_pulses, o.rom_depth, o.frames, o.simulator) =
        (Some(16), Some(8), 2, ArraySimulator::Icarus);
    let good = cosim_array(&design, &o).unwrap();
    assert!(
        good.pass && good.mismatches == 0 && good.cycles > 100,
        "{:?}",
        good.first
    );
    // The model's prediction for each fault.
    let ov = RtlOverrides {
        frame_pulses: Some(16),
        rom_depth: Some(8),
    };
    let chip = Chip::array_of(&design, &ov, RomPurpose::Replayed).unwrap();
    let ro = chip.readout.unwrap();
    // The stimulus the co-simulation replays: the scene's, thinned (`exercise`).
    let mut det = scene_detections(&design, 16, 2, None).unwrap();
    exercise(&mut det, 2, 1);
    let model = |f| {
        run(
            &mut ArrayModel::new(&ro, &chip.pixel, &chip.rom.words, f).unwrap(),
            &det,
            2,
        )
        .unwrap()
    };
    let reference = model(None);
    for (fault, what) in [
        (ArrayFault::RowLate { row: 1 }, "frame 0, pulse 0"),
        (ArrayFault::NeighbourTdc { row: 0, col: 1 }, "pixel (0, 1)"),
        (ArrayFault::OrderSwap, "pixel (0, 0)"),
        (ArrayFault::RowStuck { row: 0 }, "pixel (1, 0)"),
    ] {
        let faulty = model(Some(fault));
        let predicted = (1..reference.pins.len())
            .find(|&c| reference.pins[c] != faulty.pins[c])
            .unwrap_or_else(|| panic!("{fault:?}: the model does not see it"))
            as u64;
        o.out = dir.path().join(fault.name());
        o.fault = Some(fault);
        let r = cosim_array(&design, &o).unwrap();
        let first = r.first.clone().unwrap_or_default();
        assert!(!r.pass && r.mismatches > 0, "{fault:?} not caught");
        assert_eq!(r.first_cycle, Some(predicted), "{fault:?}: {first}");
        assert!(first.contains(what), "{fault:?}: {first}");
    }
}

/// A readout width beyond W and a frame rate the readout does not allow are refused by
/// every command, exit status 2, naming the key and what works.
#[test]
fn bad_readouts_are_refused_by_the_commands() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "wide.toml",
        &config(2, 2, false, "readout_bits = 63\n"),
    );
    let o = tofprobe(&["rtl", &cfg, "--out", dir.path().join("r").to_str().unwrap()]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(2), "{text}");
    assert!(
        text.contains("array.readout_bits = 63") && text.contains("allowed 1..="),
        "{text}"
    );
    // 64 × 64 pixels × 5 words at one beat per cycle: 20,481 cycles of readout after
    // 80,000 of accumulation at f_clk = C · f_laser = 40 MHz: 398.085 Hz at most.
    let cfg = write(
        dir.path(),
        "fast.toml",
        &config(64, 64, false, "frame_rate_hz = 1000.0\n"),
    );
    let o = tofprobe(&["config", &cfg]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(2), "{text}");
    assert!(
        text.contains("array.frame_rate_hz = 1000") && text.contains("allows at most 398.085"),
        "{text}"
    );
}

/// `[array] superpixel = 2`: 4 × 4 SPADs as 2 × 2 pixels, each behind one averaging front
/// end (`<prefix>_superpixel`, docs/pixel-contract.md "Superpixel"). Bit-exact under
/// Verilator and Icarus against the array model, which averages the same SPAD stimulus
/// with `tofprobe_pixel::Superpixel`; the stimulus holds pulses where two or more of a
/// pixel's SPADs fire with different codes (the average is exercised, not one SPAD's code
/// passed through); two crossed averaged TDCs are caught at the cycle the faulty model
/// predicts. One Verilator build (≈ 10 s on two cores), two Icarus runs.
#[test]
fn a_superpixel_array_is_bit_exact_and_a_crossed_average_is_caught() {
    let text = config(4, 4, false, "superpixel = 2\n");
    let design = resolve(
        Document::from_toml_str(&text, "sp.toml").unwrap(),
        "sp.toml",
    )
    .unwrap();
    // The stimulus the co-simulation replays: the scene's, thinned so that every count of
    // valid SPADs (none, exactly one, …, all four) occurs (`exercise`).
    let mut det = scene_detections(&design, 16, 2, None).unwrap();
    exercise(&mut det, 2, 2);
    // 16 SPADs row-major over the 4 × 4 grid: pixel (r, c) owns (2r + i, 2c + j).
    assert_eq!(det.len(), 16);
    for count in 0..=4 {
        let seen = (0..32).any(|n| {
            (0..4).any(|px| {
                let (r, c) = (px / 2, px % 2);
                (0..4)
                    .filter(|s| det[(2 * r + s / 2) * 4 + 2 * c + s % 2][n].is_some())
                    .count()
                    == count
            })
        });
        assert!(
            seen,
            "no pulse with exactly {count} valid SPAD(s) of a pixel"
        );
    }
    let mixed = (0..32)
        .filter(|&n| {
            (0..4).any(|px| {
                let (r, c) = (px / 2, px % 2);
                let codes: Vec<u32> = (0..4)
                    .filter_map(|s| det[(2 * r + s / 2) * 4 + 2 * c + s % 2][n])
                    .collect();
                codes.len() >= 2 && codes.iter().any(|&x| x != codes[0])
            })
        })
        .count();
    assert!(mixed > 0, "no pulse averages two different codes");
    let dir = tempfile::tempdir().unwrap();
    let mut o = ArrayCosimOptions::new(&dir.path().join("icarus"));
    (o.frame_pulses, o.rom_depth, o.frames, o.simulator) =
        (Some(16), Some(16), 2, ArraySimulator::Icarus);
    if have_tools(&["verilator"]) {
        let cfg = write(dir.path(), "sp.toml", &text);
        let out = dir.path().join("verilator");
        let v = tofprobe(&[
            "cosim",
            &cfg,
            "--frame-pulses",
            "16",
            "--rom-depth",
            "16",
            "--frames",
            "2",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        let j = crate::common::last_json(&v);
        assert_eq!(
            (j["pass"].as_bool(), j["mismatches"].as_u64()),
            (Some(true), Some(0)),
            "{j}"
        );
        assert_eq!(
            (j["rows"].as_u64(), j["cols"].as_u64()),
            (Some(2), Some(2)),
            "{j}"
        );
        let rtl = std::fs::read_to_string(out.join("rtl/tofprobe_array.v")).unwrap();
        // One averaging instance in the generate loop over the 2 × 2 pixels; the ports
        // are per SPAD: 2 × 2 pixels × 4 SPADs.
        assert_eq!(rtl.matches("tofprobe_superpixel u_superpixel (").count(), 1);
        assert!(
            rtl.contains("parameter integer SPADS = 4,"),
            "2 × 2 SPADs a pixel"
        );
        assert!(
            rtl.contains("input  wire [INPUTS - 1:0] valid,"),
            "SPAD inputs"
        );
    }
    if !have_tools(&["iverilog", "vvp"]) {
        return;
    }
    let good = cosim_array(&design, &o).unwrap();
    assert!(
        good.pass && good.mismatches == 0 && good.cycles > 100,
        "{:?}",
        good.first
    );
    // The model's first differing cycle with pixel (0, 0)'s and (0, 1)'s averages crossed.
    let ov = RtlOverrides {
        frame_pulses: Some(16),
        rom_depth: Some(16),
    };
    let chip = Chip::array_of(&design, &ov, RomPurpose::Replayed).unwrap();
    let ro = chip.readout.unwrap();
    let model = |f| {
        let m = ArrayModel::new(&ro, &chip.pixel, &chip.rom.words, f).unwrap();
        run(&mut m.with_superpixel(2, &chip.pixel).unwrap(), &det, 2).unwrap()
    };
    let (reference, faulty) = (
        model(None),
        model(Some(ArrayFault::NeighbourTdc { row: 0, col: 0 })),
    );
    let predicted = (1..reference.pins.len())
        .find(|&c| reference.pins[c] != faulty.pins[c])
        .expect("the crossed averages change the readout") as u64;
    o.out = dir.path().join("crossed");
    o.fault = Some(ArrayFault::NeighbourTdc { row: 0, col: 0 });
    let r = cosim_array(&design, &o).unwrap();
    assert!(!r.pass && r.mismatches > 0, "crossed averages not caught");
    assert_eq!(r.first_cycle, Some(predicted), "{:?}", r.first);
    // The mutation study's escapes, caught now that SPADs go missing: valid as the AND of
    // the SPADs, two SPADs' codes crossed, a wrong reciprocal entry.
    for fault in [
        ArrayFault::SuperpixelAnd,
        ArrayFault::SpadSwap,
        ArrayFault::ReciprocalEntry,
    ] {
        o.out = dir.path().join(fault.name());
        o.fault = Some(fault);
        let r = cosim_array(&design, &o).unwrap();
        assert!(!r.pass && r.mismatches > 0, "{fault:?} not caught");
    }
}

/// G = 3: 6 × 6 SPADs as 2 × 2 pixels; under Icarus bit-exact on the thinned stimulus (every
/// count of valid SPADs from none to nine, exactly one among them), and the three
/// superpixel escapes caught.
#[test]
fn a_three_by_three_superpixel_reaches_every_count_and_its_escapes_are_caught() {
    if !have_tools(&["iverilog", "vvp"]) {
        return;
    }
    let text = config(6, 6, false, "superpixel = 3\n");
    let design = resolve(
        Document::from_toml_str(&text, "sp3.toml").unwrap(),
        "sp3.toml",
    )
    .unwrap();
    let mut det = scene_detections(&design, 16, 2, None).unwrap();
    exercise(&mut det, 2, 3);
    assert_eq!(det.len(), 36);
    let one = (0..32).any(|n| {
        (0..9)
            .filter(|s| det[(s / 3) * 6 + s % 3][n].is_some())
            .count()
            == 1
    });
    assert!(one, "pixel (0, 0) never has exactly one valid SPAD");
    let dir = tempfile::tempdir().unwrap();
    let mut o = ArrayCosimOptions::new(&dir.path().join("good"));
    (o.frame_pulses, o.rom_depth, o.frames, o.simulator) =
        (Some(16), Some(16), 2, ArraySimulator::Icarus);
    let good = cosim_array(&design, &o).unwrap();
    assert!(good.pass && good.mismatches == 0, "{:?}", good.first);
    for fault in [
        ArrayFault::SuperpixelAnd,
        ArrayFault::SpadSwap,
        ArrayFault::ReciprocalEntry,
    ] {
        o.out = dir.path().join(fault.name());
        o.fault = Some(fault);
        let r = cosim_array(&design, &o).unwrap();
        assert!(!r.pass && r.mismatches > 0, "{fault:?} not caught");
    }
}

/// `[array] double_buffer = true` (docs/pixel-contract.md "Double buffer"): a 2 × 3 array
/// of shadow-register pixels, 3 frames of N = 8 (N·C + 1 = 33 > D = 31: each frame's
/// readout runs during the next frame's pulses, which are accepted), bit-exact under
/// Verilator against the array model at the array's ports; under Icarus also readout-bound
/// (N = 4: D = 31 > 17, the sequencer holds 14 cycles), and the shadow taken a cycle late
/// (`ArrayFault::SwapLate`) is caught at the cycle the faulty model predicts: frame 0's
/// first beat, pixel (0, 0) register 0. One Verilator build (≈ 17 s on two cores), three
/// Icarus runs (< 1 s each).
#[test]
fn a_double_buffered_array_is_bit_exact_and_a_late_shadow_is_caught() {
    let text = config(2, 3, false, "double_buffer = true\n");
    let design = resolve(
        Document::from_toml_str(&text, "db.toml").unwrap(),
        "db.toml",
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    if have_tools(&["verilator"]) {
        let cfg = write(dir.path(), "db.toml", &text);
        let out = dir.path().join("verilator");
        let v = tofprobe(&[
            "cosim",
            &cfg,
            "--frame-pulses",
            "8",
            "--rom-depth",
            "16",
            "--frames",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        let j = crate::common::last_json(&v);
        assert_eq!(
            (j["pass"].as_bool(), j["mismatches"].as_u64()),
            (Some(true), Some(0)),
            "{j}"
        );
        // Reset 2 + frames 0, 1 at 33 cycles + the last's N·C + D = 32 + 31 + tail 6.
        assert_eq!(j["cycles"].as_u64(), Some(2 + 2 * 33 + 32 + 31 + 6), "{j}");
        let pixel = std::fs::read_to_string(out.join("rtl/tofprobe_pixel.v")).unwrap();
        assert!(pixel.contains("input  wire swap,") && pixel.contains("sh_0 <= y[0];"));
    }
    if !have_tools(&["iverilog", "vvp"]) {
        return;
    }
    let mut o = ArrayCosimOptions::new(&dir.path().join("icarus"));
    (o.frame_pulses, o.rom_depth, o.frames, o.simulator) =
        (Some(4), Some(16), 3, ArraySimulator::Icarus);
    let good = cosim_array(&design, &o).unwrap();
    assert!(good.pass && good.mismatches == 0, "{:?}", good.first);
    // The late shadow: the model carrying it names the first cycle the RTL must differ at.
    o.frame_pulses = Some(8);
    let ov = RtlOverrides {
        frame_pulses: Some(8),
        rom_depth: Some(16),
    };
    let chip = Chip::array_of(&design, &ov, RomPurpose::Replayed).unwrap();
    let ro = chip.readout.unwrap();
    assert!(ro.double_buffer);
    let mut det = scene_detections(&design, 8, 3, None).unwrap();
    exercise(&mut det, 3, 1);
    let model = |f| {
        let mut m = ArrayModel::new(&ro, &chip.pixel, &chip.rom.words, f).unwrap();
        run(&mut m, &det, 3).unwrap()
    };
    let (reference, faulty) = (model(None), model(Some(ArrayFault::SwapLate)));
    let predicted = (1..reference.pins.len())
        .find(|&c| reference.pins[c] != faulty.pins[c])
        .expect("the late swap changes the readout") as u64;
    assert_eq!(predicted, reference.beat_cycle(0, 0, 0, 0));
    o.out = dir.path().join("late");
    o.fault = Some(ArrayFault::SwapLate);
    let r = cosim_array(&design, &o).unwrap();
    assert!(!r.pass && r.mismatches > 0, "the late shadow is not caught");
    assert_eq!(r.first_cycle, Some(predicted), "{:?}", r.first);
    let first = format!("{:?}", r.first);
    assert!(
        first.contains("pixel (0, 0)") && first.contains("register 0"),
        "{first}"
    );
}
