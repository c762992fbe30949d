//! The Pareto plot of the trade: wall time per simulated second (log x) against the
//! amplitude error versus the scene's true amplitude (log y), one point per level and
//! scene; the cheapest level that is accurate enough is the leftmost point low enough.

use std::path::Path;

use tofprobe_io::chart::prelude::*;

use super::SceneResult;
use crate::error::ExperimentError;

/// Writes the SVG atomically; levels without a tone amplitude are left out.
pub fn pareto_svg(path: &Path, scenes: &[SceneResult]) -> Result<(), ExperimentError> {
    tofprobe_io::write_svg_atomic(path, pareto_svg_text(path, scenes)?.as_bytes()).map_err(|e| {
        ExperimentError::Output {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    })
}

/// The text of [`pareto_svg`], for a caller that writes it as part of a set of files;
/// `path` only names the file in errors.
pub fn pareto_svg_text(path: &Path, scenes: &[SceneResult]) -> Result<String, ExperimentError> {
    let err = |e: &dyn std::fmt::Display| ExperimentError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let pts: Vec<(String, f64, f64)> = scenes
        .iter()
        .flat_map(|s| {
            s.levels.iter().filter_map(|l| {
                l.amplitude_err_vs_true_um.map(|e| {
                    (
                        l.level.clone(),
                        l.seconds_per_sim_second.max(1e-9),
                        e.max(1e-3),
                    )
                })
            })
        })
        .collect();
    if pts.is_empty() {
        return Err(err(&"no level with a tone amplitude to plot"));
    }
    let (x0, x1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let (y0, y1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.2), b.max(p.2)));
    svg((900, 560), |root| {
        let frame = Frame::new(
            "speed/accuracy: wall s per simulated s vs amplitude error",
            20,
        )
        .margin(12)
        .axes("wall seconds per simulated second", "|A − A_true| (µm)");
        let mut chart = frame.build(
            root,
            (x0 / 3.0..x1 * 3.0).log_scale(),
            (y0 / 3.0..y1 * 3.0).log_scale(),
        )?;
        frame.draw_mesh(&mut chart)?;
        let mut names: Vec<String> = pts.iter().map(|p| p.0.clone()).collect();
        names.dedup();
        names.sort();
        names.dedup();
        for (i, name) in names.iter().enumerate() {
            let c = Palette99::pick(i).to_rgba();
            let series: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| &p.0 == name)
                .map(|p| (p.1, p.2))
                .collect();
            chart
                .draw_series(series.iter().map(|&p| Circle::new(p, 6, c.filled())))?
                .label(name.as_str())
                .legend(move |(x, y)| Circle::new((x, y), 5, c.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::MiddleRight, 1.0, None)
    })
    .map_err(|e| err(&e))
}
