//! Fig. 7 and Fig. 8: the Fig. 8 scene (Table 2's σ_s = 7.5 mm, ρ_s = 1 row: 100 µm at
//! 4.5 kHz) read over 0–20 kHz by the float DFT (Fig. 7) and by ΣΔ probing of every bin
//! on a grid (Fig. 8), from the same prefiltered record, with the streaming full-band
//! prober (`tofprobe_dsp::sd::fullband_spectrum::windowed_band`, the `bench fullband`
//! engine) and Table 2's probe design. The grid is coarser than the record's 1 Hz bins so
//! that the reproduction stays within its time budget: [`STEP_HZ`] over [`MAX_HZ`] is
//! 2·(MAX/STEP)·N modulator steps (8·10^9 at N = 10^7), a few seconds on two cores.

use tofprobe_dsp::sd::LanePrecision;
use tofprobe_dsp::sd::fullband_spectrum::{
    BandSpectrum, BandSummary, prefiltered_record_zoomed, windowed_band,
};

use super::chart::{Chart, Series};
use super::setup::FS_HZ;
use super::sigma_delta::{ProbeSetup, alpha};
use super::stats::SEEDS;
use super::table2::{F0_HZ, ROWS, Spec};
use crate::ExperimentError;

/// Highest bin of the band (Hz).
pub const MAX_HZ: f64 = 20_000.0;
/// Grid step of the full run (Hz).
pub const STEP_HZ: f64 = 50.0;
/// Grid step of `--quick` (Hz).
pub const QUICK_STEP_HZ: f64 = 250.0;

/// The scene of the two figures: the σ_s = 7.5 mm, ρ_s = 1, ρ_b = 0, 100 µm row.
pub fn scene() -> Spec {
    ROWS[8]
}

/// Bins k ≥ 1 of step, 2·step, … ≤ [`MAX_HZ`] on an N-pulse record's f_s/N grid.
pub fn grid(n: u64, step_hz: f64) -> Vec<u64> {
    let df = FS_HZ / n as f64;
    let mut bins: Vec<u64> = (1..=(MAX_HZ / step_hz).floor() as u64)
        .map(|i| (i as f64 * step_hz / df).round() as u64)
        .filter(|&k| k >= 1)
        .collect();
    // The tone's own bin, so the peak is read where it is.
    bins.push((F0_HZ / df).round() as u64);
    bins.sort_unstable();
    bins.dedup();
    bins
}

/// The band of the Fig. 8 scene (seed `SEEDS[0]`, N = `probe.n`) by ΣΔ probing and the
/// DFT, zoomed to δ0 like the pixel, prefiltered with α = 1/32.
pub fn measure(probe: &ProbeSetup, step_hz: f64) -> Result<BandSpectrum, ExperimentError> {
    let spec = scene();
    let setup = spec.setup();
    let source = setup.source(SEEDS[0])?;
    let x = prefiltered_record_zoomed(&source, probe.n, alpha(), setup.depth_mm())?;
    Ok(windowed_band(
        &x,
        &probe.design,
        FS_HZ,
        &grid(probe.n, step_hz),
        alpha(),
        LanePrecision::F64,
        // The fastest kernel this CPU runs: bit-identical to the baseline
        // (crates/dsp/tests/fullband_isa.rs).
        tofprobe_dsp::sd::KernelPath::detect(),
        |_| {},
    )?)
}

