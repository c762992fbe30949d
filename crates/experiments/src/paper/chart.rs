//! One chart description for every reproduce figure (lines, markers, mean ± sd error bars,
//! labelled vertical marks and text notes such as the paper's printed values), rendered to
//! SVG text by plotters on linear or logarithmic axes. Rendering never writes a file: the
//! reproduction stages every figure into one output set (`reproduce`), whole or absent.

use tofprobe_io::chart::plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use tofprobe_io::chart::prelude::*;

use crate::ExperimentError;

/// (x, y) points of one curve.
pub type Curve = Vec<(f64, f64)>;

/// A named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points,
        }
    }
}

/// A named set of (x, mean, sd) points drawn as a marker with a ±sd bar.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorSeries {
    pub name: String,
    pub points: Vec<(f64, f64, f64)>,
}

/// One figure: everything drawn, and the file it is staged as.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chart {
    /// File name inside the output directory (a plain name).
    pub file: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    /// Drawn as lines.
    pub lines: Vec<Series>,
    /// Drawn as markers (e.g. the paper's printed values).
    pub points: Vec<Series>,
    pub error_bars: Vec<ErrorSeries>,
    /// Labelled vertical lines (band edges, 3 dB points).
    pub marks: Vec<(String, f64)>,
    /// Text lines printed under the chart (the paper's values, the measured ones).
    pub notes: Vec<String>,
    /// Preferred corner of the legend; another corner is taken when a data marker would
    /// sit under the box there (`legend_corner`).
    pub legend: Legend,
    /// Tick values of a logarithmic x axis (e.g. the swept ρ_s); empty: 1-2-5 per decade.
    pub x_ticks: Vec<f64>,
}

/// Where the legend box goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    #[default]
    LowerLeft,
    LowerRight,
    UpperLeft,
    UpperRight,
}

impl Legend {
    const ALL: [Legend; 4] = [
        Legend::LowerLeft,
        Legend::LowerRight,
        Legend::UpperLeft,
        Legend::UpperRight,
    ];

    fn position(self) -> SeriesLabelPosition {
        match self {
            Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
            Legend::LowerRight => SeriesLabelPosition::LowerRight,
            Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
            Legend::UpperRight => SeriesLabelPosition::UpperRight,
        }
    }
}

/// Distinct colours (the Tableau 10 set), in drawing order.
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(127, 127, 127),
];

