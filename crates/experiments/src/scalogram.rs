//! The Haar scalogram as an SVG heat map and as JSON.
//!
//! The heat map: time across (ms), scale down (u = 0, the whole frame, on top; U at the
//! bottom), each coefficient a rectangle over its wavelet's support, so a coarse
//! coefficient covers the 2^(U−u) finest cells below it. A diverging colour scale (blue
//! for w < 0, a depth increase; white at 0; red for w > 0, a depth decrease), symmetric
//! about 0 at ±max|w|, with a colour bar in mm. The row labels give the scale and its
//! wavelet duration T/2^u. Events, when given, outline their peak coefficient in black.
//!
//! The JSON form is the [`ScalogramDocument`]: the scalogram (N, U, f_s and each
//! coefficient's u, v, value_mm, start_s, end_s) and, if given, the events.

use std::path::Path;

use serde::Serialize;
use tofprobe_dsp::haar::{EventReport, Scalogram};
use tofprobe_io::chart::prelude::*;

use tofprobe_eda::error::{EdaError, Result};

/// Diverging blue–white–red for x in [−1, 1].
pub fn diverging(x: f64) -> RGBColor {
    let x = if x.is_finite() {
        x.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    // White to (178, 24, 43) for x > 0, white to (33, 102, 172) for x < 0 (ColorBrewer
    // RdBu ends): linear in each half keeps 0 white and the sign readable.
    let (r, g, b) = if x >= 0.0 {
        (178.0, 24.0, 43.0)
    } else {
        (33.0, 102.0, 172.0)
    };
    let a = x.abs();
    let mix = |c: f64| (255.0 + (c - 255.0) * a).round() as u8;
    RGBColor(mix(r), mix(g), mix(b))
}

fn check(s: &Scalogram) -> std::result::Result<f64, String> {
    if s.coefficients.is_empty() {
        return Err("the scalogram has no coefficients".into());
    }
    if let Some(c) = s
        .coefficients
        .iter()
        .find(|c| !(c.value_mm.is_finite() && c.start_s.is_finite() && c.end_s.is_finite()))
    {
        return Err(format!(
            "coefficient ({}, {}) is not finite: {} mm over {}..{} s",
            c.u, c.v, c.value_mm, c.start_s, c.end_s
        ));
    }
    let vmax = s
        .coefficients
        .iter()
        .map(|c| c.value_mm.abs())
        .fold(0.0, f64::max);
    Ok(if vmax > 0.0 { vmax } else { 1.0 })
}

/// Renders the scalogram (and optionally its events) as SVG text.
pub fn scalogram_svg(
    s: &Scalogram,
    title: &str,
    events: Option<&EventReport>,
) -> std::result::Result<String, String> {
    scalogram_svg_with_notes(s, title, events, &[])
}

/// Height of one note line under the heat map (px; 14 px text).
const NOTE_H: u32 = 20;

/// [`scalogram_svg`] with text lines under the heat map (the paper's values beside the
/// measured ones, in the reproduction's Fig. 3 and Fig. 12).
pub fn scalogram_svg_with_notes(
    s: &Scalogram,
    title: &str,
    events: Option<&EventReport>,
    notes: &[String],
) -> std::result::Result<String, String> {
    let vmax = check(s)?;
    let u_max = s.scales;
    let t_ms = s.duration_s() * 1e3;
    let map_h = 80 + 50 * (u_max + 1);
    let size = (1000, map_h + NOTE_H * notes.len() as u32 + 8);
    svg(size, |root| {
        let (upper, lower) = root.split_vertically(map_h);
        for (i, note) in notes.iter().enumerate() {
            lower.draw(&Text::new(
                note.clone(),
                (20, (NOTE_H * i as u32) as i32),
                ("sans-serif", 14).into_font().color(&BLACK),
            ))?;
        }
        let (main, bar) = upper.split_horizontally(880);
        // Row u spans y ∈ [U − u − ½, U − u + ½]: integer ticks fall on the row centres.
        let y_top = f64::from(u_max) + 0.5;
        let frame = Frame::new(title, 18)
            .label_areas(40, 130)
            .axes("time (ms)", "scale (wavelet duration)")
            .fonts(14, Some(15))
            .without_grid();
        let mut chart = frame.build(&main, 0.0..t_ms, -0.5..y_top)?;
        let row_label = move |y: &f64| {
            let k = y.round();
            if (y - k).abs() > 1e-6 || k < 0.0 || k > f64::from(u_max) {
                return String::new();
            }
            let u = u_max - k as u32;
            let d = t_ms / (1u64 << u) as f64;
            format!("u = {u} ({d:.3} ms)")
        };
        frame
            .mesh(&mut chart)
            .y_labels(u_max as usize + 2)
            .y_label_formatter(&row_label)
            .draw()?;
        let row = |u: u32| f64::from(u_max - u);
        chart.draw_series(s.coefficients.iter().map(|c| {
            let y = row(c.u);
            Rectangle::new(
                [(c.start_s * 1e3, y - 0.5), (c.end_s * 1e3, y + 0.5)],
                diverging(c.value_mm / vmax).filled(),
            )
        }))?;
        if let Some(ev) = events {
            chart.draw_series(ev.events.iter().map(|v| {
                let c = &v.peak;
                let y = row(c.u);
                Rectangle::new(
                    [(c.start_s * 1e3, y - 0.5), (c.end_s * 1e3, y + 0.5)],
                    BLACK.stroke_width(2),
                )
            }))?;
        }
        // Colour bar: 100 strips from −max|w| to +max|w| (the bar's explicit font sizes:
        // plotters scales its default label font with the area, which made the narrow
        // colour bar's labels 4 px).
        ColourBar {
            range: (-vmax, vmax),
            desc: "w (mm)",
            label_area: 70,
            strips: 100,
            ticks: Some((7, &|y: &f64| format!("{y:+.3}"))),
        }
        .draw(&bar, |lo, hi| diverging(0.5 * (lo + hi) / vmax))
    })
    .map_err(|e| e.to_string())
}

/// Writes the scalogram SVG to `path` atomically.
pub fn write_scalogram_svg(
    s: &Scalogram,
    title: &str,
    events: Option<&EventReport>,
    path: &Path,
) -> Result<()> {
    let svg = scalogram_svg(s, title, events).map_err(|reason| EdaError::Plot {
        path: path.to_path_buf(),
        reason,
    })?;
    tofprobe_io::write_svg_atomic(path, svg.as_bytes())
        .map_err(|e| EdaError::io("writing", path, e))
}

/// The JSON document of a scalogram and its events.
#[derive(Debug, Clone, Serialize)]
pub struct ScalogramDocument<'a> {
    pub scalogram: &'a Scalogram,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub events: Option<&'a EventReport>,
}

