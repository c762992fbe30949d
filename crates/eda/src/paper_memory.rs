//! The paper's Section 8 memory and compression example, computed with the size report's
//! own width and readout rules ([`crate::memory`]) and shown beside the figures the paper
//! prints, marked where they differ.
//!
//! The example: motion up to |Y|max = 10 mm, a 1 mm TDC LSB (6.67 ps), N = 10^7 pulses
//! (1 s at 10 MHz), 128 bins (256 I/Q registers), 14-bit timestamps. The paper bounds a
//! register by |Y|max·N/2 = 5·10^7 and prints 26 bits, 832 bytes per pixel, 17.5 MB of
//! timestamps and "approximately 22400×".
//! - 5·10^7 < 2^26 = 67,108,864: 26 bits hold it **unsigned**. An I/Q register sums ±d
//!   with either sign, so it holds −5·10^7..5·10^7: 26 magnitude bits and a sign, **27**.
//! - That bound presumes depths centred on zero (±5 codes for a 10 mm range, the pixel's
//!   zoom). Codes 0..10 of an uncentred window weighted ±1 reach ±10·10^7 = ±10^8, and
//!   2^26 < 10^8 < 2^27: 27 magnitude bits and a sign, **28** (DESIGN.md's figure).
//! - 128 × 2 × 26 bits = 6656 bits = 832 B (as printed); 10^7 × 14 bits = 17.5·10^6 B (as
//!   printed); 17.5·10^6 / 832 = **21,033.7**, not ≈ 22,400 (6.1 % less). With the signed
//!   27-bit registers: 864 B and 20,254.6×.

use serde::{Deserialize, Serialize};
use tofprobe_io::markdown::{Align, Table};

use crate::error::Result;
use crate::memory::{MemoryInput, WidthConvention, memory, register_width};

/// One figure of the example.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PaperFigure {
    /// What it is.
    pub figure: String,
    /// Computed here.
    pub computed: f64,
    /// What the paper prints (none where it prints no such figure).
    pub printed: Option<f64>,
    pub unit: String,
    /// The printed value differs from the computed one (beyond its printed rounding).
    pub differs: bool,
    /// How it is computed.
    pub derivation: String,
}

/// The example's inputs as the paper states them.
pub const PULSES: u64 = 10_000_000;
/// Largest motion (mm) = codes at a 1 mm LSB.
pub const MOTION_CODES: u64 = 10;
pub const BINS: u64 = 128;
pub const TIMESTAMP_BITS: u32 = 14;
pub const LASER_RATE_HZ: f64 = 10e6;
/// The paper's printed figures.
pub const PRINTED_BITS: f64 = 26.0;
pub const PRINTED_BYTES: f64 = 832.0;
pub const PRINTED_TIMESTAMP_BYTES: f64 = 17.5e6;
pub const PRINTED_COMPRESSION: f64 = 22_400.0;

/// Every figure of the example (module doc), computed.
pub fn section8() -> Result<Vec<PaperFigure>> {
    let half = MOTION_CODES / 2;
    let readout = |max_abs: u64, convention| {
        memory(&MemoryInput {
            registers: 2 * BINS,
            frame_pulses: PULSES,
            max_abs_operand: max_abs,
            configured_width: None,
            convention,
            timestamp_bits: TIMESTAMP_BITS,
            laser_rate_hz: LASER_RATE_HZ,
        })
    };
    let unsigned = readout(half, WidthConvention::MagnitudeOnly)?;
    let signed = readout(half, WidthConvention::TwosComplement)?;
    let fig =
        |figure: &str, computed: f64, printed: Option<f64>, unit: &str, tol: f64, how: String| {
            PaperFigure {
                figure: figure.into(),
                computed,
                printed,
                unit: unit.into(),
                differs: printed.is_some_and(|p| (p - computed).abs() > tol),
                derivation: how,
            }
        };
    let bound = PULSES * half;
    Ok(vec![
        fig(
            "I/Q register width, unsigned",
            f64::from(register_width(PULSES, half, WidthConvention::MagnitudeOnly)),
            Some(PRINTED_BITS),
            "bits",
            0.0,
            format!("|Y|max·N/2 = {bound:.3e} < 2^26: magnitude bits only, no sign"),
        ),
        fig(
            "I/Q register width, two's complement (±|Y|max·N/2)",
            f64::from(register_width(
                PULSES,
                half,
                WidthConvention::TwosComplement,
            )),
            Some(PRINTED_BITS),
            "bits",
            0.0,
            format!("±{bound:.3e}: 26 magnitude bits + a sign (an I/Q sum takes either sign)"),
        ),
        fig(
            "I/Q register width, two's complement (codes 0..10 weighted ±1)",
            f64::from(register_width(
                PULSES,
                MOTION_CODES,
                WidthConvention::TwosComplement,
            )),
            Some(PRINTED_BITS),
            "bits",
            0.0,
            format!(
                "±{:.3e} (uncentred codes 0..10, no zoom): 2^26 < 10^8 < 2^27, 27 magnitude bits + a sign",
                (PULSES * MOTION_CODES) as f64
            ),
        ),
        fig(
            "readout per pixel (26-bit registers)",
            unsigned.bytes_per_pixel as f64,
            Some(PRINTED_BYTES),
            "B",
            0.0,
            format!("{BINS} bins × 2 × {} bits / 8", unsigned.width_bits),
        ),
        fig(
            "raw timestamps per pixel",
            unsigned.raw_bytes_per_frame,
            Some(PRINTED_TIMESTAMP_BYTES),
            "B",
            0.05e6,
            format!("{PULSES} pulses × {TIMESTAMP_BITS} bits / 8"),
        ),
        fig(
            "compression, timestamps / readout (26-bit registers)",
            unsigned.compression_vs_raw,
            Some(PRINTED_COMPRESSION),
            "×",
            // "approximately 22400×": anything that rounds to it.
            50.0,
            format!(
                "{:.4e} B / {} B = {:.1}",
                unsigned.raw_bytes_per_frame, unsigned.bytes_per_pixel, unsigned.compression_vs_raw
            ),
        ),
        fig(
            "compression with signed 27-bit registers",
            signed.compression_vs_raw,
            None,
            "×",
            0.0,
            format!(
                "{:.4e} B / {} B ({BINS} × 2 × {} bits)",
                signed.raw_bytes_per_frame, signed.bytes_per_pixel, signed.width_bits
            ),
        ),
    ])
}

