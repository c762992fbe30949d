//! The segmented fold (`SegmentedModel`, issue 28: one pixel's run cut into eight time
//! segments run in vector lanes, then repaired) against the transaction driver: over
//! random Fourier configurations from the testkit's generator (any zoom, S, F, G, rounding,
//! tight W so the registers wrap; sometimes a slow prefilter, S up to 15, whose chains may
//! never meet within a segment), random N (tiny ones included, shorter than eight
//! segments) and L, detections with gaps (late priming, dark stretches, sparse runs),
//! streamed over several frames in chunks drawn from a few lengths (so a frame's runs
//! share the rotation of the lanes' sums, and some do not fit it), with segments as short
//! as one pulse: every readout equals `TransactionModel::run`'s. The same property with
//! the stream shifted by one pulse fails; a repair stopped early is caught by the unit
//! test `segments::tests::a_repair_stopped_early_is_caught`.

use common::{Rng, random_detection, random_params, random_rom};
use proptest::prelude::*;
use proptest::test_runner::Config;
use tofprobe_dsp::RomImage;
use tofprobe_pixel::detections::compact;
use tofprobe_pixel::{
    FrameDriver, Mode, PixelParams, Readout, SegmentedModel, TransactionModel, segments_pay,
};
use tofprobe_testkit::mutants::some_seed_fails;

use crate::common;

#[derive(Debug, Clone)]
struct Case {
    params: PixelParams,
    rom: RomImage,
    codes: Vec<u32>,
    chunks: Vec<usize>,
    min_segment: usize,
}

fn case(seed: u64) -> Case {
    let mut rng = Rng(seed);
    let mut params = random_params(&mut rng);
    while params.mode != Mode::Fourier {
        params = random_params(&mut rng);
    }
    if rng.chance(15) {
        params.shift = 12 + rng.below(4) as u32;
    }
    params.frame_pulses = if rng.chance(20) {
        1 + rng.below(8)
    } else {
        1 + rng.below(3000)
    };
    let deepest = if rng.chance(50) { 40 } else { 700 };
    params.rom_depth = 1 + rng.below(deepest) as usize;
    params.validate().expect("N, L and S within the contract");
    let rom = random_rom(&mut rng, &params);
    let total = (1 + rng.below(3) as usize) * params.frame_pulses as usize;
    let lead = if rng.chance(30) {
        rng.below(total as u64 + 1) as usize
    } else {
        0
    };
    let sparse = rng.chance(25);
    let mut dark = 0usize;
    let codes = (0..total)
        .map(|i| {
            if dark == 0 && rng.chance(1) {
                dark = rng.below(300) as usize;
            }
            let gap = dark > 0;
            dark = dark.saturating_sub(1);
            if i < lead || gap || (sparse && rng.chance(80)) {
                compact(None)
            } else {
                compact(random_detection(&mut rng, &params))
            }
        })
        .collect();
    let lengths: Vec<usize> = (0..3).map(|_| 1 + rng.below(3000) as usize).collect();
    let chunks = (0..8).map(|_| *rng.pick(&lengths)).collect();
    Case {
        params,
        rom,
        codes,
        chunks,
        min_segment: 1 + rng.below(64) as usize,
    }
}

/// The (start, length, frame ends) runs of a case: frames of N cut into the chunk lengths.
fn runs(c: &Case) -> Vec<(usize, usize, bool)> {
    let n = c.params.frame_pulses as usize;
    let mut out = Vec::new();
    let mut k = 0;
    for frame in 0..c.codes.len() / n {
        let (start, end) = (frame * n, (frame + 1) * n);
        let mut at = start;
        while at < end {
            let len = c.chunks[k % c.chunks.len()].min(end - at);
            k += 1;
            out.push((at, len, at + len == end));
            at += len;
        }
    }
    out
}

