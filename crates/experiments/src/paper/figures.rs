//! The paper's figures drawn from the data the reproduction already computed (no second
//! pipeline): Fig. 2 (a 50 kHz probe's bitstream spectrum, noise shaping), Fig. 4 (noise
//! floor vs σ_I, `fig4`) and Fig. 6 (the 1NN hold's 3 dB point vs ρ_s, `bandwidth`).
//! Simulated points are the mean ± sd over the seeds of `stats::SEEDS`; the paper's printed
//! values are drawn as crosses and written out as text. The figures of Table 2's rows
//! (Fig. 5, Fig. 9) are in `plots`, Fig. 7 and 8 in `band_spectra`.

use tofprobe_dsp::Window;
use tofprobe_dsp::closed_form::{hold_bandwidth_hz, zoh_hold_f3db};
use tofprobe_dsp::sd::Modulator;
use tofprobe_dsp::sd::quality::{ToneSpectrum, eq4_snr_db};

use super::chart::{Chart, ErrorSeries, Legend, Series};
use super::setup::FS_HZ;
use super::stats::{SEEDS, mean_sd};
use super::{bandwidth, fig4};
use crate::ExperimentError;

/// Fig. 2's probe frequency (Hz).
pub const FIG2_PROBE_HZ: f64 = 50_000.0;
/// Fig. 2's record (samples of the bitstream).
pub const FIG2_SAMPLES: usize = 1 << 16;
/// SNR of 12 bits, 6.02·12 + 1.76 dB.
pub const SNR_12_BITS_DB: f64 = 6.02 * 12.0 + 1.76;
/// The band below which the paper reads ENOB ≥ 12 bits from eq. 4 (Hz; DESIGN.md).
pub const PAPER_12_BIT_BAND_HZ: f64 = 297_000.0;

/// The ΣΔ bitstream of a probe at [`FIG2_PROBE_HZ`] (amplitude `amplitude`), its
/// Hann-windowed power spectrum (`ToneSpectrum`: a full-scale sine sums to 1).
pub fn probe_spectrum(m: &Modulator, amplitude: f64) -> Result<ToneSpectrum, ExperimentError> {
    let bin = (FIG2_PROBE_HZ / FS_HZ * FIG2_SAMPLES as f64).round() as usize;
    Ok(ToneSpectrum::measure(m, amplitude, bin, FIG2_SAMPLES)?)
}

/// Fig. 2: the probe's spectrum in dB against log frequency, the signal band
/// f_s/(2·OSR) marked, the measured in-band SNR beside eq. 4.
pub fn fig2(m: &Modulator, amplitude: f64) -> Result<Chart, ExperimentError> {
    let t = probe_spectrum(m, amplitude)?;
    let df = FS_HZ / t.n as f64;
    // Log-spaced maxima (≈ 300 points) of the power per bin, in dB (the noise-shaped
    // floor's envelope: Fig. 2 is read for its slope and the tone, both maxima).
    let mut pts = Vec::new();
    let mut k = 1usize;
    while k < t.power.len() {
        let next = ((k as f64 * 1.03).ceil() as usize)
            .max(k + 1)
            .min(t.power.len());
        let p = t.power[k..next].iter().copied().fold(0.0, f64::max);
        // A group of exactly-zero bins has no level in dB: it is left out, not drawn at a
        // clamp (a −200 dB floor read as data).
        if p > 0.0 {
            pts.push((k as f64 * df, 10.0 * p.log10()));
        }
        k = next;
    }
    let band = 0.5 / m.osr;
    let band_hz = band * FS_HZ;
    let snr = t.snr_db(band);
    let b12 = t.band_for_snr(SNR_12_BITS_DB) * FS_HZ;
    let ideal = eq4_snr_db(m.order, m.osr, amplitude);
    Ok(Chart {
        file: "fig2_probe_spectrum.svg".into(),
        title: format!(
            "Fig. 2: ΣΔ bitstream of a {} kHz probe (order {}, OSR {}, H_inf {}, A_p {amplitude})",
            FIG2_PROBE_HZ / 1e3,
            m.order,
            m.osr,
            m.h_inf
        ),
        x_label: "frequency (Hz)".into(),
        y_label: "power per bin (dB re full-scale sine)".into(),
        x_log: true,
        lines: vec![Series::new("bitstream (Hann, 2^16 samples)", pts)],
        marks: vec![
            (
                format!("signal band f_s/(2·OSR) = {} kHz", band_hz / 1e3),
                band_hz,
            ),
            (
                format!(
                    "paper: ENOB ≥ 12 bits below {} kHz",
                    PAPER_12_BIT_BAND_HZ / 1e3
                ),
                PAPER_12_BIT_BAND_HZ,
            ),
        ],
        notes: vec![
            format!("in-band SNR {snr:.1} dB measured; eq. 4 (ideal (1 − z⁻¹)^Θ) {ideal:.1} dB"),
            if b12 > 0.0 {
                format!(
                    "12 bits ({SNR_12_BITS_DB:.2} dB) measured below {:.0} kHz",
                    b12 / 1e3
                )
            } else {
                format!("12 bits ({SNR_12_BITS_DB:.2} dB) not reached at A_p = {amplitude}")
            },
        ],
        legend: Legend::LowerRight,
        ..Chart::default()
    })
}