/// The scalogram (and events) as pretty JSON; refuses non-finite values (JSON has none).
pub fn scalogram_json(s: &Scalogram, events: Option<&EventReport>) -> Result<String> {
    check(s).map_err(|reason| EdaError::OutOfRange {
        field: "scalogram",
        value: reason,
        allowed: "finite coefficients and times".into(),
    })?;
    serde_json::to_string_pretty(&ScalogramDocument {
        scalogram: s,
        events,
    })
    .map_err(|source| EdaError::Json {
        what: "the Haar scalogram".into(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use tofprobe_dsp::haar::{HaarNoise, Thresholds, detect_events};

    fn step() -> (Scalogram, EventReport) {
        let n = 1024;
        let x: Vec<f64> = (0..n).map(|i| if i >= 300 { 2.0 } else { 0.0 }).collect();
        let s = Scalogram::from_depths_mm(&x, 5, 1e7).unwrap();
        let t = Thresholds::new(&HaarNoise::new(0.05, 1.0).unwrap(), n, 5, 0.01).unwrap();
        let ev = detect_events(&s, &t).unwrap();
        (s, ev)
    }

    /// One rectangle per coefficient (63) plus 100 colour-bar strips plus one event
    /// outline; the row labels name scale and duration; no NaN reaches the file.
    #[test]
    fn svg_has_every_coefficient_and_the_colour_bar() {
        let (s, ev) = step();
        let svg = scalogram_svg(&s, "step", Some(&ev)).unwrap();
        assert!(svg.starts_with("<svg"));
        let rects = svg.matches("<rect").count();
        // + the background fill of the root.
        assert!(rects > 63 + 100, "{rects} rects");
        assert!(svg.contains("u = 5 (0.003 ms)"), "row label");
        assert!(svg.contains("time (ms)") && svg.contains("w (mm)"));
        assert!(!svg.contains("NaN"));
        // The deepest colours are the extremes: w(5,9) = −0.75 is not the max; the max
        // |w| is at a coarser scale; its colour is the full blue end.
        assert!(
            svg.contains("#2166AC") || svg.contains("#2166ac"),
            "full blue present"
        );
        let mut bad = s.clone();
        bad.coefficients[3].value_mm = f64::NAN;
        assert!(scalogram_svg(&bad, "bad", None).is_err());
        assert!(scalogram_json(&bad, None).is_err());
    }

    #[test]
    fn colour_scale_is_diverging() {
        assert_eq!(diverging(0.0), RGBColor(255, 255, 255));
        assert_eq!(diverging(1.0), RGBColor(178, 24, 43));
        assert_eq!(diverging(-1.0), RGBColor(33, 102, 172));
        assert_eq!(diverging(f64::NAN), RGBColor(255, 255, 255));
        assert_eq!(diverging(7.0), diverging(1.0));
    }

    /// The JSON round-trips: coefficients with u, v, value_mm, start_s, end_s, and the
    /// events with their times and rates.
    #[test]
    fn json_round_trips() {
        let (s, ev) = step();
        let j = scalogram_json(&s, Some(&ev)).unwrap();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        let back: Scalogram = serde_json::from_value(v["scalogram"].clone()).unwrap();
        assert_eq!(back, s);
        let c = &v["scalogram"]["coefficients"][0];
        for k in ["u", "v", "value_mm", "start_s", "end_s"] {
            assert!(c.get(k).is_some(), "{k}");
        }
        let evs: EventReport = serde_json::from_value(v["events"].clone()).unwrap();
        assert_eq!(evs, ev);
        assert_eq!(v["events"]["events"][0]["change"], "increase");
    }
}
