//! `[array] superpixel = G`: 4 × 4 SPADs as 2 × 2 superpixels of G = 2. Each pixel's
//! registers are the single-pixel transaction model driven pulse by pulse on its four
//! SPADs' records averaged by the naive rule (an integer division, not the front end's
//! reciprocal table); the lane driver and the one-pixel driver agree; SPAD (r, c) draws the
//! same photons whatever G; bad keys are refused naming them.

use tofprobe_array::model::{run_array, run_group, run_pixel};
use tofprobe_design::{Document, ProbeCache, ResolvedDesign, resolve_with};
use tofprobe_pixel::transaction::TransactionModel;

use crate::common::{design, plate, text};

const SPADS: &str = "rows = 4\ncols = 4\npitch_um = 15.0\nmm_per_pixel = 20.0\nsuperpixel = 2\n\
                     signal_map = { kind = \"gradient\", from = 0.2, to = 0.9 }\n\
                     background_map = { kind = \"constant\", value = 0.05 }";

/// The naive reference of superpixel (r, c): each pulse, the mean of the valid SPADs'
/// T-bit codes rounded half up by integer division, then the transaction model.
fn reference(d: &ResolvedDesign, r: usize, c: usize) -> (Vec<i64>, u64) {
    let a = d.array.as_ref().unwrap();
    let n = d.pixel.frame_pulses;
    let records: Vec<Vec<Option<u32>>> = a
        .spads_of(r, c)
        .map(|(sr, sc)| d.spad_source(sr, sc).unwrap().record(n))
        .collect();
    let rom = d.probe_rom().unwrap().unwrap();
    let mask = (1u32 << d.pixel.tdc_bits) - 1;
    let mut tm = TransactionModel::new(&d.pixel).unwrap();
    let mut detections = 0;
    for i in 0..n as usize {
        let valid: Vec<u32> = records.iter().filter_map(|rec| rec[i]).collect();
        let det = (!valid.is_empty()).then(|| {
            let (s, k) = (
                valid.iter().map(|c| c & mask).sum::<u32>(),
                valid.len() as u32,
            );
            (s + k / 2) / k
        });
        detections += u64::from(det.is_some());
        tm.pulse(det, rom.image.entry(i % d.pixel.rom_depth));
    }
    (tm.readout().words, detections)
}

#[test]
fn every_superpixel_is_the_single_pixel_model_on_its_averaged_spads() {
    let d = design(&plate(1, 1), 20_000, SPADS);
    let a = d.array.as_ref().unwrap();
    assert_eq!((a.rows, a.cols, a.superpixel), (2, 2, 2));
    assert_eq!((a.spad_rows(), a.spad_cols()), (4, 4));
    assert_eq!(a.pitch_um, 30.0, "a pixel is 2 × 2 SPADs of 15 µm");
    assert_eq!(a.mm_per_pixel, 40.0);
    let rom = d.probe_rom().unwrap().unwrap();
    let frame = run_array(&d, Some(&rom.image)).unwrap();
    assert_eq!((frame.rows, frame.cols), (2, 2));
    for (r, c) in [(0, 0), (0, 1), (1, 1)] {
        let (words, detections) = reference(&d, r, c);
        assert_eq!(frame.pixel(r, c), words, "superpixel ({r}, {c})");
        assert_eq!(
            frame.detections[r * 2 + c],
            detections,
            "detections of ({r}, {c})"
        );
    }
    // The lane driver (the array's path here) and the one-pixel driver agree.
    let group = [(1, 0), (0, 1)];
    let lanes = run_group(&d, &rom.image, &group).unwrap();
    for (&(r, c), got) in group.iter().zip(&lanes) {
        assert_eq!(
            got,
            &run_pixel(&d, Some(&rom.image), r, c).unwrap(),
            "({r}, {c})"
        );
    }
    // The gradient gives the columns different rates, so pixels differ: the test can fail.
    assert_ne!(frame.pixel(0, 0), frame.pixel(0, 1));
    // More valid pulses than any one SPAD: at ρ_s ≥ 0.2 per SPAD, 1 − 0.8^4 ≥ 59 %.
    assert!(frame.detections.iter().all(|&k| k > 20_000 * 59 / 100));
}

/// SPAD (r, c) of the superpixel array draws the photons of pixel (r, c) of the same array
/// written without `superpixel` (the seed, the rates and the position are the SPAD's).
#[test]
fn a_spad_draws_the_same_photons_whatever_g() {
    let d2 = design(&plate(1, 1), 20_000, SPADS);
    let d1 = design(&plate(1, 1), 20_000, &SPADS.replace("superpixel = 2\n", ""));
    for (r, c) in [(0, 0), (1, 3), (3, 2)] {
        assert_eq!(
            d2.spad_source(r, c).unwrap().record(20_000),
            d1.pixel_source(r, c).unwrap().record(20_000),
            "SPAD ({r}, {c})"
        );
    }
    let e = d2.pixel_source(0, 0).unwrap_err().to_string();
    assert!(
        e.contains("superpixel") && e.contains("pixel_sources"),
        "{e}"
    );
}

fn refused(array: &str) -> String {
    let t = text(&plate(1, 1), 20_000, array);
    let d = Document::from_toml_str(&t, "test.toml").unwrap();
    resolve_with(d, "test.toml", &mut ProbeCache::default())
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_superpixels_are_refused_naming_the_keys() {
    let e = refused(&SPADS.replace("superpixel = 2", "superpixel = 5"));
    assert!(
        e.contains("array.superpixel = 5") && e.contains("1..=4"),
        "{e}"
    );
    let e = refused(&SPADS.replace("superpixel = 2", "superpixel = 0"));
    assert!(e.contains("array.superpixel = 0"), "{e}");
    let e = refused(&SPADS.replace("rows = 4", "rows = 5"));
    assert!(
        e.contains("array.rows = 5 is not a multiple of array.superpixel = 2")
            && e.contains("array.rows = 4 is the nearest"),
        "{e}"
    );
    let e = refused(
        &SPADS
            .replace("rows = 4", "rows = 6")
            .replace("cols = 4", "cols = 7")
            .replace("superpixel = 2", "superpixel = 3"),
    );
    assert!(
        e.contains("array.cols = 7") && e.contains("array.cols = 6 is the nearest"),
        "{e}"
    );
}
