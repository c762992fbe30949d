//! The Universal File Format (ASCII) file of an array's deflection shapes, the format
//! modal-analysis tools open (as `pyuff` reads and writes it): data set 151 (header), 164
//! (units: mm, mN, °C — lengths in the file are mm), 15 (the pixel grid as nodes, node
//! r·C + c + 1 at the pixel's centre on the scene plane, z = 0) and one data set 55 per bin
//! (frequency response, complex, three values per node: x and y 0, z the pixel's complex
//! deflection amplitude·e^{jφ} in mm), then one data set 58 per pixel (its spectrum at the
//! probed bins: a general function of frequency, complex, uneven abscissa in Hz, ordinate
//! displacement in mm, response node = the pixel, direction +z). Deterministic: the dates
//! are fixed, not the clock's.

use tofprobe_design::ResolvedDesign;

use crate::maps::VibrationMaps;

/// C's `%W.Pe`: a sign, one digit, P decimals, `e`, a sign and at least two exponent
/// digits, right-aligned in W columns (non-finite values written as 0).
fn e(x: f64, width: usize, precision: usize) -> String {
    let x = if x.is_finite() { x } else { 0.0 };
    let s = format!("{x:.precision$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = e.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{:>width$}", format!("{m}e{sign}{:02}", e.abs()))
}

/// `%13.5e`.
fn e13(x: f64) -> String {
    e(x, 13, 5)
}

/// `%20.11e`.
fn e20(x: f64) -> String {
    e(x, 20, 11)
}

/// `%-80s`, cut to 80 characters of printable ASCII.
fn a80(t: &str) -> String {
    let t: String = t
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '_'
            }
        })
        .take(80)
        .collect();
    format!("{t:<80}")
}

fn start(out: &mut String, set: u32) {
    out.push_str(&format!("{:>6}\n{set:>6}{:74}\n", -1, ""));
}

fn end(out: &mut String) {
    out.push_str(&format!("{:>6}\n", -1));
}

