//! `tofprobe replay` through the binary on the real PicoQuant records of ../shared/data/tttr
//! (BSD-3-Clause sample data): the counts the decoder must read (cross-checked against
//! PyPI's `ptufile` by scripts/tttr-crosscheck.sh), the bit-true spectrum against its float
//! twin, finite JSON, and the errors a user meets.

mod common;

use common::tofprobe;
use std::path::PathBuf;

fn record(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/tttr")
        .join(name)
}

/// The HydraHarp v2 T3 record (5 MHz sync): 77,883 photons in 106,349 records (the
/// decoder's figures, equal to ptufile's), fitted and replayed through the pixel. The
/// bit-true amplitudes follow the float twin of the same detections: the pixel's only
/// differences are the prefilter's floor shift on 2^−8 codes and the 2^−F truncation,
/// bounded here by 2% of each bin's amplitude plus 1 µm (measured ≤ 0.7%).
#[test]
fn hydraharp_t3_replays_through_the_pixel() {
    let f = record("hydraharp_v20_t3.ptu");
    let out = tofprobe(&["replay", f.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["record"]["counts"]["photons"], 77_883);
    assert_eq!(v["record"]["counts"]["records"], 106_349);
    let frame = v["frame_pulses"].as_u64().unwrap();
    assert_eq!(frame % 20_000, 0, "whole ROM periods");
    assert!(frame <= v["fitted"]["pulses"].as_u64().unwrap());
    let bins = v["bins"].as_array().unwrap();
    assert_eq!(bins.len(), 16);
    for b in bins {
        let (a, f) = (
            b["amplitude_um"].as_f64().unwrap(),
            b["float_amplitude_um"].as_f64().unwrap(),
        );
        assert!(
            (a - f).abs() <= 0.02 * f + 1.0,
            "bit-true {a} µm vs float {f} µm"
        );
    }
    assert!(v["closed_form_floor_um"].as_f64().unwrap() > 0.0);
    // The floor against the closed form, bin by bin. A noise-only amplitude over its
    // Rayleigh median has median 1; the sample median of 16 such ratios has sd
    // 1/(2·f(1)·√16) = 0.18 (f(1) = ln 2, the median-normalised Rayleigh density at 1), so
    // 2.5 sd gives [0.55, 1.45] (the record's lowest two bins carry real low-frequency
    // content and only push the median up by one rank).
    let ratio = v["floor_ratio"].as_f64().unwrap();
    assert!((0.55..=1.45).contains(&ratio), "floor ratio {ratio}");
    // The comparison this replaced (median of amplitudes over the mean of the bins'
    // floors) is 0.46 on this record, outside the band: the hold's floor falls as 1/f
    // across the bins, so that statistic measures the bins' spread, not the noise.
    let (amps, mut floors): (Vec<f64>, Vec<f64>) = bins
        .iter()
        .map(|b| {
            (
                b["amplitude_um"].as_f64().unwrap(),
                b["closed_form_um"].as_f64().unwrap(),
            )
        })
        .unzip();
    let mut sorted = amps.clone();
    sorted.sort_by(f64::total_cmp);
    let median_amp = 0.5 * (sorted[7] + sorted[8]);
    floors.sort_by(f64::total_cmp);
    let mean_floor = floors.iter().sum::<f64>() / floors.len() as f64;
    let old = median_amp / mean_floor;
    assert!(!(0.55..=1.45).contains(&old), "old statistic {old}");
    // The text form names the record, the photon count and the floor comparison.
    let out = tofprobe(&["replay", f.to_str().unwrap()]);
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(
        s.contains("77883 photons") && s.contains("noise floor: measured"),
        "{s}"
    );
}

/// Errors name the file and what was expected: a T2 record without syncs, a file that is
/// not a record, a missing file; exit status 2 and no panic.
#[test]
fn bad_records_are_refused_clearly() {
    let t2 = record("hydraharp_v20_t2.ptu");
    let out = tofprobe(&["replay", t2.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("hydraharp_v20_t2.ptu") && e.contains("sync"),
        "{e}"
    );

    let dir = tempfile::tempdir().unwrap();
    let bogus = dir.path().join("not-a-record.ptu");
    std::fs::write(&bogus, b"this is not a PicoQuant file at all").unwrap();
    let out = tofprobe(&["replay", bogus.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("not-a-record.ptu") && !e.contains("panicked"),
        "{e}"
    );

    let out = tofprobe(&["replay", "/nonexistent/x.ptu"]);
    assert_eq!(out.status.code(), Some(2));
    let out = tofprobe(&["replay", t2.to_str().unwrap(), "--resolution-s=-1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("resolution-s"));
}
