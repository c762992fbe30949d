//! The maps drawn as SVG heat maps: one colour cell per pixel (row 0 at the top, column 0
//! at the left), axes in pixels with the scene-plane size in mm in the caption, and a
//! colour bar with its unit. Amplitude uses a perceptual blue–green–yellow scale from 0 to
//! the map's maximum, phase a cyclic hue scale over −180..180°, bins a qualitative one.

use std::io::Write;

use tofprobe_io::chart::prelude::*;

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

/// Largest text of a heat map's frame (axes, caption, colour bar: everything but the
/// cells), for the set's size estimate; the frame does not grow with the array (its
/// caption's title and unit are a few dozen characters).
pub const FRAME_BYTES: u64 = 48 << 10;

/// Largest text of one heat-map cell: `<rect x=".." y=".." width=".." height=".."
/// fill="#rrggbb"/>` with every coordinate below 1000 at two decimals.
pub const CELL_BYTES: u64 = 80;

/// Largest text of one pixel of the deflection animation (its cell, 13 colours of 7
/// characters and the `animate` element; coordinates up to 7 digits).
pub const DEFLECTION_CELL_BYTES: u64 = 260;

/// Largest heading of the deflection animation (its title at most 200 characters, escaped).
pub const DEFLECTION_HEAD_BYTES: u64 = 1024;

/// The heat map's frame (everything but the cells) as SVG text whose closing `</svg>` is
/// cut off, and the plot area's cell edges: x of column edges 0..=cols, y of row edges
/// 0..=rows, in pixels of the SVG.
fn heat_map_frame(
    title: &str,
    unit: &str,
    rows: usize,
    cols: usize,
    mm_per_pixel: f64,
    scale: Scale,
    max: f64,
) -> Result<(String, [f64; 4]), String> {
    let (lo, hi) = match scale {
        Scale::Amplitude | Scale::Index => (0.0, max),
        Scale::Phase => (-180.0, 180.0),
    };
    let mut area = [0.0; 4];
    let mut svg = svg((760, 620), |root| {
        let (map_area, bar_area) = root.split_horizontally(640);
        let caption = format!(
            "{title} ({rows} × {cols} pixels, {:.2} × {:.2} mm)",
            cols as f64 * mm_per_pixel,
            rows as f64 * mm_per_pixel
        );
        let frame = Frame::new(caption, 16)
            .label_areas(40, 50)
            .axes("column (pixel)", "row (pixel)")
            .fonts(13, None)
            .without_grid();
        let mut chart = frame.build(&map_area, 0.0..cols as f64, rows as f64..0.0)?;
        frame.draw_mesh(&mut chart)?;
        let (x0, y0) = chart.backend_coord(&(0.0, 0.0));
        let (x1, y1) = chart.backend_coord(&(cols as f64, rows as f64));
        area = [f64::from(x0), f64::from(y0), f64::from(x1), f64::from(y1)];
        ColourBar {
            range: (lo, hi.max(lo + f64::MIN_POSITIVE)),
            desc: unit,
            label_area: 60,
            strips: 64,
            ticks: None,
        }
        .draw(&bar_area, |a, _| colour(scale, a, max))
    })
    .map_err(|e| e.to_string())?;
    let end = svg
        .rfind("</svg>")
        .ok_or_else(|| "the plot backend wrote no </svg>".to_string())?;
    svg.truncate(end);
    Ok((svg, area))
}

/// Writes an SVG heat map of `count = rows·cols` values (`value(i)`, row-major) titled
/// `title`, its colour bar labelled `unit`, to `out`: the frame drawn by plotters (a few
/// kB), then one `<rect>` per pixel streamed as it is made (never the file in memory);
/// `mm_per_pixel` sizes the plane in the caption.
#[allow(clippy::too_many_arguments)]
pub fn write_heat_map(
    out: &mut dyn Write,
    title: &str,
    unit: &str,
    value: &dyn Fn(usize) -> f64,
    rows: usize,
    cols: usize,
    mm_per_pixel: f64,
    scale: Scale,
) -> std::io::Result<()> {
    let max = (0..rows * cols)
        .map(value)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let (frame, [x0, y0, x1, y1]) =
        heat_map_frame(title, unit, rows, cols, mm_per_pixel, scale, max)
            .map_err(std::io::Error::other)?;
    out.write_all(frame.as_bytes())?;
    // Cell edges on the plot area, at two decimals (a cell narrower than a screen pixel
    // keeps its place: integer edges would merge the columns of a large array).
    let (dx, dy) = ((x1 - x0) / cols as f64, (y1 - y0) / rows as f64);
    for i in 0..rows * cols {
        let (r, c) = ((i / cols) as f64, (i % cols) as f64);
        let RGBColor(red, g, b) = colour(scale, value(i), max);
        writeln!(
            out,
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{:.2}\" fill=\"#{red:02x}{g:02x}{b:02x}\"/>",
            x0 + c * dx,
            y0 + r * dy,
            dx,
            dy
        )?;
    }
    out.write_all(b"</svg>\n")
}

/// [`write_heat_map`] into a string (small arrays, tests).
pub fn heat_map_svg(
    title: &str,
    unit: &str,
    values: &[f64],
    rows: usize,
    cols: usize,
    mm_per_pixel: f64,
    scale: Scale,
) -> Result<String, String> {
    if values.len() != rows * cols {
        return Err(format!("{} values for a {rows} × {cols} map", values.len()));
    }
    let mut out = Vec::new();
    write_heat_map(
        &mut out,
        title,
        unit,
        &|i| values[i],
        rows,
        cols,
        mm_per_pixel,
        scale,
    )
    .map_err(|e| e.to_string())?;
    String::from_utf8(out).map_err(|e| e.to_string())
}