/// The file's text.
pub fn write(design: &ResolvedDesign, m: &VibrationMaps) -> String {
    let mut s = String::new();
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    start(&mut s, 151);
    s.push_str(&format!(
        "{}\n",
        a80(&tofprobe_io::text::sanitize(&design.origin))
    ));
    s.push_str(&format!(
        "{}\n",
        a80(&format!(
            "tofprobe array {} x {}: deflection shapes per probed bin",
            m.rows, m.cols
        ))
    ));
    s.push_str(&format!("{}\n", a80("tofprobe")));
    s.push_str(&format!(
        "{:<10}{:<10}{:>10}{:>10}{:>10}\n",
        "01-Jan-00", "00:00:00", 0, 0, 0
    ));
    s.push_str(&format!("{:<10}{:<10}\n", "01-Jan-00", "00:00:00"));
    s.push_str(&format!(
        "{}\n",
        a80(concat!("tofprobe ", env!("CARGO_PKG_VERSION")))
    ));
    s.push_str(&format!("{:<10}{:<10}\n", "01-Jan-00", "00:00:00"));
    end(&mut s);

    start(&mut s, 164);
    s.push_str(&format!("{:>10}{:>20}{:>10}\n", 5, "mm (milli-newton)", 2));
    // Factors from the file's units to SI (divide by them): mm → m, mN → N, °C.
    s.push_str(
        "  1.0000000000000000D+03  1.0000000000000000D+03  1.0000000000000000D+00\n  2.7315000000000000D+02\n",
    );
    end(&mut s);

    start(&mut s, 15);
    for r in 0..m.rows {
        for c in 0..m.cols {
            let (x, y) = ((c as f64 + 0.5) * mm, (r as f64 + 0.5) * mm);
            s.push_str(&format!(
                "{:>10}{:>10}{:>10}{:>10}{}{}{}\n",
                r * m.cols + c + 1,
                0,
                0,
                0,
                e13(x),
                e13(y),
                e13(0.0)
            ));
        }
    }
    end(&mut s);

    for b in 0..m.bins() {
        start(&mut s, 55);
        s.push_str(&format!(
            "{}\n",
            a80(&format!(
                "deflection shape at {:.3} Hz (bin {b})",
                m.frequencies_hz[b]
            ))
        ));
        for _ in 0..4 {
            s.push_str(&format!("{}\n", a80("NONE")));
        }
        // Model 1 (structural), analysis 5 (frequency response), data characteristic 2
        // (3 DOF translation), specific type 8 (displacement), data type 5 (complex), 3
        // values per node.
        s.push_str(&format!(
            "{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}\n",
            1, 5, 2, 8, 5, 3
        ));
        s.push_str(&format!("{:>10}{:>10}{:>10}{:>10}\n", 2, 1, 1, b + 1));
        s.push_str(&format!("{}\n", e13(m.frequencies_hz[b])));
        for (node, (re, im)) in m.deflection(b).into_iter().enumerate() {
            s.push_str(&format!("{:>10}\n", node + 1));
            s.push_str(&format!(
                "{}{}{}{}{}{}\n",
                e13(0.0),
                e13(0.0),
                e13(0.0),
                e13(0.0),
                e13(re / 1000.0),
                e13(im / 1000.0)
            ));
        }
        end(&mut s);
    }

    let n = m.rows * m.cols;
    for node in 0..n {
        start(&mut s, 58);
        s.push_str(&format!(
            "{}\n",
            a80(&format!(
                "spectrum of pixel ({}, {})",
                node / m.cols,
                node % m.cols
            ))
        ));
        for _ in 0..4 {
            s.push_str(&format!("{}\n", a80("NONE")));
        }
        // Function type 0 (general), id 0, version 0, load case 0; response "pixel" at the
        // node, direction 3 (+z); no reference.
        s.push_str(&format!(
            "{:>5}{:>10}{:>5}{:>10} {:>10}{:>10}{:>4} {:>10}{:>10}{:>4}\n",
            0,
            0,
            0,
            0,
            "pixel",
            node + 1,
            3,
            "NONE",
            0,
            0
        ));
        // Complex double (6), B points, uneven spacing (0).
        s.push_str(&format!(
            "{:>10}{:>10}{:>10}{}{}{}\n",
            6,
            m.bins(),
            0,
            e13(0.0),
            e13(0.0),
            e13(0.0)
        ));
        // Abscissa: frequency (18) in Hz; ordinate: displacement (8), length exponent 1,
        // in mm; no denominator, no z axis.
        for (kind, len, label, unit) in [
            (18, 0, "Frequency", "Hz"),
            (8, 1, "Displacement", "mm"),
            (0, 0, "NONE", "NONE"),
            (0, 0, "NONE", "NONE"),
        ] {
            s.push_str(&format!(
                "{kind:>10}{len:>5}{:>5}{:>5} {label:<20} {unit:<20}\n",
                0, 0
            ));
        }
        for b in 0..m.bins() {
            let (a, p) = (m.amplitude(b)[node] / 1000.0, m.phase(b)[node].to_radians());
            s.push_str(&format!(
                "{}{}{}\n",
                e13(m.frequencies_hz[b]),
                e20(a * p.cos()),
                e20(a * p.sin())
            ));
        }
        end(&mut s);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{e13, e20};

    /// The same text as C's printf("%13.5e").
    #[test]
    fn e13_is_printf() {
        assert_eq!(e13(12.5), "  1.25000e+01");
        assert_eq!(e13(-0.00012345), " -1.23450e-04");
        assert_eq!(e13(0.0), "  0.00000e+00");
        assert_eq!(e13(f64::NAN), "  0.00000e+00");
        assert_eq!(e13(1e300).len(), 13);
        assert_eq!(e20(-1.5), "  -1.50000000000e+00");
    }
}