/// x values spread geometrically over [lo, hi] (`n` ≥ 2 points).
fn geomspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// Fig. 4: the noise floor against σ_I, both windows, mean ± sd over the seeds.
pub fn fig4_chart(points: &[fig4::Point], n: u64) -> Chart {
    let quick = n != fig4::N;
    let mut c = Chart {
        file: "fig4_noise_vs_sigma_i.svg".into(),
        title: format!(
            "Fig. 4: noise floor vs σ_I (ρ_s = 1, N = {n}, {} seeds)",
            SEEDS.len()
        ),
        x_label: "σ_I (ps)".into(),
        y_label: "noise floor (µm)".into(),
        x_log: true,
        y_log: true,
        legend: Legend::UpperLeft,
        ..Chart::default()
    };
    for w in fig4::WINDOWS {
        let of_w: Vec<&fig4::Point> = points.iter().filter(|p| p.window == w).collect();
        // eq. 12 is linear in σ: the closed form through the measured σ_I range.
        if let (Some(a), Some(b)) = (of_w.first(), of_w.last()) {
            let slope = a.closed_form_um / a.sigma_i_ps;
            c.lines.push(Series::new(
                format!("eq. 12, {}", w.name()),
                geomspace(a.sigma_i_ps / 1.5, b.sigma_i_ps * 1.5, 20)
                    .into_iter()
                    .map(|s| (s, slope * s))
                    .collect(),
            ));
        }
        c.error_bars.push(ErrorSeries {
            name: format!("simulation, {} (mean ± sd)", w.name()),
            points: of_w
                .iter()
                .map(|p| {
                    let (m, sd) = mean_sd(&p.floors_um);
                    (p.sigma_i_ps, m, sd)
                })
                .collect(),
        });
        // The printed values (rectangular: the paper's; Blackman: corrected), at N = 10^6.
        let printed: Vec<(f64, f64)> = fig4::POINTS
            .iter()
            .map(|&(s, paper, blackman)| {
                (
                    s,
                    if w == Window::Rectangular {
                        paper
                    } else {
                        blackman
                    },
                )
            })
            .collect();
        let who = if w == Window::Rectangular {
            "paper (rectangular)"
        } else {
            "corrected (Blackman)"
        };
        c.notes.push(format!(
            "{who}: {} µm at N = {}",
            printed
                .iter()
                .map(|p| format!("{}", p.1))
                .collect::<Vec<_>>()
                .join(" / "),
            fig4::N
        ));
        c.points.push(Series::new(who, printed));
    }
    c.notes.push(format!(
        "σ_I = {} ps",
        fig4::POINTS
            .iter()
            .map(|p| format!("{}", p.0))
            .collect::<Vec<_>>()
            .join(" / ")
    ));
    if quick {
        c.notes.push(QUICK_NOTE.into());
    }
    c
}

/// The note of a `--quick` figure.
pub const QUICK_NOTE: &str =
    "QUICK RUN: short records; the paper's values are for its full-length records";

/// The exact corner of the 1NN hold against ρ (Hz), |H|² = 1/2, over `rhos` in (0, 1).
pub fn hold_corner_curve(rhos: &[f64]) -> Vec<(f64, f64)> {
    rhos.iter()
        .filter_map(|&r| hold_bandwidth_hz(r, FS_HZ).map(|f| (r, f / 1e3)))
        .collect()
}

