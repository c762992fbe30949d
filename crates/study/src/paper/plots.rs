//! SVG plots (plotters) of the reproduce results: Table 2 spectra, and the noise floor
//! versus σ_s and versus ρ_s with the closed form beside the simulation.

use std::path::Path;

use plotters::prelude::*;

use super::table2::RowResult;
use crate::StudyError;
use crate::spectrum::write_atomic;

fn plot_err(path: &Path, e: impl std::fmt::Display) -> StudyError {
    StudyError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Renders one log-log chart of several series (lines) and point sets, then writes it.
#[allow(clippy::type_complexity)]
fn loglog(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    lines: &[(String, Vec<(f64, f64)>)],
    points: &[(String, Vec<(f64, f64)>)],
) -> Result<(), StudyError> {
    let all = lines.iter().chain(points).flat_map(|(_, v)| v.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all.filter(|p| p.0 > 0.0 && p.1 > 0.0) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 >= x1 || y0 >= y1 {
        return Err(plot_err(path, "no positive data to plot"));
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (x0 * 0.9..x1 * 1.1).log_scale(),
                (y0 * 0.8..y1 * 1.25).log_scale(),
            )
            .map_err(|e| plot_err(path, e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        for (i, (name, v)) in lines.iter().enumerate() {
            let c = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(v.iter().copied(), c))
                .map_err(|e| plot_err(path, e))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
        }
        for (i, (name, v)) in points.iter().enumerate() {
            let c = Palette99::pick(i + lines.len()).to_rgba();
            chart
                .draw_series(v.iter().map(|&p| Circle::new(p, 4, c.filled())))
                .map_err(|e| plot_err(path, e))?
                .label(name.as_str())
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, c.filled()));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        root.present().map_err(|e| plot_err(path, e))?;
    }
    write_atomic(path, svg.as_bytes())
}

/// Writes spectra.svg, noise_vs_sigma.svg and noise_vs_rho.svg into `dir`; returns the
/// paths written.
pub fn write_all(dir: &Path, results: &[RowResult]) -> Result<Vec<String>, StudyError> {
    std::fs::create_dir_all(dir).map_err(|source| StudyError::Io {
        path: dir.display().to_string(),
        source,
    })?;
    let mut written = Vec::new();
    // Spectra of the σ_s = 7.5 mm tone rows without background (ρ_s = 1, 0.3, 0.1, 0.03).
    let spectra: Vec<(String, Vec<(f64, f64)>)> = results
        .iter()
        .filter(|r| r.spec.sigma_s_mm == 7.5 && r.spec.rho_b == 0.0 && r.spec.amp_um.is_some())
        .map(|r| (format!("ρ_s = {}", r.spec.rho_s), r.spectrum.clone()))
        .collect();
    let p = dir.join("spectra.svg");
    loglog(
        &p,
        "Table 2: Blackman DFT of the held depth, 100 µm at 4.5 kHz, σ_s = 7.5 mm",
        "frequency (Hz)",
        "|Y| (µm)",
        &spectra,
        &[],
    )?;
    written.push(p.display().to_string());

    type Sel = fn(&RowResult) -> bool;
    type Abscissa = fn(&RowResult) -> f64;
    /// (file, title, x label, which rows, x of a row)
    type Family = (&'static str, &'static str, &'static str, Sel, Abscissa);
    let families: [Family; 2] = [
        (
            "noise_vs_sigma.svg",
            "Noise floor vs σ_s (ρ_s = 1, no tone, N = 10^7, Blackman)",
            "σ_s (mm)",
            |r| r.spec.rho_s == 1.0 && r.spec.amp_um.is_none(),
            |r| r.spec.sigma_s_mm,
        ),
        (
            "noise_vs_rho.svg",
            "Noise floor vs ρ_s (σ_s = 7.5 mm, ρ_b = 0, 1NN hold)",
            "ρ_s",
            |r| r.spec.sigma_s_mm == 7.5 && r.spec.rho_b == 0.0 && r.spec.amp_um.is_some(),
            |r| r.spec.rho_s,
        ),
    ];
    for (file, title, xl, sel, x) in families {
        let mut chosen: Vec<&RowResult> = results.iter().filter(|r| sel(r)).collect();
        chosen.sort_by(|a, b| x(a).total_cmp(&x(b)));
        let closed: Vec<(f64, f64)> = chosen.iter().map(|r| (x(r), r.closed_form_um)).collect();
        let sim: Vec<(f64, f64)> = chosen
            .iter()
            .map(|r| (x(r), r.columns[0].1.noise_um))
            .collect();
        let paper: Vec<(f64, f64)> = chosen
            .iter()
            .map(|r| (x(r), r.spec.paper_noise_um))
            .collect();
        let p = dir.join(file);
        loglog(
            &p,
            title,
            xl,
            "noise floor (µm)",
            &[("closed form".into(), closed)],
            &[("simulation".into(), sim), ("paper".into(), paper)],
        )?;
        written.push(p.display().to_string());
    }
    Ok(written)
}