/// Markdown lines: the figures as a table, the paper's beside them, "**differs**" where
/// they do.
pub fn markdown(figures: &[PaperFigure]) -> String {
    let mut t = Table::new([
        ("figure", Align::Left),
        ("computed", Align::Right),
        ("printed", Align::Right),
        ("", Align::Left),
        ("derivation", Align::Left),
    ]);
    for f in figures {
        t.row([
            f.figure.to_string(),
            format!("{} {}", fmt(f.computed), f.unit),
            f.printed
                .map_or_else(|| "–".to_string(), |p| format!("{} {}", fmt(p), f.unit)),
            if f.differs { "**differs**" } else { "" }.to_string(),
            f.derivation.to_string(),
        ]);
    }
    format!(
        "The paper's Section 8 example (10 mm motion, 1 mm LSB, N = 10^7, 128 bins, 14-bit \
         timestamps), computed:\n\n{t}"
    )
}

/// Thousands separated; integers as integers, others with one decimal.
fn fmt(v: f64) -> String {
    let text = if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    };
    let (int, frac) = text
        .split_once('.')
        .map_or((text.as_str(), None), |(a, b)| (a, Some(b)));
    let mut out = String::new();
    for (i, c) in int.chars().enumerate() {
        if i > 0 && (int.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    if let Some(f) = frac {
        out.push('.');
        out.push_str(f);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example's figures against the paper's print and against integer arithmetic
    /// done by hand here (not through `memory`): 26 bits unsigned as printed, 27 signed,
    /// 28 for codes 0..10; 832 B and 17.5 MB as printed; 21,033.65× where 22,400× is
    /// printed.
    #[test]
    fn section8_is_computed_and_marked() {
        let f = section8().unwrap();
        let by = |name: &str| f.iter().find(|x| x.figure.starts_with(name)).unwrap();
        // By hand: 5·10^7 needs 26 bits (2^25 < 5·10^7 < 2^26), 10^8 needs 27.
        let bits = |v: u64| 64 - v.leading_zeros();
        assert_eq!((bits(50_000_000), bits(100_000_000)), (26, 27));
        let unsigned = by("I/Q register width, unsigned");
        assert_eq!((unsigned.computed, unsigned.differs), (26.0, false));
        let signed = by("I/Q register width, two's complement (±");
        assert_eq!((signed.computed, signed.differs), (27.0, true));
        let uncentred = by("I/Q register width, two's complement (codes");
        assert_eq!((uncentred.computed, uncentred.differs), (28.0, true));
        let bytes = by("readout per pixel");
        assert_eq!((bytes.computed, bytes.differs), (832.0, false));
        assert_eq!(by("raw timestamps").computed, 17.5e6);
        assert!(!by("raw timestamps").differs);
        let c = by("compression, timestamps");
        assert!((c.computed - 17.5e6 / 832.0).abs() < 1e-9 && c.computed.round() == 21_034.0);
        assert!(c.differs, "22,400 is 6.1 % off 21,034");
        assert!((by("compression with signed").computed - 17.5e6 / 864.0).abs() < 1e-9);
        let md = markdown(&f);
        assert!(
            md.contains("| 21,033.7 × | 22,400 × | **differs** |"),
            "{md}"
        );
        assert!(md.contains("| 26 bits | 26 bits |  |"), "{md}");
        assert!(md.contains("| 27 bits | 26 bits | **differs** |"), "{md}");
    }
}
