//! The lane driver (`FoldLanes`, issue 28's array speed) against the transaction driver:
//! over random Fourier configurations (as tests/it/fold.rs: any zoom, S, F, G, rounding,
//! tight W so the registers wrap; random N and L below and above the fold's minimum
//! segment), 1 ..= 8 pixels each with its own detections (some primed late, some dark for
//! whole chunks or frames, some sparse), streamed in random chunks over several frames in
//! the compact form, every pixel's readouts equal `TransactionModel::run`'s on its stream
//! alone. The same property with the pixels' streams rotated fails.

use common::{Rng, random_detection, random_params, random_rom};
use proptest::prelude::*;
use proptest::test_runner::Config;
use tofprobe_dsp::RomImage;
use tofprobe_pixel::detections::compact;
use tofprobe_pixel::{FoldLanes, LANES, Mode, PixelParams, Readout, TransactionModel};
use tofprobe_testkit::mutants::some_seed_fails;

use crate::common;

/// A random case: parameters, ROM, the pixels' streams (compact codes) and chunk lengths.
#[derive(Debug, Clone)]
struct Case {
    params: PixelParams,
    rom: RomImage,
    streams: Vec<Vec<u32>>,
    chunks: Vec<usize>,
}

fn case(seed: u64) -> Case {
    let mut rng = Rng(seed);
    let mut params = random_params(&mut rng);
    while params.mode != Mode::Fourier {
        params = random_params(&mut rng);
    }
    params.frame_pulses = 1 + rng.below(2000);
    let deepest = if rng.chance(50) { 40 } else { 700 };
    params.rom_depth = 1 + rng.below(deepest) as usize;
    params.validate().expect("N and L within the contract");
    let rom = random_rom(&mut rng, &params);
    let frames = 1 + rng.below(3) as usize;
    let total = frames * params.frame_pulses as usize;
    let lanes = 1 + rng.below(LANES as u64) as usize;
    let streams = (0..lanes)
        .map(|_| {
            let lead = if rng.chance(40) {
                rng.below(total as u64 + 1)
            } else {
                0
            } as usize;
            let dark = rng.chance(10);
            let sparse = rng.chance(25);
            (0..total)
                .map(|i| {
                    if dark || i < lead || (sparse && rng.chance(80)) {
                        compact(None)
                    } else {
                        compact(random_detection(&mut rng, &params))
                    }
                })
                .collect()
        })
        .collect();
    let chunks = (0..8).map(|_| 1 + rng.below(700) as usize).collect();
    Case {
        params,
        rom,
        streams,
        chunks,
    }
}