/// A short tick label: 3 significant digits, trailing zeros dropped, exponent form only
/// outside 1e-3..1e6.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        return format!("{v:.0e}");
    }
    let digits = if a == 0.0 {
        0
    } else {
        (2 - a.log10().floor() as i32).max(0) as usize
    };
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Ticks of a log axis over [lo, hi]: the `wanted` values inside it and the 1-2-5 values of
/// each decade not within a factor 1.4 of one of them (their labels would overprint), or
/// 1…9 per decade when the range is too short for three 1-2-5 ticks. Explicit ticks, and
/// no light lines: plotters' own log mesh draws a line per minor step (dense grey bands)
/// and labels too few of them (no label below 10 µm on a 3–100 µm axis).
pub fn log_ticks(lo: f64, hi: f64, wanted: &[f64]) -> Vec<f64> {
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let decade_values = |mantissas: &[f64]| -> Vec<f64> {
        let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (d0..=d1)
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(inside)
            .collect()
    };
    let mut ticks = decade_values(&[1.0, 2.0, 5.0]);
    if ticks.len() < 3 {
        ticks = decade_values(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    }
    let wanted: Vec<f64> = wanted.iter().copied().filter(inside).collect();
    ticks.retain(|t| wanted.iter().all(|w| (t / w).max(w / t) >= 1.4));
    ticks.extend(wanted);
    ticks.sort_by(f64::total_cmp);
    ticks.dedup();
    ticks
}

/// Smallest text of any figure (px at the size the file opens): the rendering check
/// (`svg_check`) refuses anything smaller.
pub const MIN_TEXT_PX: f64 = 8.0;

/// Height of the chart proper and of one note line (pixels).
const CHART_H: u32 = 600;
const LINE_H: u32 = 18;

fn plot_err(file: &str, e: impl std::fmt::Display) -> ExperimentError {
    ExperimentError::Plot {
        path: file.to_string(),
        message: e.to_string(),
    }
}

impl Chart {
    /// Every number the chart would draw, with where it comes from (for the finite check).
    fn values(&self) -> impl Iterator<Item = (&str, f64)> {
        let xy = |s: &'_ Series| {
            s.points
                .iter()
                .flat_map(|&(x, y)| [x, y])
                .collect::<Vec<_>>()
        };
        self.lines
            .iter()
            .chain(&self.points)
            .flat_map(move |s| xy(s).into_iter().map(move |v| (s.name.as_str(), v)))
            .chain(self.error_bars.iter().flat_map(|s| {
                s.points
                    .iter()
                    .flat_map(|&(x, m, d)| [x, m, d])
                    .map(move |v| (s.name.as_str(), v))
            }))
            .chain(self.marks.iter().map(|(n, v)| (n.as_str(), *v)))
    }

    /// The data range of one axis over every drawn element (positive values only on a
    /// log axis), padded.
    fn range(&self, x_axis: bool) -> Result<(f64, f64), ExperimentError> {
        let log = if x_axis { self.x_log } else { self.y_log };
        let mut v: Vec<f64> = Vec::new();
        for s in self.lines.iter().chain(&self.points) {
            v.extend(s.points.iter().map(|&(x, y)| if x_axis { x } else { y }));
        }
        for s in &self.error_bars {
            for &(x, m, d) in &s.points {
                if x_axis {
                    v.push(x);
                } else {
                    v.extend([m - d, m + d]);
                }
            }
        }
        if x_axis {
            v.extend(self.marks.iter().map(|m| m.1));
        }
        let v: Vec<f64> = v.into_iter().filter(|&a| !log || a > 0.0).collect();
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            return Err(plot_err(&self.file, "no data to plot on an axis"));
        }
        Ok(if log {
            let (lo, hi) = if lo == hi {
                (lo / 2.0, hi * 2.0)
            } else {
                (lo, hi)
            };
            (lo / 1.25, hi * 1.6)
        } else {
            let pad = if hi > lo { 0.06 * (hi - lo) } else { 1.0 };
            (lo - pad, hi + pad)
        })
    }

    /// Renders the chart as SVG text. Refuses a NaN or infinite value (naming its series):
    /// no output carries one.
    pub fn render(&self) -> Result<String, ExperimentError> {
        if let Some((name, v)) = self.values().find(|(_, v)| !v.is_finite()) {
            return Err(plot_err(
                &self.file,
                format!("series `{name}` holds {v}: every plotted value must be finite"),
            ));
        }
        let (x0, x1) = self.range(true)?;
        let (y0, y1) = self.range(false)?;
        let h = CHART_H + LINE_H * self.notes.len() as u32 + 8;
        svg((960, h), |root| {
            let (upper, lower) = root.split_vertically(CHART_H);
            let xk = || {
                (x0..x1)
                    .log_scale()
                    .with_key_points(log_ticks(x0, x1, &self.x_ticks))
            };
            let yk = || (y0..y1).log_scale().with_key_points(log_ticks(y0, y1, &[]));
            match (self.x_log, self.y_log) {
                (false, false) => self.draw(&upper, x0..x1, y0..y1),
                (true, false) => self.draw(&upper, xk(), y0..y1),
                (false, true) => self.draw(&upper, x0..x1, yk()),
                (true, true) => self.draw(&upper, xk(), yk()),
            }?;
            for (i, note) in self.notes.iter().enumerate() {
                lower.draw(&Text::new(
                    note.clone(),
                    (80, (LINE_H * i as u32) as i32),
                    ("sans-serif", 14).into_font().color(&BLACK),
                ))?;
            }
            Ok(())
        })
        .map_err(|e| plot_err(&self.file, e))
    }

    /// The legend's box (x0, y0, x1, y1 in pixels) in `corner` of the plotting area, as
    /// plotters lays it out for these entries at the 14 px label font (≈ 7 px a character,
    /// 18 px a row, a 10 px margin; estimated generously so that the check below errs
    /// towards moving the box).
    fn legend_box(&self, corner: Legend, xs: (i32, i32), ys: (i32, i32)) -> (i32, i32, i32, i32) {
        let names = self
            .lines
            .iter()
            .chain(&self.points)
            .map(|s| s.name.chars().count())
            .chain(self.error_bars.iter().map(|s| s.name.chars().count()));
        let rows = self.lines.len() + self.points.len() + self.error_bars.len();
        let w = 40 + 8 * names.max().unwrap_or(0) as i32;
        let h = 14 + 19 * rows as i32;
        let (m, left, top) = (
            10,
            matches!(corner, Legend::LowerLeft | Legend::UpperLeft),
            matches!(corner, Legend::UpperLeft | Legend::UpperRight),
        );
        let x0 = if left { xs.0 + m } else { xs.1 - m - w };
        let y0 = if top { ys.0 + m } else { ys.1 - m - h };
        (x0, y0, x0 + w, y0 + h)
    }

    /// The preferred corner unless a marker (error-bar mean, point) would sit under the
    /// legend there; then the first other corner that covers none (or the one covering
    /// fewest).
    fn legend_corner(&self, markers: &[(i32, i32)], xs: (i32, i32), ys: (i32, i32)) -> Legend {
        let covered = |c: Legend| {
            let (x0, y0, x1, y1) = self.legend_box(c, xs, ys);
            // A marker is ≈ 6 px across: one touching the box counts as covered.
            markers
                .iter()
                .filter(|&&(x, y)| x >= x0 - 6 && x <= x1 + 6 && y >= y0 - 6 && y <= y1 + 6)
                .count()
        };
        std::iter::once(self.legend)
            .chain(Legend::ALL.into_iter().filter(|&c| c != self.legend))
            .min_by_key(|&c| covered(c))
            .unwrap_or(self.legend)
    }

    fn draw<X, Y>(&self, root: &Root<'_>, xr: X, yr: Y) -> Result<(), ChartError>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let frame = Frame::new(self.title.as_str(), 19)
            .margin(14)
            .label_areas(44, 64)
            .axes(self.x_label.as_str(), self.y_label.as_str())
            .fonts(14, Some(15));
        let mut chart = frame.build(root, xr, yr)?;
        frame
            .mesh(&mut chart)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            // Grid lines at the labelled ticks only: plotters' light lines between them
            // drew dense grey bands on log axes.
            .light_line_style(TRANSPARENT)
            .draw()?;
        let (y_lo, y_hi) = {
            let r = chart.y_range();
            (r.start, r.end)
        };
        let mut colour = 0usize;
        let mut next = || {
            colour += 1;
            COLOURS[(colour - 1) % COLOURS.len()].to_rgba()
        };
        for s in &self.lines {
            let c = next();
            chart
                .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))?
                .label(s.name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
        }
        for s in &self.error_bars {
            let c = next();
            // A marker at the mean and a bar from mean − sd to mean + sd (clipped to the
            // axis on a log scale, where mean − sd may be ≤ 0).
            let bar = |&(x, m, d): &(f64, f64, f64)| {
                let lo = if self.y_log { (m - d).max(y_lo) } else { m - d };
                PathElement::new(vec![(x, lo), (x, m + d)], c.stroke_width(2))
            };
            chart.draw_series(s.points.iter().map(bar))?;
            chart
                .draw_series(
                    s.points
                        .iter()
                        .map(|&(x, m, _)| Circle::new((x, m), 4, c.filled())),
                )?
                .label(s.name.as_str())
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, c.filled()));
        }
        for s in &self.points {
            let c = next();
            chart
                .draw_series(
                    s.points
                        .iter()
                        .map(|&p| Cross::new(p, 6, c.stroke_width(2))),
                )?
                .label(s.name.as_str())
                .legend(move |(x, y)| Cross::new((x + 8, y), 5, c.stroke_width(2)));
        }
        for (i, (label, x)) in self.marks.iter().enumerate() {
            let c = BLACK.mix(0.6);
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(*x, y_lo), (*x, y_hi)],
                c.stroke_width(1),
            )))?;
            // Labels stacked down from the top so that close marks do not overprint.
            let (px, py) = chart.backend_coord(&(*x, y_hi));
            root.draw(&Text::new(
                label.clone(),
                (px + 4, py + 6 + 17 * i as i32),
                ("sans-serif", 13).into_font().color(&BLACK),
            ))?;
        }
        let markers: Vec<(i32, i32)> = self
            .error_bars
            .iter()
            .flat_map(|s| s.points.iter().map(|&(x, m, _)| (x, m)))
            .chain(self.points.iter().flat_map(|s| s.points.iter().copied()))
            .map(|p| chart.backend_coord(&p))
            .collect();
        let area = chart.plotting_area().get_pixel_range();
        let corner = self.legend_corner(
            &markers,
            (area.0.start, area.0.end),
            (area.1.start, area.1.end),
        );
        legend(&mut chart, corner.position(), 0.85, Some(14))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        Chart {
            file: "t.svg".into(),
            title: "T: a test".into(),
            x_label: "x (Hz)".into(),
            y_label: "y (µm)".into(),
            x_log: true,
            y_log: true,
            lines: vec![Series::new("closed form", vec![(1.0, 1.0), (10.0, 10.0)])],
            points: vec![Series::new("paper", vec![(2.0, 2.5)])],
            error_bars: vec![ErrorSeries {
                name: "mean ± sd".into(),
                points: vec![(3.0, 3.0, 0.5)],
            }],
            marks: vec![("edge 5 Hz".into(), 5.0)],
            notes: vec!["paper: 2.5 µm".into()],
            legend: Legend::UpperRight,
            x_ticks: Vec::new(),
        }
    }

    /// 1-2-5 per decade; wanted ticks replace the decade values next to them; a short range
    /// gets 1…9. Plotters' own log mesh left 3–10 unlabelled (the defect this replaces).
    #[test]
    fn log_ticks_label_every_decade_and_the_wanted_values() {
        assert_eq!(
            log_ticks(3.0, 100.0, &[]),
            vec![5.0, 10.0, 20.0, 50.0, 100.0]
        );
        assert_eq!(
            log_ticks(0.02, 1.2, &[0.03, 0.1, 0.3, 1.0]),
            vec![0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0]
        );
        assert_eq!(log_ticks(2.1, 4.5, &[]), vec![3.0, 4.0]);
        // A wanted value outside the axis is not drawn.
        assert_eq!(log_ticks(3.0, 40.0, &[100.0]), vec![5.0, 10.0, 20.0]);
    }

    /// A marker under the preferred corner moves the legend; with every corner free the
    /// preferred one stays.
    #[test]
    fn the_legend_avoids_markers() {
        let c = chart();
        let (xs, ys) = ((80, 940), (40, 540));
        assert_eq!(c.legend_corner(&[], xs, ys), Legend::UpperRight);
        let (x0, y0, x1, y1) = c.legend_box(Legend::UpperRight, xs, ys);
        let under = [((x0 + x1) / 2, (y0 + y1) / 2)];
        let moved = c.legend_corner(&under, xs, ys);
        assert_ne!(moved, Legend::UpperRight);
        let (a, b, cx, d) = c.legend_box(moved, xs, ys);
        assert!(!(under[0].0 >= a && under[0].0 <= cx && under[0].1 >= b && under[0].1 <= d));
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(&0.300_000_000_000_004), "0.3");
        assert_eq!(tick(&1000.0), "1000");
        assert_eq!(tick(&156.25), "156");
        assert_eq!(tick(&1e7), "1e7");
        assert_eq!(tick(&0.0), "0");
        assert_eq!(tick(&-20.0), "-20");
    }

    /// Every element reaches the SVG as text; a NaN anywhere is refused with its series.
    #[test]
    fn renders_text_and_refuses_non_finite() {
        let svg = chart().render().unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for t in [
            "T: a test",
            "x (Hz)",
            "closed form",
            "paper: 2.5 µm",
            "edge 5 Hz",
        ] {
            assert!(svg.contains(t), "{t}");
        }
        for (x_log, y_log) in [(false, false), (true, false), (false, true)] {
            let c = Chart {
                x_log,
                y_log,
                ..chart()
            };
            assert!(c.render().is_ok());
        }
        let mut bad = chart();
        bad.error_bars[0].points[0].2 = f64::NAN;
        let err = bad.render().unwrap_err().to_string();
        assert!(err.contains("mean ± sd") && err.contains("NaN"), "{err}");
        let empty = Chart {
            file: "e.svg".into(),
            ..Chart::default()
        };
        assert!(empty.render().is_err());
    }
}
