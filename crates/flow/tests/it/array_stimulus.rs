//! Stimulus that reaches every feature of the array (issue 42, point 4), on the committed
//! 2 × 2 example (testbench/array-2x2/array-2x2.toml, N = 16): a reset in the middle of the
//! first frame restarts model and RTL (the frame after it is the frame a fresh array makes
//! of the same detections) and catches the pixel's reset escapes under Verilator's seeds
//! 1, 2, 3 and Icarus's X; registers narrower than the sizing (the test option
//! `ArrayCosimOptions::width`, on frames of half the ROM's period) overflow and wrap, their words reach the sign bit and the top
//! bit of W, and an accumulate that holds instead of wrapping is caught.
//!
//! Cold cost: three Verilator builds of the 2 × 2 array (clean, two mutants) and eleven
//! Icarus runs; the four tests took 43 s with an empty `TOFPROBE_CACHE` on the shared
//! two-core machine at a load of ≈ 7 (2 s with the builds cached).

use std::path::PathBuf;

use tofprobe_array::rtl_driver::{ArrayRun, mid_frame_reset, run, run_with_reset};
use tofprobe_array::rtl_model::ArrayModel;
use tofprobe_design::{Chip, Document, ResolvedDesign, RomPurpose, RtlOverrides, resolve};
use tofprobe_flow::array::{ArrayCosimOptions, ArrayCosimReport, ArraySimulator, cosim_array};
use tofprobe_pixel::Fault;
use tofprobe_rtlgen::ArrayFault;

fn example_text() -> String {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../testbench/array-2x2/array-2x2.toml");
    std::fs::read_to_string(&path).unwrap()
}

fn resolved(text: &str, name: &str) -> ResolvedDesign {
    resolve(Document::from_toml_str(text, name).unwrap(), name).unwrap()
}

fn example() -> ResolvedDesign {
    resolved(&example_text(), "array-2x2.toml")
}

