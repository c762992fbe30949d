//! The Universal File Format (ASCII) file of an array's deflection shapes, the format
//! modal-analysis tools open (as `pyuff` reads and writes it): data set 151 (header), 164
//! (units: mm, mN, °C — lengths in the file are mm), 15 (the pixel grid as nodes, node
//! r·C + c + 1 at the pixel's centre on the scene plane, z = 0) and one data set 55 per bin
//! (frequency response, complex, three values per node: x and y 0, z the pixel's complex
//! deflection amplitude·e^{jφ} in mm), then one data set 58 per pixel (its spectrum at the
//! probed bins: a general function of frequency, complex, uneven abscissa in Hz, ordinate
//! displacement in mm, response node = the pixel, direction +z). Deterministic: the dates
//! are fixed, not the clock's.

use std::io::Write;

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

fn start(out: &mut dyn Write, set: u32) -> std::io::Result<()> {
    writeln!(out, "{:>6}\n{set:>6}{:74}", -1, "")
}

fn end(out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(out, "{:>6}", -1)
}

/// Writes the file to `out`, one line at a time (never the file in memory: one data set
/// 58 per pixel is ≈ 1 kB); `name` is the configuration's name in the header, `level`
/// the `[array] level` the maps were computed at.
pub fn write_to(
    out: &mut dyn Write,
    name: &str,
    level: &str,
    mm_per_pixel: f64,
    m: &VibrationMaps,
) -> std::io::Result<()> {
    let s = out;
    let mm = mm_per_pixel;
    start(s, 151)?;
    writeln!(s, "{}", a80(&tofprobe_io::text::sanitize(name)))?;
    writeln!(
        s,
        "{}",
        a80(&format!(
            "tofprobe array {} x {} ({level}): deflection shapes per probed bin",
            m.rows, m.cols
        ))
    )?;
    writeln!(s, "{}", a80("tofprobe"))?;
    writeln!(
        s,
        "{:<10}{:<10}{:>10}{:>10}{:>10}",
        "01-Jan-00", "00:00:00", 0, 0, 0
    )?;
    writeln!(s, "{:<10}{:<10}", "01-Jan-00", "00:00:00")?;
    writeln!(
        s,
        "{}",
        a80(concat!("tofprobe ", env!("CARGO_PKG_VERSION")))
    )?;
    writeln!(s, "{:<10}{:<10}", "01-Jan-00", "00:00:00")?;
    end(s)?;

    start(s, 164)?;
    writeln!(s, "{:>10}{:>20}{:>10}", 5, "mm (milli-newton)", 2)?;
    // Factors from the file's units to SI (divide by them): mm → m, mN → N, °C.
    s.write_all(
        b"  1.0000000000000000D+03  1.0000000000000000D+03  1.0000000000000000D+00\n  2.7315000000000000D+02\n",
    )?;
    end(s)?;

    start(s, 15)?;
    for r in 0..m.rows {
        for c in 0..m.cols {
            let (x, y) = ((c as f64 + 0.5) * mm, (r as f64 + 0.5) * mm);
            writeln!(
                s,
                "{:>10}{:>10}{:>10}{:>10}{}{}{}",
                r * m.cols + c + 1,
                0,
                0,
                0,
                e13(x),
                e13(y),
                e13(0.0)
            )?;
        }
    }
    end(s)?;

    for b in 0..m.bins() {
        start(s, 55)?;
        writeln!(
            s,
            "{}",
            a80(&format!(
                "deflection shape at {:.3} Hz (bin {b})",
                m.frequencies_hz[b]
            ))
        )?;
        for _ in 0..4 {
            writeln!(s, "{}", a80("NONE"))?;
        }
        // Model 1 (structural), analysis 5 (frequency response), data characteristic 2
        // (3 DOF translation), specific type 8 (displacement), data type 5 (complex), 3
        // values per node.
        writeln!(s, "{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}", 1, 5, 2, 8, 5, 3)?;
        writeln!(s, "{:>10}{:>10}{:>10}{:>10}", 2, 1, 1, b + 1)?;
        writeln!(s, "{}", e13(m.frequencies_hz[b]))?;
        for (node, (&a, &p)) in m.amplitude(b).iter().zip(m.phase(b)).enumerate() {
            // The complex deflection a·e^{jφ} (µm), as `VibrationMaps::deflection` gives it,
            // one node at a time.
            let (sin, cos) = p.to_radians().sin_cos();
            let (re, im) = (a * cos, a * sin);
            writeln!(s, "{:>10}", node + 1)?;
            writeln!(
                s,
                "{}{}{}{}{}{}",
                e13(0.0),
                e13(0.0),
                e13(0.0),
                e13(0.0),
                e13(re / 1000.0),
                e13(im / 1000.0)
            )?;
        }
        end(s)?;
    }

    let n = m.rows * m.cols;
    for node in 0..n {
        start(s, 58)?;
        writeln!(
            s,
            "{}",
            a80(&format!(
                "spectrum of pixel ({}, {})",
                node / m.cols,
                node % m.cols
            ))
        )?;
        for _ in 0..4 {
            writeln!(s, "{}", a80("NONE"))?;
        }
        // Function type 0 (general), id 0, version 0, load case 0; response "pixel" at the
        // node, direction 3 (+z); no reference.
        writeln!(
            s,
            "{:>5}{:>10}{:>5}{:>10} {:>10}{:>10}{:>4} {:>10}{:>10}{:>4}",
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
        )?;
        // Complex double (6), B points, uneven spacing (0).
        writeln!(
            s,
            "{:>10}{:>10}{:>10}{}{}{}",
            6,
            m.bins(),
            0,
            e13(0.0),
            e13(0.0),
            e13(0.0)
        )?;
        // Abscissa: frequency (18) in Hz; ordinate: displacement (8), length exponent 1,
        // in mm; no denominator, no z axis.
        for (kind, len, label, unit) in [
            (18, 0, "Frequency", "Hz"),
            (8, 1, "Displacement", "mm"),
            (0, 0, "NONE", "NONE"),
            (0, 0, "NONE", "NONE"),
        ] {
            writeln!(
                s,
                "{kind:>10}{len:>5}{:>5}{:>5} {label:<20} {unit:<20}",
                0, 0
            )?;
        }
        for b in 0..m.bins() {
            let (a, p) = (m.amplitude(b)[node] / 1000.0, m.phase(b)[node].to_radians());
            writeln!(
                s,
                "{}{}{}",
                e13(m.frequencies_hz[b]),
                e20(a * p.cos()),
                e20(a * p.sin())
            )?;
        }
        end(s)?;
    }
    Ok(())
}

