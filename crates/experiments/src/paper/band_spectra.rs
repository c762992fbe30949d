//! Fig. 7 and Fig. 8 read over 0–20 kHz by the float DFT and by ΣΔ probing of every bin on
//! a grid, from the same prefiltered record, with the streaming full-band prober
//! (`tofprobe_dsp::sd::fullband_spectrum::windowed_band`, the `bench fullband` engine) and
//! Table 2's probe design. Fig. 7 is the paper's noise-only scene (σ_s = 3.0 mm, ρ_s = 1,
//! no tone: Table 2's first row), whose caption prints an "average noise" of 2.5 µm — an
//! erratum of its own Table 2's 2.25 (DESIGN.md), both marked beside the measured floor.
//! Fig. 8 is the σ_s = 7.5 mm, ρ_s = 1 row with 100 µm at 4.5 kHz. The grid is coarser
//! than the record's 1 Hz bins so that the reproduction stays within its time budget:
//! [`STEP_HZ`] over [`MAX_HZ`] is 2·(MAX/STEP)·N modulator steps (8·10^9 at N = 10^7) a
//! figure, a few seconds on two cores.

use tofprobe_dsp::sd::LanePrecision;
use tofprobe_dsp::sd::fullband_spectrum::{
    BandSpectrum, BandSummary, prefiltered_record_zoomed, windowed_band,
};

use super::chart::{Chart, Curve, Series};
use super::figures::QUICK_NOTE;
use super::setup::FS_HZ;
use super::sigma_delta::{ProbeSetup, alpha};
use super::table2::{F0_HZ, ROWS, Spec};
use crate::ExperimentError;

/// Highest bin of the band (Hz).
pub const MAX_HZ: f64 = 20_000.0;
/// Grid step of the full run (Hz).
pub const STEP_HZ: f64 = 50.0;
/// Grid step of `--quick` (Hz).
pub const QUICK_STEP_HZ: f64 = 250.0;

/// Fig. 7's "average noise" as the paper prints it (µm): Table 2 gives 2.25 for the same
/// scene, and the closed form (eq. 12 with Blackman's N_eff) 2.21.
pub const FIG7_PRINTED_NOISE_UM: f64 = 2.5;

/// Fig. 7's scene: the σ_s = 3.0 mm, ρ_s = 1, ρ_b = 0 row without a tone.
pub fn fig7_scene() -> Spec {
    ROWS[0]
}

/// Fig. 8's scene: the σ_s = 7.5 mm, ρ_s = 1, ρ_b = 0, 100 µm row.
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
    measure_scene(&scene(), probe, step_hz)
}

/// The band of one Table 2 scene, as [`measure`].
pub fn measure_scene(
    spec: &Spec,
    probe: &ProbeSetup,
    step_hz: f64,
) -> Result<BandSpectrum, ExperimentError> {
    let setup = spec.setup();
    // The row's first seed: the figure draws one record of its Table 2 row.
    let source = setup.source(super::table2::seeds_for(spec, probe.n)?[0])?;
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
        tofprobe_dsp::sd::Isa::current(),
        |_| {},
    )?)
}

/// |Y| of the band's ΣΔ and DFT bins in µm against frequency (a bin of exactly 0 — never
/// met on a noisy record — is left out rather than drawn at a clamp).
fn amplitudes_um(s: &BandSpectrum) -> (Curve, Curve) {
    let um = |y: &mut dyn Iterator<Item = f64>| -> Vec<(f64, f64)> {
        s.frequencies_hz
            .iter()
            .zip(y)
            .filter(|&(_, a)| a > 0.0)
            .map(|(&f, a)| (f, a * 1e3))
            .collect()
    };
    (
        um(&mut s.sd.iter().map(|y| y.norm())),
        um(&mut s.dft.iter().map(|y| y.norm())),
    )
}

/// The scene line of a figure's notes.
fn scene_note(spec: &Spec, n: u64) -> String {
    format!(
        "scene: σ_s = {} mm, ρ_s = {}, ρ_b = {}, {}; N = {n}, seed {}",
        spec.sigma_s_mm,
        spec.rho_s,
        spec.rho_b,
        spec.amp_um.map_or("no tone".to_string(), |a| format!(
            "A = {a} µm at {F0_HZ} Hz"
        )),
        super::table2::seeds_for(spec, n).map_or(0, |s| s[0])
    )
}

