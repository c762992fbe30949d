//! The maps drawn as SVG heat maps: one colour cell per pixel (row 0 at the top, column 0
//! at the left), axes in pixels with the scene-plane size in mm in the caption, and a
//! colour bar with its unit. Amplitude uses a perceptual blue–green–yellow scale from 0 to
//! the map's maximum, phase a cyclic hue scale over −180..180°, bins a qualitative one.

use plotters::prelude::*;

/// What a map's values are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// 0 ..= max, a sequential scale.
    Amplitude,
    /// −180 ..= 180 degrees, a cyclic scale.
    Phase,
    /// Small integers (bin indices), one hue each.
    Index,
}

/// Anchors of the sequential scale (viridis at 0, ¼, ½, ¾, 1).
const SEQUENTIAL: [(u8, u8, u8); 5] = [
    (68, 1, 84),
    (59, 82, 139),
    (33, 145, 140),
    (94, 201, 98),
    (253, 231, 37),
];

fn sequential(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    } * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let (a, b) = (SEQUENTIAL[i], SEQUENTIAL[i + 1]);
    let mix = |x: u8, y: u8| (f64::from(x) + f * (f64::from(y) - f64::from(x))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

fn colour(scale: Scale, v: f64, max: f64) -> RGBColor {
    match scale {
        Scale::Amplitude => sequential(if max > 0.0 { v / max } else { 0.0 }),
        Scale::Phase => {
            let h = ((v + 180.0) / 360.0).rem_euclid(1.0);
            let rgb = HSLColor(h, 0.8, 0.5).to_rgba();
            RGBColor(rgb.0, rgb.1, rgb.2)
        }
        Scale::Index => {
            let h = (v * 0.618_033_988_75).rem_euclid(1.0);
            let rgb = HSLColor(h, 0.7, 0.55).to_rgba();
            RGBColor(rgb.0, rgb.1, rgb.2)
        }
    }
}

/// An SVG heat map of `values` ([rows, cols] row-major) titled `title`, its colour bar
/// labelled `unit`; `mm_per_pixel` sizes the plane in the caption.
pub fn heat_map_svg(
    title: &str,
    unit: &str,
    values: &[f64],
    rows: usize,
    cols: usize,
    mm_per_pixel: f64,
    scale: Scale,
) -> Result<String, String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let max = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let (lo, hi) = match scale {
        Scale::Amplitude => (0.0, max),
        Scale::Phase => (-180.0, 180.0),
        Scale::Index => (0.0, max),
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760, 620)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let (map_area, bar_area) = root.split_horizontally(640);
        let caption = format!(
            "{title} ({rows} × {cols} pixels, {:.2} × {:.2} mm)",
            cols as f64 * mm_per_pixel,
            rows as f64 * mm_per_pixel
        );
        let mut chart = ChartBuilder::on(&map_area)
            .caption(caption, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..cols as f64, rows as f64..0.0)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .label_style(("sans-serif", 13))
            .x_desc("column (pixel)")
            .y_desc("row (pixel)")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series((0..rows * cols).map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                Rectangle::new(
                    [(c, r), (c + 1.0, r + 1.0)],
                    colour(scale, values[i], max).filled(),
                )
            }))
            .map_err(|x| e(&x))?;
        let mut bar = ChartBuilder::on(&bar_area)
            .margin_top(40)
            .margin_bottom(50)
            .margin_right(10)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..1.0, lo..hi.max(lo + f64::MIN_POSITIVE))
            .map_err(|x| e(&x))?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 14))
            .y_desc(unit)
            .draw()
            .map_err(|x| e(&x))?;
        let steps = 64;
        bar.draw_series((0..steps).map(|k| {
            let a = lo + (hi - lo) * k as f64 / steps as f64;
            let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new([(0.0, a), (1.0, b)], colour(scale, a, max).filled())
        }))
        .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
    }
    Ok(svg)
}

/// An animated SVG of the deflection shape at one bin: each pixel's cell brightens and
/// darkens as a·cos(2πft + φ) over one period (SMIL `animate` of its fill, 12 frames,
/// looped at 1 s per period), so the mode's nodal lines stand still and its antinodes
/// swing in opposition.
pub fn deflection_animation_svg(
    title: &str,
    amplitude: &[f64],
    phase_deg: &[f64],
    rows: usize,
    cols: usize,
) -> String {
    let max = amplitude
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let cell = (600 / cols.max(rows)).max(2);
    let (w, h) = (cols * cell, rows * cell + 30);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n\
         <text x=\"4\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">{}</text>\n",
        xml_escape(title)
    );
    const FRAMES: usize = 12;
    for i in 0..rows * cols {
        let (r, c) = (i / cols, i % cols);
        let colours: Vec<String> = (0..=FRAMES)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / FRAMES as f64;
                let v = if max > 0.0 {
                    amplitude[i] / max * (t + phase_deg[i].to_radians()).cos()
                } else {
                    0.0
                };
                // Deflection −1..1 onto the sequential scale's 0..1.
                let RGBColor(r, g, b) = sequential(0.5 + 0.5 * v);
                format!("#{r:02x}{g:02x}{b:02x}")
            })
            .collect();
        s.push_str(&format!(
            "<rect x=\"{}\" y=\"{}\" width=\"{cell}\" height=\"{cell}\" fill=\"{}\">\
             <animate attributeName=\"fill\" dur=\"1s\" repeatCount=\"indefinite\" values=\"{}\"/></rect>\n",
            c * cell,
            r * cell + 30,
            colours[0],
            colours.join(";")
        ));
    }
    s.push_str("</svg>\n");
    s
}

/// Text for an SVG text node.
fn xml_escape(t: &str) -> String {
    t.chars()
        .map(|c| match c {
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '&' => "&amp;".to_string(),
            c if c.is_control() => " ".to_string(),
            c => c.to_string(),
        })
        .collect()
}
