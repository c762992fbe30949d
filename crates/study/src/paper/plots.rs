//! Table 2's own plots: the spectra of the ρ_s sweep (seed 0) and the noise floor versus
//! σ_s (mean ± sd over the seeds) with the closed form and the paper's values beside.

use super::chart::{Chart, ErrorSeries, Series};
use super::stats::{SEEDS, mean_sd};
use super::table2::RowResult;

/// spectra.svg and noise_vs_sigma.svg.
pub fn charts(results: &[RowResult], quick: bool) -> Vec<Chart> {
    // Spectra of the σ_s = 7.5 mm tone rows without background (ρ_s = 1, 0.3, 0.1, 0.03).
    let spectra: Vec<Series> = results
        .iter()
        .filter(|r| r.spec.sigma_s_mm == 7.5 && r.spec.rho_b == 0.0 && r.spec.amp_um.is_some())
        .map(|r| Series::new(format!("ρ_s = {}", r.spec.rho_s), r.spectrum.clone()))
        .collect();
    let spectra = Chart {
        file: "spectra.svg".into(),
        title: "Table 2: Blackman DFT of the held depth, 100 µm at 4.5 kHz, σ_s = 7.5 mm (seed 0)"
            .into(),
        x_label: "frequency (Hz)".into(),
        y_label: "|Y| (µm)".into(),
        x_log: true,
        y_log: true,
        lines: spectra,
        ..Chart::default()
    };
    let mut chosen: Vec<&RowResult> = results
        .iter()
        .filter(|r| r.spec.rho_s == 1.0 && r.spec.amp_um.is_none())
        .collect();
    chosen.sort_by(|a, b| a.spec.sigma_s_mm.total_cmp(&b.spec.sigma_s_mm));
    let mut noise = Chart {
        file: "noise_vs_sigma.svg".into(),
        title: format!(
            "Table 2: noise floor vs σ_s (ρ_s = 1, no tone, Blackman, {} seeds)",
            SEEDS.len()
        ),
        x_label: "σ_s (mm)".into(),
        y_label: "noise floor (µm)".into(),
        x_log: true,
        y_log: true,
        lines: vec![Series::new(
            "closed form",
            chosen
                .iter()
                .map(|r| (r.spec.sigma_s_mm, r.closed_form_um))
                .collect(),
        )],
        error_bars: vec![ErrorSeries {
            name: "simulation (mean ± sd)".into(),
            points: chosen
                .iter()
                .map(|r| {
                    let (m, sd) = mean_sd(&r.noises_um);
                    (r.spec.sigma_s_mm, m, sd)
                })
                .collect(),
        }],
        ..Chart::default()
    };
    {
        noise.points.push(Series::new(
            "paper",
            chosen
                .iter()
                .map(|r| (r.spec.sigma_s_mm, r.spec.paper_noise_um))
                .collect(),
        ));
        noise.notes.push(format!(
            "paper: {} µm",
            chosen
                .iter()
                .map(|r| format!("{}", r.spec.paper_noise_um))
                .collect::<Vec<_>>()
                .join(" / ")
        ));
        if quick {
            noise.notes.push(super::figures::QUICK_NOTE.into());
        }
    }
    vec![spectra, noise]
}