/// The readouts through the transaction driver, and through the segmented fold of the
/// stream shifted by `shift` pulses (0: correct), with the pulses its repairs stepped.
fn readouts(c: &Case, shift: usize) -> (Vec<Readout>, Vec<Readout>, u64) {
    let mut tm = TransactionModel::new(&c.params).unwrap();
    let mut sm = SegmentedModel::with_min_segment(&c.params, &c.rom, c.min_segment).unwrap();
    let shifted: Vec<u32> = c.codes[shift.min(c.codes.len())..]
        .iter()
        .chain(&c.codes[..shift.min(c.codes.len())])
        .copied()
        .collect();
    let n = c.params.frame_pulses as usize;
    let (mut want, mut got) = (Vec::new(), Vec::new());
    for (at, len, ends) in runs(c) {
        let addr = (at % n) as u64;
        tm.run(&c.codes[at..at + len], Some(&c.rom), addr).unwrap();
        sm.run(&shifted[at..at + len], addr);
        assert_eq!(sm.pulses_in_frame(), tm.pulses_in_frame());
        if ends {
            assert_eq!(
                sm.registers(),
                tm.registers().to_vec(),
                "registers before the readout"
            );
            want.push(tm.readout());
            got.push(sm.readout());
        }
    }
    (want, got, sm.repaired_pulses())
}

fn segments_agree(seed: u64, shift: usize) -> Result<(), TestCaseError> {
    let c = case(seed);
    let (want, got, _) = readouts(&c, shift);
    for (f, (w, g)) in want.iter().zip(&got).enumerate() {
        let first = w.words.iter().zip(&g.words).position(|(a, b)| a != b);
        prop_assert_eq!(w, g, "frame {}, first differing register {:?}", f, first);
    }
    Ok(())
}

proptest! {
    #![proptest_config(Config { cases: 300, ..Config::default() })]

    /// The segmented fold reads out what the transaction driver reads.
    #[test]
    fn segments_equal_the_transaction_driver(seed in any::<u64>()) {
        segments_agree(seed, 0)?;
    }
}

/// The property sees the pulses: a stream shifted by one pulse fails it.
#[test]
fn a_shifted_stream_fails_the_property() {
    assert!(
        some_seed_fails(300, |seed| segments_agree(seed, 1)),
        "shifted streams passed 300 cases"
    );
}

/// The cases reach every path: segmented runs whose repairs met early, and slow
/// prefilters whose repairs ran whole segments (more repaired pulses than a few hundred
/// per segment), all still equal.
#[test]
fn the_cases_reach_the_repairs() {
    let (mut met, mut whole) = (0, 0);
    for seed in 0..200 {
        let c = case(seed);
        let (want, got, repaired) = readouts(&c, 0);
        assert_eq!(want, got, "seed {seed}");
        if repaired > 0 && c.params.shift <= 6 {
            met += 1;
        }
        if repaired > 0 && c.params.shift >= 12 {
            whole += 1;
        }
    }
    assert!(
        met >= 50 && whole >= 5,
        "repaired: {met} fast, {whole} slow"
    );
}

/// `FrameDriver` runs the segmented fold for a long frame of a fast prefilter and the
/// plain fold otherwise, and reads out the transaction driver's registers; the default
/// pixel's frame is segmented.
#[test]
fn the_frame_driver_picks_the_segments() {
    assert!(segments_pay(&PixelParams::default()));
    let mut rng = Rng(11);
    for (n, shift, segmented) in [
        (100_000u64, 5, true),
        (100_000, 9, false),
        (20_000, 5, false),
    ] {
        let params = PixelParams {
            shift,
            ..PixelParams::fourier_default(30, n, 1000)
        };
        let rom = random_rom(&mut rng, &params);
        let mut d = FrameDriver::new(&params, Some(&rom)).unwrap();
        assert_eq!(
            (d.is_segmented(), d.is_folded()),
            (segmented, true),
            "N = {n}, S = {shift}"
        );
        let codes: Vec<u32> = (0..n)
            .map(|_| compact(random_detection(&mut rng, &params)))
            .collect();
        let mut tm = TransactionModel::new(&params).unwrap();
        for (i, chunk) in codes.chunks(1 << 14).enumerate() {
            d.run(chunk, (i << 14) as u64).unwrap();
            tm.run(chunk, Some(&rom), (i << 14) as u64).unwrap();
        }
        assert_eq!(d.readout(), tm.readout(), "N = {n}, S = {shift}");
    }
}