/// Fig. 7: the noise-only scene's band by ΣΔ probing and the DFT, with the paper's printed
/// average noise (2.5 µm), its Table 2 value (2.25 µm) and the measured floors.
pub fn fig7(s: &BandSpectrum, n: u64, quick: bool) -> Result<Chart, ExperimentError> {
    let sum = BandSummary::of(s, n)?;
    let spec = fig7_scene();
    let (sd, dft) = amplitudes_um(s);
    let (f_lo, f_hi) = band_edges(s);
    let flat = |name: String, v: f64| Series::new(name, vec![(f_lo, v), (f_hi, v)]);
    let mut lines = vec![Series::new("ΣΔ probing", sd), Series::new("DFT", dft)];
    if !quick {
        lines.push(flat(
            format!("paper, Fig. 7 caption: average noise {FIG7_PRINTED_NOISE_UM} µm (erratum)"),
            FIG7_PRINTED_NOISE_UM,
        ));
        lines.push(flat(
            format!("paper, Table 2 (true): {} µm", spec.printed.noise_um.dft),
            spec.printed.noise_um.dft,
        ));
    }
    lines.push(flat(
        format!("measured mean |Y| (DFT): {:.3} µm", sum.noise_dft_um),
        sum.noise_dft_um,
    ));
    let mut notes = vec![
        scene_note(&spec, n),
        format!(
            "paper: Fig. 7 prints an average noise of {FIG7_PRINTED_NOISE_UM} µm; its Table 2 \
             gives {} µm (DFT) / {} µm (ΣΔ) for this scene — the caption is an erratum",
            spec.printed.noise_um.dft, spec.printed.noise_um.sd
        ),
        format!(
            "measured: mean |Y| {:.3} µm (DFT), {:.3} µm (ΣΔ); ΣΔ error {:.3}× the floor",
            sum.noise_dft_um,
            sum.noise_sd_um,
            sum.error_um / sum.noise_dft_um
        ),
    ];
    if quick {
        notes.push(format!(
            "{QUICK_NOTE} (the paper's 2.5 and 2.25 µm are for N = 10^7)"
        ));
    }
    Ok(Chart {
        file: "fig7_dft_spectrum.svg".into(),
        title: format!(
            "Fig. 7: noise-only spectrum over 0–{} kHz, DFT and ΣΔ (σ_s = {} mm, {} bins)",
            MAX_HZ / 1e3,
            spec.sigma_s_mm,
            s.bins.len()
        ),
        x_label: "frequency (Hz)".into(),
        y_label: "|Y| (µm)".into(),
        y_log: true,
        lines,
        notes,
        ..Chart::default()
    })
}

/// The first and last frequency of a band (Hz).
fn band_edges(s: &BandSpectrum) -> (f64, f64) {
    (
        s.frequencies_hz.first().copied().unwrap_or(0.0),
        s.frequencies_hz.last().copied().unwrap_or(MAX_HZ),
    )
}