/// The file's bytes for a small array (tests; the set streams [`write_to`]).
pub fn write(design: &ResolvedDesign, m: &VibrationMaps) -> String {
    let mut out = Vec::new();
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    // Writing into memory cannot fail.
    let level = design.array.as_ref().map_or("bit-true", |a| a.level.name());
    let _ = write_to(&mut out, &crate::configuration_name(design), level, mm, m);
    String::from_utf8_lossy(&out).into_owned()
}

/// The file's size for `rows` × `cols` pixels and `bins` bins, exactly: every line is of
/// fixed width, so the size is linear in the pixels, and is measured by writing the file
/// of one and of two pixels (the set's size estimate, before any work).
pub fn file_bytes(rows: usize, cols: usize, bins: usize) -> u64 {
    let size = |cols: usize| {
        let n = cols * bins;
        let m = VibrationMaps {
            rows: 1,
            cols,
            frequencies_hz: vec![1.0; bins],
            amplitude_um: vec![1.0; n],
            phase_deg: vec![0.0; n],
            dominant_bin: 0,
            strongest_bin: vec![0; cols],
        };
        let mut counter = Counter(0);
        let _ = write_to(&mut counter, "x", "bit-true", 1.0, &m);
        counter.0
    };
    let (one, two) = (size(1), size(2));
    let pixels = (rows as u64).saturating_mul(cols as u64);
    one.saturating_add((two - one).saturating_mul(pixels.saturating_sub(1)))
}

/// A sink that counts bytes.
struct Counter(u64);

impl Write for Counter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len() as u64;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
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

    /// The estimate is the written size, whatever the values (every field is fixed width).
    #[test]
    fn file_bytes_is_the_written_size() {
        let (rows, cols, bins) = (3, 5, 4);
        let n = rows * cols;
        let m = crate::maps::VibrationMaps {
            rows,
            cols,
            frequencies_hz: vec![12.5, 1e5, 3.25e-3, 977.0],
            amplitude_um: (0..bins * n).map(|i| i as f64 * 1e3 - 7.0).collect(),
            phase_deg: (0..bins * n).map(|i| i as f64 * 37.0 - 180.0).collect(),
            dominant_bin: 1,
            strongest_bin: vec![0; n],
        };
        let mut out = Vec::new();
        super::write_to(&mut out, "a name", "bit-true", 0.25, &m).unwrap();
        assert_eq!(out.len() as u64, super::file_bytes(rows, cols, bins));
        assert!(super::file_bytes(rows, cols + 1, bins) > out.len() as u64);
    }
}