/// The example as a Haar array (U = 2: 7 registers over one adder, 16,384 pulses) on a
/// 4-bit port.
fn haar_example() -> ResolvedDesign {
    let mut text = example_text();
    for (from, to) in [
        ("pulses = 20000 ", "pulses = 16384 "),
        ("mode = \"fourier\" ", "mode = \"haar\"\nhaar_scales = 2 "),
        ("adders = 2 ", "adders = 1 "),
        ("shift = 5 ", "# "),
        ("frac_bits = 8 ", "# "),
        // Narrow registers need a narrower port: W = T + 1 = 8 bits in two beats.
        ("readout_bits = 16 ", "readout_bits = 4 "),
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    resolved(&text, "haar-2x2.toml")
}

/// One frame of N = 16 (L = 16), Verilator under `seeds` or Icarus (`seeds` empty).
fn cosim(
    d: &ResolvedDesign,
    out: PathBuf,
    fault: Option<Fault>,
    seeds: &[u64],
) -> ArrayCosimReport {
    let mut o = ArrayCosimOptions::new(&out);
    (o.frame_pulses, o.rom_depth, o.frames) = (Some(16), Some(16), 1);
    o.fault = fault.map(ArrayFault::Pixel);
    match seeds {
        [] => o.simulator = ArraySimulator::Icarus,
        s => o.x_seeds = s.to_vec(),
    }
    o.mid_frame_reset = true;
    cosim_array(d, &o).unwrap()
}

/// The model restarts: the frame after the reset is, word for word, the frame a fresh
/// array makes of the detections that follow the pulses sampled before the reset.
fn assert_the_frame_restarts(d: &ResolvedDesign, r: &ArrayRun) {
    let reset = r.reset_at.expect("a mid-frame reset");
    let before = r.pulse_cycles.iter().filter(|&&c| c < reset).count();
    assert!(before > 0, "no pulse before the reset at cycle {reset}");
    let ov = RtlOverrides {
        frame_pulses: Some(16),
        rom_depth: Some(16),
    };
    let chip = Chip::array_of(d, &ov, RomPurpose::Replayed).unwrap();
    let ro = chip.readout.unwrap();
    let mut det = tofprobe_flow::array::vectors::scene_detections(d, 16, 2, None).unwrap();
    tofprobe_rtlgen::array_vectors::exercise(&mut det, ro.cols, 1);
    let model = || ArrayModel::new(&ro, &chip.pixel, &chip.rom.words, None).unwrap();
    let with = run_with_reset(&mut model(), &det, 1, Some(mid_frame_reset(&ro))).unwrap();
    assert_eq!(with.words, r.words, "the co-simulation's model is this one");
    let after: Vec<Vec<Option<u32>>> = det.iter().map(|p| p[before..].to_vec()).collect();
    let fresh = run(&mut model(), &after, 1).unwrap();
    assert_eq!(
        with.words, fresh.words,
        "the frame after the reset is a fresh one"
    );
}

#[test]
fn a_mid_frame_reset_restarts_the_array_and_catches_the_reset_escapes() {
    if !tofprobe_testkit::tools::have(&["verilator", "iverilog", "vvp"], "flow::array_stimulus") {
        return;
    }
    let d = example();
    let dir = tempfile::tempdir().unwrap();
    let clean = cosim(&d, dir.path().join("clean"), None, &[1, 2, 3]);
    assert!(clean.pass, "clean, seeds 1-3: {:?}", clean.first);
    assert_the_frame_restarts(&d, &clean.run);
    let reset = clean.run.reset_at.unwrap();
    let x = cosim(&d, dir.path().join("clean-x"), None, &[]);
    assert!(x.pass, "clean, Icarus: {:?}", x.first);
    for fault in [Fault::ResetWhenIdle, Fault::ResetPrimed] {
        for seeds in [&[1u64][..], &[2], &[3], &[]] {
            let out = dir.path().join(format!("{}-{seeds:?}", fault.name()));
            let r = cosim(&d, out, Some(fault), seeds);
            let first = r.first.clone().unwrap_or_default();
            assert!(
                !r.pass,
                "{fault:?} under {seeds:?} (empty: Icarus) not caught"
            );
            let c = r.first_cycle.unwrap();
            // The register file cleared only when idle passes power-up's reset.
            assert!(
                fault != Fault::ResetWhenIdle || c > reset,
                "{fault:?}: {first}"
            );
            eprintln!("{fault:?} {seeds:?}: reset at cycle {reset}, caught: {first}");
        }
    }
}

/// The Haar array's words (sums of the held codes, W sized for its frame) reach the top
/// bits only past the sizing: at W = T + 1 the scaling register wraps within a frame of
/// 16 pulses (4 frames, 4 pixels: its jittered sums land on both sides), and an
/// accumulate that holds instead is caught (Icarus).
#[test]
fn haar_words_wrap_at_a_narrow_width_and_catch_hold_on_overflow() {
    if !tofprobe_testkit::tools::have(&["iverilog", "vvp"], "flow::array_stimulus") {
        return;
    }
    let d = haar_example();
    let dir = tempfile::tempdir().unwrap();
    let w = d.pixel.operand_bits();
    let frame = |name: &str, fault: Option<Fault>| {
        let mut o = ArrayCosimOptions::new(&dir.path().join(name));
        (o.frame_pulses, o.frames, o.width) = (Some(16), 4, Some(w));
        (o.fault, o.simulator) = (fault.map(ArrayFault::Pixel), ArraySimulator::Icarus);
        o.mid_frame_reset = true;
        cosim_array(&d, &o).unwrap()
    };
    let clean = frame("clean", None);
    assert!(clean.pass, "Haar, W = {w}: {:?}", clean.first);
    let (neg, pos) = top_bits(&clean);
    eprintln!(
        "Haar W = {w} (sized {}): {neg} words ≤ −2^(W−2), {pos} ≥ 2^(W−2)",
        d.pixel.width
    );
    assert!(
        neg > 0 && pos > 0,
        "Haar, W = {w}: the words miss the top bits"
    );
    let r = frame("hold", Some(Fault::HoldOnOverflow));
    assert!(!r.pass, "Haar hold_on_overflow not caught at W = {w}");
    eprintln!(
        "Haar HoldOnOverflow: caught: {}",
        r.first.unwrap_or_default()
    );
}

/// Register words with the sign bit set and the next clear (≤ −2^(W−2)), and the other way.
fn top_bits(r: &ArrayCosimReport) -> (usize, usize) {
    let (w, regs) = (r.pixel.width, r.pixel.registers());
    let words = r.run.words.iter().flatten().flat_map(|p| &p[..regs]);
    let neg = words.clone().filter(|&&v| v >> (w - 2) == 2).count();
    let pos = words.filter(|&&v| v >> (w - 2) == 1).count();
    (neg, pos)
}

#[test]
fn narrow_registers_wrap_reach_their_top_bits_and_catch_hold_on_overflow() {
    if !tofprobe_testkit::tools::have(&["verilator", "iverilog", "vvp"], "flow::array_stimulus") {
        return;
    }
    let d = example();
    let dir = tempfile::tempdir().unwrap();
    let w = d.pixel.operand_bits();
    // W as wide as the operand, on half of the ROM's period (N = 8 of L = 16): the sign
    // probes do not cancel, so the words grow to several operands, past 2^(W−1).
    let frame = |name: &str, width, fault: Option<Fault>, seeds: &[u64]| {
        let mut o = ArrayCosimOptions::new(&dir.path().join(name));
        (o.frame_pulses, o.rom_depth, o.frames, o.width) = (Some(8), Some(16), 1, width);
        o.fault = fault.map(ArrayFault::Pixel);
        match seeds {
            [] => o.simulator = ArraySimulator::Icarus,
            s => o.x_seeds = s.to_vec(),
        }
        o.mid_frame_reset = true;
        cosim_array(&d, &o).unwrap()
    };
    let sized = frame("sized", None, None, &[]);
    assert!(sized.pass, "{:?}", sized.first);
    let narrow = |name: &str, fault, seeds: &[u64]| frame(name, Some(w), fault, seeds);
    let clean = narrow("narrow", None, &[1]);
    assert!(clean.pass, "W = {w}: {:?}", clean.first);
    let (neg, pos) = top_bits(&clean);
    assert!(
        neg > 0 && pos > 0,
        "W = {w}: {neg} words ≤ −2^(W−2), {pos} ≥ 2^(W−2)"
    );
    // The same frame at the sized W, taken mod 2^w: the narrow words; some left w bits.
    let mask = (1u64 << w) - 1;
    let sign = |v: u64, bits: u32| tofprobe_pixel::fixed::sign_extend(v, bits);
    let mut wrapped = 0;
    for (wide, thin) in sized
        .run
        .words
        .iter()
        .flatten()
        .zip(clean.run.words.iter().flatten())
    {
        for (&a, &b) in wide.iter().zip(thin).take(clean.pixel.registers()) {
            assert_eq!(a & mask, b, "the narrow word is the sized one mod 2^{w}");
            wrapped += usize::from(sign(a, d.pixel.width) != sign(b, w));
        }
    }
    eprintln!(
        "W = {w} (sized {}): {neg} words ≤ −2^(W−2), {pos} ≥ 2^(W−2), {wrapped} wrapped",
        d.pixel.width
    );
    assert!(wrapped > 0, "no word overflowed W = {w}");
    let x = narrow("narrow-x", None, &[]);
    assert!(x.pass, "W = {w}, Icarus: {:?}", x.first);
    let r = narrow("hold", Some(Fault::HoldOnOverflow), &[]);
    assert!(!r.pass, "hold_on_overflow not caught at W = {w}");
    eprintln!("HoldOnOverflow: caught: {}", r.first.unwrap_or_default());
}

/// The test options are refused out of range, naming the option.
#[test]
fn a_width_beyond_the_design_or_below_the_operand_is_refused() {
    let d = example();
    let dir = tempfile::tempdir().unwrap();
    for w in [d.pixel.width + 1, d.pixel.operand_bits() - 1] {
        let mut o = ArrayCosimOptions::new(&dir.path().join("w"));
        (o.frame_pulses, o.rom_depth, o.width) = (Some(16), Some(16), Some(w));
        let e = cosim_array(&d, &o).unwrap_err().to_string();
        assert!(e.contains("--width") && e.contains(&w.to_string()), "{e}");
    }
}
