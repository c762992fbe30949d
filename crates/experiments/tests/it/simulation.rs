//! `simulation::simulate` through the library: the record summary equals a naive float
//! computation over the same source's record, the progress callback reaches the record's
//! length, and the bit-true part is the Fourier frame's spectrum at the design's bins.

use crate::common::{resolved, windowed_short};
use tofprobe_experiments::simulation::{simulate, summarise};

const N: u64 = 1 << 16;

#[test]
fn the_summary_is_the_naive_statistics_of_the_record() {
    let d = resolved(&windowed_short(N));
    let source = d.photon_source().unwrap();
    let mut last = 0;
    let s = summarise(&source, N, |done| last = done);
    assert_eq!(last, N, "the progress reaches the record's length");
    let depths: Vec<f64> = source
        .record(N)
        .into_iter()
        .flatten()
        .map(|c| source.code_to_depth_mm(c))
        .collect();
    assert_eq!(s.detections, depths.len() as u64);
    let n = depths.len() as f64;
    let mean = depths.iter().sum::<f64>() / n;
    let var = depths.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    // Integer sums against f64 sums of ~6·10^4 depths near 30 mm: they agree to ~1e-9 mm.
    assert!(
        (s.mean_depth_mm.unwrap() - mean).abs() < 1e-9,
        "{s:?} vs {mean}"
    );
    assert!(
        (s.sigma_depth_mm.unwrap() - var.sqrt()).abs() < 1e-9,
        "{s:?}"
    );
    assert!((s.detection_rate - n / N as f64).abs() < 1e-15);
}

#[test]
fn a_fourier_simulation_carries_its_spectrum_and_no_transients() {
    let d = resolved(&windowed_short(N));
    let sim = simulate(&d, |_| {}).unwrap();
    let b = sim.bit_true.as_ref().expect("a Fourier frame");
    assert_eq!(b.bins.len(), 4);
    assert_eq!(b.frame_pulses, d.pixel.frame_pulses);
    assert!(sim.haar.is_none());
    let spectrum = sim.spectrum.as_ref().expect("kept for the plot");
    for (out, bin) in b.bins.iter().zip(&spectrum.bins) {
        assert_eq!(out.amplitude_um, Some(bin.amplitude_um));
    }
    // The paper's noise statistic: the mean |Y| of the bins away from the 4.5 kHz tone
    // (more than 1.5 bins of f_s/L from it), not the median of all bins, tone included.
    let bin_hz = 10e6 / d.pixel.rom_depth as f64;
    let away: Vec<f64> = b
        .bins
        .iter()
        .filter(|x| (x.frequency_hz - 4500.0).abs() > 1.5 * bin_hz)
        .map(|x| x.amplitude_um.unwrap())
        .collect();
    assert!(
        !away.is_empty() && away.len() < b.bins.len(),
        "the tone is a bin"
    );
    let mean = away.iter().sum::<f64>() / away.len() as f64;
    assert!((b.noise_estimate_um.unwrap() - mean).abs() < 1e-12);
    assert_eq!(b.noise_bins, away.len());
    assert_eq!(b.median_amplitude_um, Some(spectrum.median_amplitude_um));
    let json = serde_json::to_value(&sim).unwrap();
    assert_eq!(
        json["pulses"], N,
        "the summary is flattened into the object"
    );
    assert_eq!(json["mode"], "fourier");
}