/// The (start, length, frame ends) runs of a case: frames of N cut into the chunk lengths.
fn runs(c: &Case) -> Vec<(usize, usize, bool)> {
    let n = c.params.frame_pulses as usize;
    let total = c.streams[0].len();
    let mut out = Vec::new();
    let mut k = 0;
    for frame in 0..total / n {
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

/// Pixel j's readouts through the transaction driver alone.
fn transaction_readouts(c: &Case, j: usize) -> Vec<Readout> {
    let mut tm = TransactionModel::new(&c.params).unwrap();
    let n = c.params.frame_pulses as usize;
    let mut out = Vec::new();
    for (at, len, ends) in runs(c) {
        tm.run(&c.streams[j][at..at + len], Some(&c.rom), (at % n) as u64)
            .unwrap();
        if ends {
            out.push(tm.readout());
        }
    }
    out
}

/// Every pixel's readouts through the lane driver; `rotate` hands pixel j the stream of
/// pixel j + rotate (0: correct).
fn lane_readouts(c: &Case, rotate: usize) -> Vec<Vec<Readout>> {
    let lanes = c.streams.len();
    let mut fl = FoldLanes::new(&c.params, &c.rom, lanes).unwrap();
    let n = c.params.frame_pulses as usize;
    let mut out = vec![Vec::new(); lanes];
    for (at, len, ends) in runs(c) {
        let chunk: Vec<&[u32]> = (0..lanes)
            .map(|j| &c.streams[(j + rotate) % lanes][at..at + len])
            .collect();
        fl.run(&chunk, (at % n) as u64).unwrap();
        if ends {
            for (o, r) in out.iter_mut().zip(fl.readout()) {
                o.push(r);
            }
        }
    }
    out
}

fn lanes_agree(seed: u64, rotate: usize) -> Result<(), TestCaseError> {
    let c = case(seed);
    let lanes = lane_readouts(&c, rotate);
    for (j, got) in lanes.iter().enumerate() {
        prop_assert_eq!(got, &transaction_readouts(&c, j), "pixel {}", j);
    }
    Ok(())
}

proptest! {
    #![proptest_config(Config { cases: 200, ..Config::default() })]

    /// Each pixel of the lane driver reads out what the transaction driver reads alone.
    #[test]
    fn lanes_equal_the_transaction_driver(seed in any::<u64>()) {
        lanes_agree(seed, 0)?;
    }
}

/// Rotating the pixels' streams must fail the property (it sees which pixel is which).
#[test]
fn rotated_lanes_fail_the_property() {
    assert!(
        some_seed_fails(200, |seed| lanes_agree(seed, 1)),
        "rotated streams passed 200 cases"
    );
}

/// The lane driver refuses what it cannot run: a wrong number of streams, streams of
/// different lengths, no pixels or more than LANES.
#[test]
fn the_lane_driver_refuses_misfit_streams() {
    let params = PixelParams::default();
    let rom = RomImage::zeros(params.rom_depth, params.registers());
    let mut fl = FoldLanes::new(&params, &rom, 2).unwrap();
    let (a, b) = (vec![1u32; 10], vec![1u32; 9]);
    let e = fl.run(&[&a[..]], 0).unwrap_err().to_string();
    assert!(e.contains("streams") && e.contains('2'), "{e}");
    let e = fl.run(&[&a[..], &b[..]], 0).unwrap_err().to_string();
    assert!(e.contains("9") && e.contains("10 pulses"), "{e}");
    for lanes in [0, LANES + 1] {
        let e = FoldLanes::new(&params, &rom, lanes)
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("1 ..= {LANES}")), "{e}");
    }
}

/// Every ISA path of the lanes this CPU runs (`tofprobe_io::isa`: AVX2, AVX-512) reads out
/// the scalar path's registers, for the lane driver over random cases and for the
/// segmented fold (whose segments run in the lanes) on a long frame; a path the CPU
/// lacks is skipped with a note. Each case is also held to the transaction driver above,
/// so a path that agreed with a wrong scalar path would fail there.
#[test]
fn every_isa_reads_out_the_scalar_registers() {
    use tofprobe_io::isa::{Isa, with_isa};
    use tofprobe_pixel::SegmentedModel;
    let cases: Vec<Case> = (0..40).map(|s| case(0x15A_0000 + s)).collect();
    let lanes = |isa| {
        with_isa(isa, || {
            cases
                .iter()
                .map(|c| lane_readouts(c, 0))
                .collect::<Vec<_>>()
        })
    };
    let params = tofprobe_pixel::PixelParams::fourier_default(30, 400_000, 1000);
    assert!(tofprobe_pixel::segments_pay(&params));
    let rom = tofprobe_pixel::speed::synthetic_rom(params.rom_depth, params.registers());
    let codes = tofprobe_pixel::speed::synthetic_codes(params.frame_pulses as usize, 80);
    let segmented = |isa| {
        with_isa(isa, || {
            let mut m = SegmentedModel::new(&params, &rom).unwrap();
            m.run(codes.as_slice(), 0);
            (m.repaired_pulses(), m.readout())
        })
    };
    let (scalar, scalar_seg) = (lanes(Isa::Scalar), segmented(Isa::Scalar));
    assert!(scalar_seg.1.words.iter().any(|&w| w != 0));
    for isa in Isa::vector_paths_to_test() {
        assert_eq!(lanes(isa), scalar, "lane driver on {}", isa.name());
        assert_eq!(
            segmented(isa),
            scalar_seg,
            "segmented fold on {}",
            isa.name()
        );
    }
}