/// An animated SVG of the deflection shape at one bin, written to `out` a pixel at a time:
/// each pixel's cell brightens and darkens as a·cos(2πft + φ) over one period (SMIL
/// `animate` of its fill, 12 frames, looped at 1 s per period), so the mode's nodal lines
/// stand still and its antinodes swing in opposition.
pub fn write_deflection_animation(
    out: &mut dyn Write,
    title: &str,
    amplitude: &[f64],
    phase_deg: &[f64],
    rows: usize,
    cols: usize,
) -> std::io::Result<()> {
    let max = amplitude
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let cell = (600 / cols.max(rows)).max(2);
    let (w, h) = (cols * cell, rows * cell + 30);
    let title: String = xml_escape(title).chars().take(200).collect();
    write!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n\
         <text x=\"4\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">{title}</text>\n"
    )?;
    const FRAMES: usize = 12;
    let mut colours = String::with_capacity(8 * (FRAMES + 1));
    for i in 0..rows * cols {
        let (r, c) = (i / cols, i % cols);
        colours.clear();
        let mut first = String::new();
        for k in 0..=FRAMES {
            let t = std::f64::consts::TAU * k as f64 / FRAMES as f64;
            let v = if max > 0.0 {
                amplitude[i] / max * (t + phase_deg[i].to_radians()).cos()
            } else {
                0.0
            };
            // Deflection −1..1 onto the sequential scale's 0..1.
            let RGBColor(red, g, b) = sequential(0.5 + 0.5 * v);
            let hex = format!("#{red:02x}{g:02x}{b:02x}");
            if k == 0 {
                first.clone_from(&hex);
            } else {
                colours.push(';');
            }
            colours.push_str(&hex);
        }
        writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{cell}\" height=\"{cell}\" fill=\"{first}\">\
             <animate attributeName=\"fill\" dur=\"1s\" repeatCount=\"indefinite\" values=\"{colours}\"/></rect>",
            c * cell,
            r * cell + 30,
        )?;
    }
    out.write_all(b"</svg>\n")
}

/// [`write_deflection_animation`] into a string (small arrays, tests).
pub fn deflection_animation_svg(
    title: &str,
    amplitude: &[f64],
    phase_deg: &[f64],
    rows: usize,
    cols: usize,
) -> String {
    let mut out = Vec::new();
    // Writing into memory cannot fail.
    let _ = write_deflection_animation(&mut out, title, amplitude, phase_deg, rows, cols);
    String::from_utf8_lossy(&out).into_owned()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell is drawn once, in place and in its colour; the file's size stays under
    /// the bounds the set's estimate uses; the SVG ends once.
    #[test]
    fn a_streamed_heat_map_holds_one_cell_per_pixel_within_its_size_bound() {
        let (rows, cols) = (7, 5);
        let values: Vec<f64> = (0..rows * cols).map(|i| i as f64).collect();
        let svg = heat_map_svg("t", "µm", &values, rows, cols, 0.5, Scale::Amplitude).unwrap();
        let max = (rows * cols - 1) as f64;
        let (frame, _) = heat_map_frame("t", "µm", rows, cols, 0.5, Scale::Amplitude, max).unwrap();
        assert!(svg.starts_with(&frame));
        let cells: Vec<&str> = svg[frame.len()..]
            .lines()
            .filter(|l| l.starts_with("<rect x="))
            .collect();
        assert_eq!(cells.len(), rows * cols);
        assert!(
            cells.iter().all(|l| (l.len() as u64) < CELL_BYTES),
            "{cells:?}"
        );
        // The largest value gets the top of the scale (viridis' yellow), the first 0.
        assert!(
            cells[rows * cols - 1].contains("#fde725"),
            "{}",
            cells[rows * cols - 1]
        );
        assert!(cells[0].contains("#440154"), "{}", cells[0]);
        assert!((frame.len() as u64) < FRAME_BYTES, "{}", frame.len());
        assert_eq!(svg.matches("</svg>").count(), 1);
        assert!(svg.ends_with("</svg>\n"));
        // A map of the wrong length is refused, not drawn from other memory.
        assert!(heat_map_svg("t", "u", &values[1..], rows, cols, 1.0, Scale::Phase).is_err());
    }

    #[test]
    fn the_deflection_animation_stays_within_its_bounds() {
        let (rows, cols) = (3, 4);
        let a: Vec<f64> = (0..12).map(|i| i as f64).collect();
        let p: Vec<f64> = (0..12).map(|i| i as f64 * 30.0 - 180.0).collect();
        let svg = deflection_animation_svg(&"x".repeat(500), &a, &p, rows, cols);
        let cells: Vec<&str> = svg.lines().filter(|l| l.starts_with("<rect")).collect();
        assert_eq!(cells.len(), 12);
        assert!(
            cells
                .iter()
                .all(|l| (l.len() as u64) < DEFLECTION_CELL_BYTES)
        );
        assert!(svg.lines().nth(1).unwrap().len() as u64 <= DEFLECTION_HEAD_BYTES);
        assert_eq!(
            cells[0].matches('#').count(),
            14,
            "13 frames and the first fill"
        );
    }
}
