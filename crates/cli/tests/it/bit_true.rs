//! `tofprobe simulate` runs the bit-true pixel: the spectrum at the configured bins reads
//! a tone's amplitude, `--svg` writes a plot, and a bad `[pixel]` section is an error at
//! load time that names the key and the value that would work.

use crate::common;

use common::{edit, short_tone_frame, tofprobe, windowed_default};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-bt-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The windowed default (the checks are about short frames, L = N) with each `(from, to)`
/// replaced (each must occur).
fn edited(edits: &[(&str, &str)]) -> String {
    edit(windowed_default(), edits)
}

/// A 1 mm tone exactly on bin 30 of a 2^16-pulse frame (30·10 MHz/65536 Hz), σ = 7.5 mm.
/// Noise floor (Blackman, N_eff = 0.579 N): sqrt(π·7.5²/(0.579·65536)) = 68 µm mean
/// amplitude per bin; the tone bin reads 1000 µm ± that noise, so ±250 µm (3.7× the mean
/// noise amplitude) is a bound a correct model misses with probability < 10^−5, while a
/// normalisation error of the prefilter gain, coherent gain or 2/N factor breaks it.
#[test]
fn simulate_prints_the_bit_true_spectrum_and_plots_it() {
    let dir = scratch("spectrum");
    let f = 30.0 * 10e6 / 65536.0;
    let text = short_tone_frame(65536);
    let cfg = dir.join("tone.toml");
    std::fs::write(&cfg, text).expect("write");
    let svg = dir.join("spectrum.svg");
    let out = tofprobe(&[
        "simulate",
        cfg.to_str().expect("path"),
        "--json",
        "--svg",
        svg.to_str().expect("path"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["pulses"].as_u64(), Some(65536));
    let bt = &v["bit_true"];
    let bins = bt["bins"].as_array().expect("bins");
    assert_eq!(bins.len(), 4);
    // The tone's bin comes first (auto choice from the scene), then noise bins.
    assert!((bins[0]["frequency_hz"].as_f64().unwrap() - f).abs() < 1e-6);
    let a = bins[0]["amplitude_um"].as_f64().unwrap();
    assert!((a - 1000.0).abs() < 250.0, "tone {a} µm");
    for b in &bins[1..] {
        let n = b["amplitude_um"].as_f64().unwrap();
        assert!(n.is_finite() && n < 400.0, "noise bin {n} µm");
    }
    let noise = bt["noise_estimate_um"].as_f64().unwrap();
    assert!(noise > 5.0 && noise < 400.0, "noise {noise}");
    let plot = std::fs::read_to_string(&svg).expect("svg written");
    assert!(plot.starts_with("<svg") && plot.contains("bit-true"), "svg");
}

/// A `[pixel]` that cannot be built fails at load time with the key, the reason and the
/// nearest valid value (width one bit below the sizing; too many bins for the schedule).
#[test]
fn bad_pixel_section_is_a_load_error() {
    let dir = scratch("badpixel");
    for (i, (from, to, parts)) in [
        (
            "frac_bits = 8",
            "frac_bits = 8\nwidth = 38",
            &["[pixel]", "pixel.width = 38", "nearest valid value: 39"][..],
        ),
        (
            "bins = 16",
            "bins = 17",
            &["[pixel]", "cycles_per_pulse"][..],
        ),
        ("bins = 16", "bins = \"many\"", &["bins"][..]),
    ]
    .into_iter()
    .enumerate()
    {
        let p = dir.join(format!("bad{i}.toml"));
        std::fs::write(&p, edited(&[(from, to)])).expect("write");
        let out = tofprobe(&["simulate", p.to_str().expect("path")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        for part in parts {
            assert!(err.contains(part), "`{err}` lacks `{part}`");
        }
    }
}