/// Fig. 8 (ΣΔ, the DFT beside it) of a measured band, with the paper's printed amplitude
/// and floor of the scene's Table 2 row (shown where not `quick`: a short record has
/// another floor).
pub fn fig8(s: &BandSpectrum, n: u64, quick: bool) -> Result<Chart, ExperimentError> {
    let sum = BandSummary::of(s, n)?;
    let spec = scene();
    let (sd, dft) = amplitudes_um(s);
    let step = s.frequencies_hz.get(1).copied().unwrap_or(0.0) - s.frequencies_hz[0];
    let (f_lo, f_hi) = band_edges(s);
    let flat = |name: &str, v: f64| Series::new(name, vec![(f_lo, v), (f_hi, v)]);
    let mut notes = vec![scene_note(&spec, n)];
    notes.push(format!(
        "paper (Table 2): amplitude {} µm, noise floor {} µm{}",
        spec.printed.amp_um.dft,
        spec.printed.noise_um.dft,
        if quick {
            " (QUICK RUN: this record is shorter, its floor higher)"
        } else {
            ""
        }
    ));
    notes.push(format!(
        "measured: peak {:.2} µm (DFT {:.2}), floor {:.3} µm (DFT {:.3}), ΣΔ error {:.3}× floor",
        sum.peak_sd_um,
        sum.peak_dft_um,
        sum.noise_sd_um,
        sum.noise_dft_um,
        sum.error_um / sum.noise_dft_um
    ));
    Ok(Chart {
        file: "fig8_sd_spectrum.svg".into(),
        title: format!(
            "Fig. 8: ΣΔ-probed spectrum, one probe per bin every {step:.0} Hz ({} bins)",
            s.bins.len()
        ),
        x_label: "frequency (Hz)".into(),
        y_label: "|Y| (µm)".into(),
        y_log: true,
        lines: vec![
            Series::new("ΣΔ probing", sd),
            Series::new("DFT (same record)", dft),
            flat("A = 100 µm (scene)", spec.amp_um.unwrap_or(0.0)),
            flat("paper floor (Table 2, N = 10^7)", spec.printed.noise_um.dft),
        ],
        notes,
        ..Chart::default()
    })
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

    /// A short record (2^20 pulses, floor ≈ 5.5·sqrt(10^7/2^20) ≈ 17 µm: the 100 µm tone
    /// stands 6 floors up, and a noise bin of the 20 on the grid passes it with probability
    /// ≈ 20·e^(−(100/13.5)²/2) ≈ 10^-11 — at 2^18 (3 floors) that was ≈ 2 %, and one seed
    /// of the batched Monte Carlo drew it: the peak landed on 8 kHz): the ΣΔ-probed
    /// tone differs from the DFT's on the same record by the ΣΔ error only, ≈ 0.2 floor
    /// per bin; its projection on the tone has sd ≈ ē/1.13 (ē the mean error over the noise
    /// bins, `sigma_delta::rows`), so 3ē bounds it at ≈ 3.4σ. The error itself stays well
    /// under one floor (a broken prefilter correction would make it several floors).
    #[test]
    fn short_band_tracks_the_dft() {
        let n = 1u64 << 20;
        let probe = super::super::sigma_delta::tests::setup_for_tests(n);
        let s = measure(&probe, 1000.0).unwrap();
        let sum = BandSummary::of(&s, n).unwrap();
        assert!((sum.peak_hz - F0_HZ).abs() < 40.0, "{}", sum.peak_hz);
        assert!(
            (sum.peak_sd_um - sum.peak_dft_um).abs() <= 3.0 * sum.error_um,
            "{sum:?}"
        );
        assert!(sum.error_um < 0.5 * sum.noise_dft_um, "{sum:?}");
        let svg = fig8(&s, n, true).unwrap().render().unwrap();
        assert!(svg.contains("Fig. 8"));
        assert_eq!(
            super::super::svg_check::problems(&svg),
            Vec::<String>::new()
        );
    }

    /// Fig. 7 is the paper's noise-only scene: σ_s = 3 mm, no tone; the full-length figure
    /// marks the printed 2.5 µm beside Table 2's 2.25 µm, and its measured floor on a short
    /// record (2^18 pulses) is eq. 12's: 2.21·sqrt(10^7/2^18) = 13.6 µm within 20 % (80
    /// grid bins 250 Hz apart, i.e. ≈ 65 record bins apart: independent Rayleigh
    /// magnitudes, relative sd 0.52 each, so the mean's is 5.8 % and 20 % is 3.4σ; the
    /// prefilter's gain is divided out and the zoom changes no noise bin).
    #[test]
    fn fig7_is_the_noise_only_scene_with_the_printed_erratum() {
        let spec = fig7_scene();
        assert_eq!((spec.sigma_s_mm, spec.rho_s, spec.amp_um), (3.0, 1.0, None));
        let n = 1u64 << 18;
        let probe = super::super::sigma_delta::tests::setup_for_tests(n);
        let s = measure_scene(&spec, &probe, QUICK_STEP_HZ).unwrap();
        let sum = BandSummary::of(&s, n).unwrap();
        let want = 2.21 * (1e7 / n as f64).sqrt();
        assert!(
            (sum.noise_dft_um / want - 1.0).abs() < 0.20,
            "{sum:?} vs {want}"
        );
        let full = fig7(&s, n, false).unwrap();
        let names: Vec<&str> = full.lines.iter().map(|l| l.name.as_str()).collect();
        assert!(
            names.iter().any(|n| n.contains("2.5 µm (erratum)")),
            "{names:?}"
        );
        assert!(names.iter().any(|n| n.contains("2.25 µm")), "{names:?}");
        let svg = full.render().unwrap();
        assert!(svg.contains("Fig. 7") && svg.contains("no tone"));
        assert_eq!(
            super::super::svg_check::problems(&svg),
            Vec::<String>::new()
        );
    }
}
