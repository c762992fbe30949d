//! Layout checks of a rendered figure, read back from its SVG text (what a reader's viewer
//! gets, not what the chart description meant): every text at least
//! [`MIN_TEXT_PX`] pixels high at the size the file opens
//! (font size × width / viewBox width), and no legend box over a data marker (a filled
//! circle or a cross of the chart's 2 px marker strokes drawn before the legend).
//!
//! The reader is line-based on plotters' SVG output (one element per line); an element it
//! does not know is ignored, so the checks can only miss a defect in an unknown element,
//! never invent one.

use super::chart::MIN_TEXT_PX;

/// An attribute's numeric value in one element's text.
fn attr(element: &str, name: &str) -> Option<f64> {
    let key = format!(" {name}=\"");
    let start = element.find(&key)? + key.len();
    let len = element[start..].find('"')?;
    element[start..start + len].trim().parse().ok()
}

/// The scale from user units to opened pixels: width / viewBox width (1 without a viewBox).
fn scale(svg: &str) -> f64 {
    let Some(head) = svg.lines().find(|l| l.trim_start().starts_with("<svg")) else {
        return 1.0;
    };
    let Some(width) = attr(head, "width") else {
        return 1.0;
    };
    let view_width = head
        .find(" viewBox=\"")
        .and_then(|i| head[i + 10..].split_whitespace().nth(2))
        .and_then(|w| w.trim_end_matches('"').parse::<f64>().ok());
    match view_width {
        Some(v) if v > 0.0 => width / v,
        _ => 1.0,
    }
}

/// Everything wrong with the figure's layout, one message each (empty: fine).
pub fn problems(svg: &str) -> Vec<String> {
    let k = scale(svg);
    let mut out = Vec::new();
    let lines: Vec<&str> = svg.lines().collect();
    let mut markers: Vec<(f64, f64)> = Vec::new();
    let mut legend: Option<(f64, f64, f64, f64)> = None;
    for (i, line) in lines.iter().enumerate() {
        let l = line.trim_start();
        if l.starts_with("<text") {
            let size = attr(l, "font-size").unwrap_or(16.0) * k;
            if size < MIN_TEXT_PX {
                let text = lines.get(i + 1).map_or("", |t| t.trim());
                out.push(format!(
                    "text `{text}` is {size:.1} px high (at least {MIN_TEXT_PX} px)"
                ));
            }
        } else if legend.is_none() && l.starts_with("<circle") && l.contains("stroke=\"none\"") {
            if let (Some(x), Some(y)) = (attr(l, "cx"), attr(l, "cy")) {
                markers.push((x, y));
            }
        } else if legend.is_none() && l.starts_with("<line") && l.contains("stroke-width=\"2\"") {
            if let (Some(x1), Some(y1), Some(x2), Some(y2)) =
                (attr(l, "x1"), attr(l, "y1"), attr(l, "x2"), attr(l, "y2"))
            {
                markers.push(((x1 + x2) / 2.0, (y1 + y2) / 2.0));
            }
        } else if legend.is_none()
            && l.starts_with("<rect")
            && l.contains("opacity=\"0.85\"")
            && l.contains("fill=\"#FFFFFF\"")
            && let (Some(x), Some(y), Some(w), Some(h)) = (
                attr(l, "x"),
                attr(l, "y"),
                attr(l, "width"),
                attr(l, "height"),
            )
        {
            legend = Some((x, y, x + w, y + h));
        }
    }
    if let Some((x0, y0, x1, y1)) = legend {
        for (x, y) in markers {
            if x >= x0 && x <= x1 && y >= y0 && y <= y1 {
                out.push(format!(
                    "the legend ({x0}, {y0})–({x1}, {y1}) covers a data marker at ({x}, {y})"
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::paper::chart::{Chart, ErrorSeries, Legend, Series};

    fn chart(legend: Legend) -> Chart {
        Chart {
            file: "t.svg".into(),
            title: "T".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            lines: vec![Series::new("line", vec![(0.0, 0.0), (10.0, 10.0)])],
            error_bars: vec![ErrorSeries {
                name: "mean ± sd".into(),
                points: vec![(0.2, 0.3, 0.1), (9.8, 9.7, 0.1), (0.2, 9.7, 0.1)],
            }],
            points: vec![Series::new("paper", vec![(9.8, 0.3)])],
            legend,
            ..Chart::default()
        }
    }

    /// A rendered chart passes: every corner holds a marker here, so the legend goes
    /// where it covers fewest — and the check reads the boxes and markers back from SVG.
    #[test]
    fn a_rendered_chart_passes_and_defects_are_caught() {
        let mut c = chart(Legend::LowerLeft);
        // Leave the upper-right corner free: the legend must move there.
        c.error_bars[0].points.remove(1);
        let svg = c.render().unwrap();
        assert_eq!(problems(&svg), Vec::<String>::new());
        // The same SVG with its legend box moved over the lower-left marker is refused.
        let moved: String = svg
            .lines()
            .map(|l| {
                if l.starts_with("<rect") && l.contains("opacity=\"0.85\"") {
                    "<rect x=\"0\" y=\"0\" width=\"960\" height=\"600\" opacity=\"0.85\" \
                     fill=\"#FFFFFF\" stroke=\"none\"/>"
                        .to_string()
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let p = problems(&moved);
        assert!(
            p.iter().any(|m| m.contains("covers a data marker")),
            "{p:?}"
        );
        // Text scaled down by a viewBox twice the width: 14 px labels become 7 px.
        let small = svg.replacen("viewBox=\"0 0 960", "viewBox=\"0 0 1920", 1);
        let p = problems(&small);
        assert!(p.iter().any(|m| m.contains("px high")), "{p:?}");
    }
}
