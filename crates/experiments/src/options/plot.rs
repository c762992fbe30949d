//! The area/accuracy front as an SVG: area per bin on the front's library (x) against the
//! mean tone error over the seeds (y, log; the seeds' range as a bar), one labelled point
//! per option, the Pareto front joined by a line, the recommendation ringed and the
//! accuracy target drawn across.

use std::path::Path;

use tofprobe_io::chart::prelude::*;

use super::OptionsReport;
use crate::error::ExperimentError;

/// Label heights (factors of the point's error, log axis) for points of equal x.
const LABEL_STEPS: [f64; 4] = [1.12, 0.8, 0.6, 0.45];

/// The SVG text; `path` only names the file in errors.
pub fn front_svg(path: &Path, r: &OptionsReport) -> Result<String, ExperimentError> {
    let err = |e: &dyn std::fmt::Display| ExperimentError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let lib = r
        .rows
        .first()
        .map_or(0, |row| row.libraries.len().saturating_sub(1));
    // A zero error (an option exact on every seed) sits at the axis floor.
    let floor = 1e-4;
    let pts: Vec<(String, f64, f64, f64, f64, bool)> = r
        .rows
        .iter()
        .map(|row| {
            let e = &row.tone_error_um;
            (
                row.option.name.clone(),
                row.libraries[lib].model.per_bin_um2,
                e.mean.max(floor),
                e.min.max(floor),
                e.max.max(floor),
                row.on_front,
            )
        })
        .collect();
    if pts.is_empty() {
        return Err(err(&"no option to plot"));
    }
    let x0 = pts.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let x1 = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let y0 = pts.iter().map(|p| p.3).fold(r.target_error_um, f64::min);
    let y1 = pts.iter().map(|p| p.4).fold(r.target_error_um, f64::max);
    let pad = ((x1 - x0) * 0.15).max(x1.abs() * 0.05).max(1.0);
    let same_x = |i: usize| {
        pts[..i]
            .iter()
            .filter(|q| (q.1 - pts[i].1).abs() < 0.02 * (x1 - x0 + 1.0))
            .count()
    };
    svg((900, 560), |root| {
        let frame = Frame::new(
            format!(
                "area per bin ({}) vs tone error against the float DFT, B = {}",
                r.front_library, r.bins
            ),
            18,
        )
        .margin(12)
        .axes("area per bin (µm²)", "tone error vs float DFT (µm)");
        let mut chart = frame.build(root, x0 - pad..x1 + pad, (y0 / 2.0..y1 * 2.0).log_scale())?;
        frame.draw_mesh(&mut chart)?;
        let target = r.target_error_um;
        chart
            .draw_series(LineSeries::new(
                [(x0 - pad, target), (x1 + pad, target)],
                RED.stroke_width(1),
            ))?
            .label(format!("target {target} µm"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED));
        let mut front: Vec<(f64, f64)> = pts.iter().filter(|p| p.5).map(|p| (p.1, p.2)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, BLUE.stroke_width(2)))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLUE));
        for (i, p) in pts.iter().enumerate() {
            chart.draw_series(std::iter::once(PathElement::new(
                [(p.1, p.3), (p.1, p.4)],
                BLACK.mix(0.5),
            )))?;
            let colour = if p.5 { BLUE } else { BLACK };
            chart.draw_series(std::iter::once(Circle::new((p.1, p.2), 5, colour.filled())))?;
            chart
                // Options of (nearly) equal area per bin, like the baseline and one adder,
                // would print their labels over each other: the k-th such point's label
                // steps down.
                .draw_series(std::iter::once(Text::new(
                    p.0.clone(),
                    (p.1, p.2 * LABEL_STEPS[same_x(i) % LABEL_STEPS.len()]),
                    ("sans-serif", 12).into_font(),
                )))?;
            if p.0 == r.recommendation.option {
                chart.draw_series(std::iter::once(Circle::new(
                    (p.1, p.2),
                    10,
                    GREEN.stroke_width(2),
                )))?;
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 1.0, None)
    })
    .map_err(|e| err(&e))
}