/// Fig. 7 (DFT) and Fig. 8 (ΣΔ, the DFT beside it) of a measured band, with the paper's
/// printed amplitude and floor of the scene's Table 2 row (shown where not `quick`: a
/// short record has another floor).
pub fn charts(s: &BandSpectrum, n: u64, quick: bool) -> Result<Vec<Chart>, ExperimentError> {
    let sum = BandSummary::of(s, n)?;
    let spec = scene();
    let um = |a: &mut dyn Iterator<Item = f64>| -> Vec<(f64, f64)> {
        s.frequencies_hz
            .iter()
            .zip(a)
            .map(|(&f, y)| (f, (y * 1e3).max(1e-3)))
            .collect()
    };
    let (sd, dft) = (
        um(&mut s.sd.iter().map(|y| y.norm())),
        um(&mut s.dft.iter().map(|y| y.norm())),
    );
    let step = s.frequencies_hz.get(1).copied().unwrap_or(0.0) - s.frequencies_hz[0];
    let f_lo = s.frequencies_hz[0];
    let f_hi = s.frequencies_hz.last().copied().unwrap_or(MAX_HZ);
    let flat = |name: &str, v: f64| Series::new(name, vec![(f_lo, v), (f_hi, v)]);
    let mut paper = vec![format!(
        "scene: σ_s = {} mm, ρ_s = {}, ρ_b = {}, A = {} µm at {F0_HZ} Hz; N = {n}, seed {}",
        spec.sigma_s_mm,
        spec.rho_s,
        spec.rho_b,
        spec.amp_um.unwrap_or(0.0),
        SEEDS[0]
    )];
    let refs = vec![
        flat("A = 100 µm (scene)", spec.amp_um.unwrap_or(0.0)),
        flat("paper floor (Table 2, N = 10^7)", spec.paper_noise_um),
    ];
    paper.push(format!(
        "paper (Table 2): amplitude {} µm, noise floor {} µm{}",
        spec.paper_amp_um.unwrap_or(0.0),
        spec.paper_noise_um,
        if quick {
            " (QUICK RUN: this record is shorter, its floor higher)"
        } else {
            ""
        }
    ));
    let mut fig7 = Chart {
        file: "fig7_dft_spectrum.svg".into(),
        title: format!(
            "Fig. 7: DFT spectrum over 0–{} kHz (Blackman, prefiltered, {} bins)",
            MAX_HZ / 1e3,
            s.bins.len()
        ),
        x_label: "frequency (Hz)".into(),
        y_label: "|Y| (µm)".into(),
        y_log: true,
        lines: [vec![Series::new("DFT", dft.clone())], refs.clone()].concat(),
        notes: paper.clone(),
        ..Chart::default()
    };
    fig7.notes.push(format!(
        "measured: peak {:.2} µm at {:.0} Hz, floor {:.3} µm",
        sum.peak_dft_um, sum.peak_hz, sum.noise_dft_um
    ));
    let mut fig8 = Chart {
        file: "fig8_sd_spectrum.svg".into(),
        title: format!(
            "Fig. 8: ΣΔ-probed spectrum, one probe per bin every {step:.0} Hz ({} bins)",
            s.bins.len()
        ),
        x_label: "frequency (Hz)".into(),
        y_label: "|Y| (µm)".into(),
        y_log: true,
        lines: [
            vec![
                Series::new("ΣΔ probing", sd),
                Series::new("DFT (same record)", dft),
            ],
            refs,
        ]
        .concat(),
        notes: paper,
        ..Chart::default()
    };
    fig8.notes.push(format!(
        "measured: peak {:.2} µm (DFT {:.2}), floor {:.3} µm (DFT {:.3}), ΣΔ error {:.3}× floor",
        sum.peak_sd_um,
        sum.peak_dft_um,
        sum.noise_sd_um,
        sum.noise_dft_um,
        sum.error_um / sum.noise_dft_um
    ));
    Ok(vec![fig7, fig8])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid holds the tone's bin, starts above DC and stops at [`MAX_HZ`].
    #[test]
    fn grid_holds_the_tone() {
        for n in [1u64 << 20, 10_000_000] {
            let g = grid(n, STEP_HZ);
            let df = FS_HZ / n as f64;
            assert!(g.contains(&((F0_HZ / df).round() as u64)));
            assert!(g[0] >= 1 && *g.last().unwrap() as f64 * df <= MAX_HZ + df);
            assert!(g.windows(2).all(|w| w[0] < w[1]));
        }
    }

    /// A short record (2^18 pulses, floor ≈ 5.5·sqrt(10^7/2^18) ≈ 34 µm): the ΣΔ-probed
    /// tone differs from the DFT's on the same record by the ΣΔ error only, ≈ 0.2 floor
    /// per bin; its projection on the tone has sd ≈ ē/1.13 (ē the mean error over the noise
    /// bins, `sigma_delta::rows`), so 3ē bounds it at ≈ 3.4σ. The error itself stays well
    /// under one floor (a broken prefilter correction would make it several floors).
    #[test]
    fn short_band_tracks_the_dft() {
        let n = 1u64 << 18;
        let probe = super::super::sigma_delta::tests::setup_for_tests(n);
        let s = measure(&probe, 1000.0).unwrap();
        let sum = BandSummary::of(&s, n).unwrap();
        assert!((sum.peak_hz - F0_HZ).abs() < 40.0, "{}", sum.peak_hz);
        assert!(
            (sum.peak_sd_um - sum.peak_dft_um).abs() <= 3.0 * sum.error_um,
            "{sum:?}"
        );
        assert!(sum.error_um < 0.5 * sum.noise_dft_um, "{sum:?}");
        let c = charts(&s, n, true).unwrap();
        assert_eq!(c.len(), 2);
        assert!(c[0].render().unwrap().contains("Fig. 7"));
    }
}
