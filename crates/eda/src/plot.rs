//! The sweep plot: area and f_max against B (at the configured W) and against W (at the
//! configured B), as one SVG of four panels.

use crate::error::{EdaError, Result};
use crate::size_report::SizeReport;
use std::path::Path;
use tofprobe_io::chart::prelude::*;

type Series = Vec<(f64, f64)>;

fn panel(
    area: &Root<'_>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(&str, Series, RGBColor)],
) -> std::result::Result<(), ChartError> {
    let pts: Vec<(f64, f64)> = series.iter().flat_map(|s| s.1.iter().copied()).collect();
    if pts.is_empty() {
        area.titled(&format!("{title}: no data"), ("sans-serif", 16))?;
        return Ok(());
    }
    let (x0, x1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let y1 = pts.iter().fold(0.0f64, |a, p| a.max(p.1));
    let pad = if x1 > x0 { 0.05 * (x1 - x0) } else { 1.0 };
    let frame = Frame::new(title, 16)
        .margin(8)
        .label_areas(35, 60)
        .axes(x_label, y_label);
    let mut chart = frame.build(area, (x0 - pad)..(x1 + pad), 0.0..(y1 * 1.1).max(1e-9))?;
    frame.draw_mesh(&mut chart)?;
    for (name, s, color) in series {
        if s.is_empty() {
            continue;
        }
        let c = *color;
        chart
            .draw_series(LineSeries::new(s.iter().copied(), c.stroke_width(2)))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
        chart.draw_series(PointSeries::of_element(
            s.iter().copied(),
            4,
            c.filled(),
            &|p, sz, st| EmptyElement::at(p) + Circle::new((0, 0), sz, st),
        ))?;
    }
    legend(&mut chart, SeriesLabelPosition::MiddleRight, 0.8, None)
}

/// Renders the sweep plot as SVG text.
pub fn sweep_svg(report: &SizeReport) -> std::result::Result<String, String> {
    let d = &report.design;
    let mut b_rows: Vec<_> = report.sweep.iter().filter(|r| r.width == d.width).collect();
    b_rows.sort_by_key(|r| r.bins);
    let mut w_rows: Vec<_> = report.sweep.iter().filter(|r| r.bins == d.bins).collect();
    w_rows.sort_by_key(|r| r.width);
    let lib = report.area.library.clone();
    let area_b: Series = b_rows.iter().map(|r| (r.bins as f64, r.area_um2)).collect();
    let sky_b: Series = b_rows
        .iter()
        .filter_map(|r| r.sky130_area_um2.map(|a| (r.bins as f64, a)))
        .collect();
    let fmax_b: Series = b_rows
        .iter()
        .filter_map(|r| r.f_max_mhz.map(|f| (r.bins as f64, f)))
        .collect();
    let area_w: Series = w_rows
        .iter()
        .map(|r| (f64::from(r.width), r.area_um2))
        .collect();
    let fmax_w: Series = w_rows
        .iter()
        .filter_map(|r| r.f_max_mhz.map(|f| (f64::from(r.width), f)))
        .collect();
    svg((1100, 760), |root| {
        let panels = root.split_evenly((2, 2));
        panel(
            &panels[0],
            &format!("area vs B (W = {})", d.width),
            "bins B",
            "area (µm²)",
            &[
                (lib.as_str(), area_b, BLUE),
                ("sky130 hd (area only)", sky_b, RED),
            ],
        )?;
        panel(
            &panels[1],
            &format!("f_max vs B (W = {})", d.width),
            "bins B",
            "f_max (MHz)",
            &[(lib.as_str(), fmax_b, BLUE)],
        )?;
        panel(
            &panels[2],
            &format!("area vs W (B = {})", d.bins),
            "register width W (bits)",
            "area (µm²)",
            &[(lib.as_str(), area_w, BLUE)],
        )?;
        panel(
            &panels[3],
            &format!("f_max vs W (B = {})", d.bins),
            "register width W (bits)",
            "f_max (MHz)",
            &[(lib.as_str(), fmax_w, BLUE)],
        )
    })
    .map_err(|e| e.to_string())
}

/// Writes the sweep plot to `path` atomically.
pub fn write_sweep_svg(report: &SizeReport, path: &Path) -> Result<()> {
    let svg = sweep_svg(report).map_err(|reason| EdaError::Plot {
        path: path.to_path_buf(),
        reason,
    })?;
    tofprobe_io::write_svg_atomic(path, svg.as_bytes())
        .map_err(|e| crate::EdaError::io("writing", path, e))
}
