//! The folded driver (issue 28 point 1) against the transaction driver: over random Fourier
//! configurations (testkit parameters: any zoom, S, F, G, rounding, tight W so the registers
//! wrap), random frame lengths N and ROM depths L (below and above the fold's minimum
//! segment), random ROM bits and random detections (misses, codes wider than the T pins),
//! streamed in random chunks over several frames, the fold's readouts, held depth and
//! prefilter state equal `TransactionModel::run`'s and the pulse-by-pulse reference's, on
//! the `Option` stream and on its compact form (`u32` codes). A fold whose phases are off
//! by one fails the same property.

use crate::common;

use common::{Rng, random_detection, random_params, random_rom};
use proptest::prelude::*;
use proptest::test_runner::Config;
use tofprobe_dsp::RomImage;
use tofprobe_pixel::detections::compact;
use tofprobe_pixel::driver::run_frames;
use tofprobe_pixel::fold::{MAX_FOLD_DEPTH, MIN_SEGMENT};
use tofprobe_pixel::{
    FoldModel, FrameDriver, Mode, PixelError, PixelParams, Readout, TransactionModel, fold_pays,
};
use tofprobe_testkit::mutants::some_seed_fails;

/// A random Fourier case: parameters, ROM and a few frames of detections.
#[derive(Debug, Clone)]
struct Case {
    params: PixelParams,
    rom: RomImage,
    detections: Vec<Option<u32>>,
    /// Chunk lengths the stream is cut into (the last one runs to the end).
    chunks: Vec<usize>,
}

fn case(seed: u64) -> Case {
    let mut rng = Rng(seed);
    let mut params = random_params(&mut rng);
    while params.mode != Mode::Fourier {
        params = random_params(&mut rng);
    }
    // Frames from a handful of pulses to several ROM periods; depths below and above the
    // fold's minimum segment (a short ROM is folded over a multiple of its depth).
    params.frame_pulses = 1 + rng.below(3000);
    let deepest = if rng.chance(50) { 40 } else { 700 };
    params.rom_depth = 1 + rng.below(deepest) as usize;
    params.validate().expect("N and L within the contract");
    let rom = random_rom(&mut rng, &params);
    let frames = 1 + rng.below(3) as usize;
    let total = frames * params.frame_pulses as usize + rng.below(50) as usize;
    // Sometimes a long run without detections first (the priming rule), sometimes a scene
    // that mostly misses.
    let lead = if rng.chance(30) { rng.below(100) } else { 0 } as usize;
    let sparse = rng.chance(25);
    let detections = (0..total)
        .map(|i| {
            if i < lead || (sparse && rng.chance(80)) {
                None
            } else {
                random_detection(&mut rng, &params)
            }
        })
        .collect();
    let chunks = (0..8).map(|_| 1 + rng.below(700) as usize).collect();
    Case {
        params,
        rom,
        detections,
        chunks,
    }
}

/// The frames of a case as (first pulse, chunk) runs, a readout after each whole frame: a
/// frame's pulses are streamed in the case's chunk lengths, each chunk starting at ROM
/// address (pulse index within the frame) mod L.
fn runs(c: &Case) -> Vec<(usize, usize, bool)> {
    let n = c.params.frame_pulses as usize;
    let mut out = Vec::new();
    let mut k = 0;
    for frame in 0..c.detections.len().div_ceil(n) {
        let (start, end) = (frame * n, ((frame + 1) * n).min(c.detections.len()));
        let mut at = start;
        while at < end {
            let len = c.chunks[k % c.chunks.len()].min(end - at);
            k += 1;
            out.push((at, len, at + len == end && end - start == n));
            at += len;
        }
    }
    out
}

/// Everything a driver exposes after a chunk: (readout if one was taken, held, x, primed).
type Trace = Vec<(Option<Readout>, i64, i64, bool)>;

fn transaction_trace(c: &Case) -> Trace {
    let mut tm = TransactionModel::new(&c.params).unwrap();
    let n = c.params.frame_pulses as usize;
    runs(c)
        .into_iter()
        .map(|(at, len, ends)| {
            tm.run(&c.detections[at..at + len], Some(&c.rom), (at % n) as u64)
                .unwrap();
            let r = ends.then(|| tm.readout());
            (r, tm.held(), tm.prefilter_state(), tm.primed())
        })
        .collect()
}