/// Fig. 6: the hold's 3 dB point against ρ_s: the exact mean response, the paper's ZOH
/// approximation, the measured corners (mean ± sd over the seeds), the printed values.
pub fn fig6(corners: &[Vec<f64>], quick: bool) -> Chart {
    let rhos = geomspace(5e-4, 0.2, 40);
    let pts = bandwidth::POINTS;
    let mut c = Chart {
        file: "fig6_hold_bandwidth.svg".into(),
        title: format!(
            "Fig. 6: 1NN hold 3 dB point vs ρ_s (f_s = 10 MHz, {} seeds)",
            SEEDS.len()
        ),
        x_label: "ρ_s".into(),
        y_label: "f_3dB (kHz)".into(),
        x_log: true,
        y_log: true,
        lines: vec![
            Series::new(
                "exact: |H|² = ρ²/(1 − 2(1−ρ)cos ω + (1−ρ)²) = 1/2",
                hold_corner_curve(&rhos),
            ),
            Series::new(
                "the paper: ZOH approx. 0.44/((2/ρ+1)T_s)",
                rhos.iter()
                    .map(|&r| (r, zoh_hold_f3db(r, FS_HZ) / 1e3))
                    .collect(),
            ),
        ],
        error_bars: vec![ErrorSeries {
            name: "simulation (mean ± sd)".into(),
            points: pts
                .iter()
                .zip(corners)
                .map(|(p, f)| {
                    let (m, sd) = mean_sd(f);
                    (p.0, m / 1e3, sd / 1e3)
                })
                .collect(),
        }],
        points: vec![
            Series::new("paper", pts.iter().map(|p| (p.0, p.1)).collect()),
            Series::new("corrected", pts.iter().map(|p| (p.0, p.2)).collect()),
        ],
        ..Chart::default()
    };
    for (p, f) in pts.iter().zip(corners) {
        let (m, sd) = mean_sd(f);
        c.notes.push(format!(
            "ρ_s = {}: measured {:.2} ± {:.2} kHz; exact {:.2}; paper {} (corrected {}){}",
            p.0,
            m / 1e3,
            sd / 1e3,
            hold_bandwidth_hz(p.0, FS_HZ).unwrap_or(0.0) / 1e3,
            p.1,
            p.2,
            if quick { "; quick records" } else { "" }
        ));
    }
    c.legend = Legend::UpperLeft;
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use tofprobe_dsp::closed_form::hold_response_sq;

    /// Fig. 6's curve: at each plotted corner the hold's mean response (an independent
    /// closed form) is exactly half power (1e-9: the asin inversion in f64), and the curve
    /// reads DESIGN.md's 167.8 / 16.0 / 1.59 kHz to their printed rounding.
    #[test]
    fn fig6_corner_is_the_half_power_point() {
        let pts = hold_corner_curve(&[0.1, 0.01, 0.001]);
        for &(rho, khz) in &pts {
            let w = 2.0 * std::f64::consts::PI * khz * 1e3 / FS_HZ;
            assert!((hold_response_sq(rho, w) - 0.5).abs() < 1e-9, "{rho}");
        }
        for ((_, khz), (want, half_ulp)) in
            pts.iter().zip([(167.8, 0.05), (16.0, 0.05), (1.59, 0.005)])
        {
            assert!((khz - want).abs() <= half_ulp, "{khz} vs {want}");
        }
        // The ZOH approximation is not the exact corner (the paper's 168.4 vs 167.8).
        assert!(hold_corner_curve(&[1.0, 0.0]).is_empty());
    }

    /// Fig. 2: the order-3 shaping puts the noise out of band: the measured in-band SNR is
    /// tens of dB above the whole-band (f_s/2) SNR, and below eq. 4's ideal value (the
    /// H_inf = 1.5 NTF, module doc of `quality`).
    #[test]
    fn fig2_shows_noise_shaping() {
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        let t = probe_spectrum(&m, 0.5).unwrap();
        let in_band = t.snr_db(0.5 / 32.0);
        let full = t.snr_db(0.5);
        eprintln!("in-band {in_band} dB, full band {full} dB");
        assert!(in_band > full + 30.0, "{in_band} vs {full}");
        assert!(in_band < eq4_snr_db(3, 32.0, 0.5));
        let chart = fig2(&m, 0.5).unwrap();
        // No clamp drawn as data: the old figure drew every group below 1e-20 at exactly
        // −200 dB (a flat line the shaping does not make). The shaped floor near DC goes
        // below that, so real points lie under −200 dB and none sits at the clamp.
        let ys: Vec<f64> = chart.lines[0].points.iter().map(|p| p.1).collect();
        assert!(ys.iter().all(|&y| y != -200.0 && y.is_finite()));
        assert!(ys.iter().any(|&y| y < -200.0), "{:?}", &ys[..8]);
        let svg = chart.render().unwrap();
        assert!(svg.contains("156.25 kHz") && svg.contains("297 kHz"));
        assert_eq!(
            super::super::svg_check::problems(&svg),
            Vec::<String>::new()
        );
    }
}