/// The pulse-by-pulse reference (`TransactionModel::pulse`, ROM entry n mod L).
fn pulse_trace(c: &Case) -> Trace {
    let mut tm = TransactionModel::new(&c.params).unwrap();
    let (n, l) = (c.params.frame_pulses as usize, c.params.rom_depth);
    runs(c)
        .into_iter()
        .map(|(at, len, ends)| {
            for i in at..at + len {
                tm.pulse(c.detections[i], c.rom.entry((i % n) % l));
            }
            let r = ends.then(|| tm.readout());
            (r, tm.held(), tm.prefilter_state(), tm.primed())
        })
        .collect()
}

/// The fold's trace; `phase_error` shifts every chunk's first ROM address (0: correct).
fn fold_trace(c: &Case, phase_error: u64) -> Trace {
    let mut fm = FoldModel::new(&c.params, &c.rom).unwrap();
    let n = c.params.frame_pulses as usize;
    runs(c)
        .into_iter()
        .map(|(at, len, ends)| {
            fm.run(&c.detections[at..at + len], (at % n) as u64 + phase_error);
            let r = ends.then(|| fm.readout());
            (r, fm.held(), fm.prefilter_state(), fm.primed())
        })
        .collect()
}

/// The fold's trace on the compact form of the same pulses (`u32` codes, NO_DETECTION).
fn fold_trace_codes(c: &Case) -> Trace {
    let codes: Vec<u32> = c.detections.iter().map(|&d| compact(d)).collect();
    let mut fm = FoldModel::new(&c.params, &c.rom).unwrap();
    let n = c.params.frame_pulses as usize;
    runs(c)
        .into_iter()
        .map(|(at, len, ends)| {
            fm.run(&codes[at..at + len], (at % n) as u64);
            let r = ends.then(|| fm.readout());
            (r, fm.held(), fm.prefilter_state(), fm.primed())
        })
        .collect()
}

fn fold_agrees(seed: u64, phase_error: u64) -> Result<(), TestCaseError> {
    let c = case(seed);
    let reference = transaction_trace(&c);
    prop_assert_eq!(&reference, &pulse_trace(&c), "run() against pulse()");
    prop_assert_eq!(
        &fold_trace(&c, phase_error),
        &reference,
        "fold against run()"
    );
    if phase_error == 0 {
        prop_assert_eq!(&fold_trace_codes(&c), &reference, "fold on codes");
    }
    Ok(())
}

proptest! {
    #![proptest_config(Config { cases: 300, ..Config::default() })]

    /// The fold's readouts and front-end state equal the transaction driver's.
    #[test]
    fn fold_equals_the_transaction_driver(seed in any::<u64>()) {
        fold_agrees(seed, 0)?;
    }
}

/// The same property with every chunk's phases off by one must fail (the property sees
/// which ROM entry each pulse's operand meets, not only the operands' sum).
#[test]
fn an_off_by_one_fold_fails_the_property() {
    assert!(
        some_seed_fails(300, |seed| fold_agrees(seed, 1)),
        "the off-by-one fold passed 300 cases"
    );
}

/// Registers wrap: at the narrowest W a long frame's sums exceed 2^W (the same frame at
/// W = 62 reads differently, modulo 2^W the same), and the fold still matches exactly.
#[test]
fn wrapping_registers_fold_exactly() {
    let mut params = PixelParams::fourier_default(1, 20_000, 37);
    params.width = params.operand_bits();
    params.validate().unwrap();
    let mut rng = Rng(11);
    let rom = random_rom(&mut rng, &params);
    let detections: Vec<Option<u32>> = (0..20_000)
        .map(|_| random_detection(&mut rng, &params))
        .collect();
    let narrow = run_frames(&params, &detections, Some(&rom)).unwrap();
    let mut tm = TransactionModel::new(&params).unwrap();
    assert_eq!(narrow, tm.run_frames(&detections, Some(&rom)).unwrap());
    let mut wide_params = params.clone();
    wide_params.width = 62;
    let wide = run_frames(&wide_params, &detections, Some(&rom)).unwrap();
    let w = params.width;
    let wrapped: Vec<i64> = wide[0]
        .words
        .iter()
        .map(|&y| (y << (64 - w)) >> (64 - w))
        .collect();
    assert_eq!(
        narrow[0].words, wrapped,
        "W-bit words are the wide sums mod 2^W"
    );
    assert_ne!(
        narrow[0].words, wide[0].words,
        "the frame must wrap at W = {w}"
    );
}

/// `fold_pays` by its closed form: N + L_v·⌈R/8⌉ < N·⌈R/8⌉ (L_v the smallest multiple of L
/// ≥ 256), Fourier only, L ≤ 2^20.
#[test]
fn the_fold_is_chosen_when_it_does_fewer_adds() {
    let default = PixelParams::default();
    assert!(fold_pays(&default), "B = 16, L = 20000, N = 10^7");
    // B = 16: 4 table bytes. N + 4·20000 < 4·N ⇔ N > 26,666.67.
    let at = |n: u64| PixelParams {
        frame_pulses: n,
        ..PixelParams::default()
    };
    assert!(!fold_pays(&at(26_666)));
    assert!(fold_pays(&at(26_667)));
    // L = 3 folds over L_v = 258: N + 4·258 < 4·N ⇔ N > 344.
    let short = |n: u64| PixelParams {
        frame_pulses: n,
        rom_depth: 3,
        ..PixelParams::default()
    };
    assert!(!fold_pays(&short(344)));
    assert!(fold_pays(&short(345)));
    // One table byte (B ≤ 4): the fold never does fewer adds.
    let narrow = PixelParams {
        bins: 4,
        ..PixelParams::default()
    };
    assert!(!fold_pays(&narrow));
    let haar = PixelParams {
        mode: Mode::Haar,
        haar_scales: 3,
        frame_pulses: 1 << 20,
        ..PixelParams::default()
    };
    assert!(!fold_pays(&haar));
    let deep = PixelParams {
        rom_depth: MAX_FOLD_DEPTH + 1,
        frame_pulses: 1 << 40,
        ..PixelParams::default()
    };
    assert!(!fold_pays(&deep));
    assert_eq!(MIN_SEGMENT, 256);
}

/// `FrameDriver` runs the fold exactly when it pays, and its readouts are the transaction
/// driver's either way.
#[test]
fn the_frame_driver_dispatches() {
    let mut rng = Rng(5);
    for (n, expect_fold) in [(100_000u64, true), (1_200, false)] {
        let params = PixelParams::fourier_default(30, n, 1000);
        let rom = random_rom(&mut rng, &params);
        let d = FrameDriver::new(&params, Some(&rom)).unwrap();
        assert_eq!(d.is_folded(), expect_fold, "N = {n}");
        let detections: Vec<Option<u32>> = (0..2 * n)
            .map(|_| random_detection(&mut rng, &params))
            .collect();
        let mut tm = TransactionModel::new(&params).unwrap();
        assert_eq!(
            run_frames(&params, &detections, Some(&rom)).unwrap(),
            tm.run_frames(&detections, Some(&rom)).unwrap()
        );
    }
}

/// The fold refuses what it cannot run, naming the field, the value and what would work.
#[test]
fn the_fold_refuses_haar_and_misfit_roms() {
    let haar = PixelParams {
        mode: Mode::Haar,
        haar_scales: 2,
        frame_pulses: 8,
        ..PixelParams::default()
    };
    let rom = RomImage::zeros(20_000, 32);
    let e = FoldModel::new(&haar, &rom).unwrap_err();
    assert!(matches!(e, PixelError::Mismatch { .. }));
    assert!(e.to_string().contains("haar") && e.to_string().contains("fourier"));
    let short = RomImage::zeros(19_999, 32);
    let e = FoldModel::new(&PixelParams::default(), &short).unwrap_err();
    assert!(e.to_string().contains("19999") && e.to_string().contains("L = 20000"));
    // The Haar pixel still runs through the frame driver (the transaction driver).
    let d = FrameDriver::new(&haar, None).unwrap();
    assert!(!d.is_folded());
}
