//! Memory sizing: the register width a scene needs, bits and bytes per pixel, readout
//! volume per frame and per second, and compression against raw timestamps.
//!
//! Width rule (docs/pixel-contract.md): registers wrap, so only the FINAL value must fit.
//! After N pulses each register holds Σ ±op, so |Y| ≤ N·max|op| with max|op| the largest
//! operand magnitude (Fourier: |d|·2^F, the prefilter output never leaves the range of
//! the held depths; Haar: |d|). Two's complement needs bitlen(N·max|op|) + 1 bits.
//! The paper counted magnitude bits only ("without a sign bit"); `WidthConvention`
//! reproduces both so the paper's 26 bits and the true 28 can be shown side by side.

use crate::error::{EdaError, Result};
use serde::{Deserialize, Serialize};
use tofprobe_pixel::sizing::{SIZING_SIGMAS, scene_code_range};

/// How a register's width is counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WidthConvention {
    /// Two's complement: magnitude bits + 1 sign bit (what the RTL implements).
    TwosComplement,
    /// Magnitude bits only (the paper's count).
    MagnitudeOnly,
}

/// Number of bits to write the unsigned value `v` (0 for 0).
pub fn bit_length(v: u128) -> u32 {
    128 - v.leading_zeros()
}

/// Register width for `frame_pulses` operands of magnitude ≤ `max_abs_operand`.
pub fn register_width(frame_pulses: u64, max_abs_operand: u64, convention: WidthConvention) -> u32 {
    let bound = u128::from(frame_pulses) * u128::from(max_abs_operand);
    let magnitude = bit_length(bound).max(1);
    match convention {
        WidthConvention::TwosComplement => magnitude + 1,
        WidthConvention::MagnitudeOnly => magnitude,
    }
}

/// Largest |tdc − Z| (in codes) for depths in [depth_min_mm, depth_max_mm], a window
/// starting at `window_start_mm` and a TDC LSB of `lsb_mm`, plus the prefilter's 2^F.
pub fn max_abs_operand(
    depth_min_mm: f64,
    depth_max_mm: f64,
    window_start_mm: f64,
    lsb_mm: f64,
    frac_bits: u32,
) -> Result<u64> {
    if !(lsb_mm.is_finite() && lsb_mm > 0.0) {
        return Err(EdaError::OutOfRange {
            field: "tdc_lsb_mm",
            value: lsb_mm.to_string(),
            allowed: "a finite value > 0".into(),
        });
    }
    if !(depth_min_mm.is_finite() && depth_max_mm.is_finite() && depth_min_mm <= depth_max_mm) {
        return Err(EdaError::OutOfRange {
            field: "depth range (mm)",
            value: format!("{depth_min_mm}..{depth_max_mm}"),
            allowed: "finite, min ≤ max".into(),
        });
    }
    if frac_bits > 16 {
        return Err(EdaError::OutOfRange {
            field: "frac_bits (F)",
            value: frac_bits.to_string(),
            allowed: "0..=16".into(),
        });
    }
    let lo = ((depth_min_mm - window_start_mm) / lsb_mm).floor().abs();
    let hi = ((depth_max_mm - window_start_mm) / lsb_mm).floor().abs();
    let codes = lo.max(hi);
    if !(codes.is_finite() && codes < 2f64.powi(40)) {
        return Err(EdaError::OutOfRange {
            field: "depth range / TDC LSB",
            value: codes.to_string(),
            allowed: "fewer than 2^40 codes".into(),
        });
    }
    Ok((codes as u64) << frac_bits)
}

/// The TDC codes a scene produces: the pixel crate's one sizing rule
/// ([`tofprobe_pixel::sizing::scene_code_range`]) at ±[`SIZING_SIGMAS`]·σ of jitter, so
/// `tofprobe size` reports on the codes `width = "auto"` sizes for. With background photons
/// any code of the window can be detected, so the whole window is returned.
pub fn scene_codes(
    depth_range_mm: (f64, f64),
    window_start_mm: f64,
    lsb_mm: f64,
    jitter_mm: f64,
    codes: u32,
    background: bool,
) -> (u32, u32) {
    scene_code_range(
        depth_range_mm.0,
        depth_range_mm.1,
        jitter_mm,
        SIZING_SIGMAS,
        window_start_mm,
        lsb_mm,
        codes,
        background,
    )
}

/// Largest operand magnitude for codes in [lo, hi] after the zoom Z, with `frac_bits`
/// fraction bits in the registers' operand (G, F unless `register_frac_bits` keeps fewer):
/// max(|lo − Z|, |hi − Z|)·2^G.
pub fn operand_from_codes(lo: u32, hi: u32, zoom: u32, frac_bits: u32) -> u64 {
    let m = u64::from(lo.abs_diff(zoom).max(hi.abs_diff(zoom)));
    m << frac_bits.min(32)
}

/// What the memory section is computed from.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct MemoryInput {
    /// Registers R (Fourier: 2·B; Haar: 2^(U+1) − 1).
    pub registers: u64,
    /// Pulses per frame N.
    pub frame_pulses: u64,
    /// Largest operand magnitude, in operand LSBs (see [`max_abs_operand`]).
    pub max_abs_operand: u64,
    /// Width the configuration uses (W), if any; the readout figures use it.
    pub configured_width: Option<u32>,
    /// Width counting convention.
    pub convention: WidthConvention,
    /// Bits of one raw timestamp (a TDC code) that a histogram-free readout would ship.
    pub timestamp_bits: u32,
    /// Laser pulse rate (Hz).
    pub laser_rate_hz: f64,
}

/// The memory section's figures.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct Memory {
    /// Width each register needs for the scene (bits).
    pub required_width_bits: u32,
    /// Width used for the readout figures (configured W, else the required one).
    pub width_bits: u32,
    /// The configured W is narrower than needed: readout values would alias.
    pub width_too_small: bool,
    /// R·W.
    pub bits_per_pixel: u64,
    /// ceil(R·W / 8).
    pub bytes_per_pixel: u64,
    /// Readout per frame and pixel (bytes) = bytes_per_pixel.
    pub readout_bytes_per_frame: u64,
    /// Frames per second = f_laser / N.
    pub frames_per_second: f64,
    /// Readout bytes per second and pixel.
    pub readout_bytes_per_second: f64,
    /// Raw timestamps of one frame: N·T bits, in bytes.
    pub raw_bytes_per_frame: f64,
    /// raw_bytes_per_frame / readout_bytes_per_frame.
    pub compression_vs_raw: f64,
    /// N / R: values read out per timestamp saved (the paper's Haar ratio).
    pub compression_in_values: f64,
}

/// Computes the memory figures.
pub fn memory(input: &MemoryInput) -> Result<Memory> {
    let range = |field: &'static str, value: String, allowed: &str| EdaError::OutOfRange {
        field,
        value,
        allowed: allowed.into(),
    };
    if input.registers == 0 {
        return Err(range("registers", "0".into(), "≥ 1"));
    }
    if input.frame_pulses == 0 {
        return Err(range("frame_pulses (N)", "0".into(), "≥ 1"));
    }
    if !(input.laser_rate_hz.is_finite() && input.laser_rate_hz > 0.0) {
        return Err(range(
            "laser_rate_hz",
            input.laser_rate_hz.to_string(),
            "finite, > 0",
        ));
    }
    let required = register_width(input.frame_pulses, input.max_abs_operand, input.convention);
    let width = input.configured_width.unwrap_or(required);
    let bits = input.registers * u64::from(width);
    let bytes = bits.div_ceil(8);
    let frames_per_second = input.laser_rate_hz / input.frame_pulses as f64;
    let raw = input.frame_pulses as f64 * f64::from(input.timestamp_bits) / 8.0;
    Ok(Memory {
        required_width_bits: required,
        width_bits: width,
        width_too_small: width < required,
        bits_per_pixel: bits,
        bytes_per_pixel: bytes,
        readout_bytes_per_frame: bytes,
        frames_per_second,
        readout_bytes_per_second: bytes as f64 * frames_per_second,
        raw_bytes_per_frame: raw,
        compression_vs_raw: raw / bytes as f64,
        compression_in_values: input.frame_pulses as f64 / input.registers as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's example: 10 mm motion, 1 mm TDC LSB, N = 10^7 pulses at 10 MHz,
    /// 128 bins, 14-bit timestamps.
    fn paper(convention: WidthConvention, max_code: u64, width: Option<u32>) -> Memory {
        memory(&MemoryInput {
            registers: 2 * 128,
            frame_pulses: 10_000_000,
            max_abs_operand: max_code,
            configured_width: width,
            convention,
            timestamp_bits: 14,
            laser_rate_hz: 10e6,
        })
        .unwrap()
    }

    #[test]
    fn paper_26_bits_are_magnitude_of_plus_minus_5_codes() {
        // ±5 codes (window centred on the motion), no sign bit: 5·10^7 < 2^26 = 67,108,864.
        let m = paper(WidthConvention::MagnitudeOnly, 5, None);
        assert_eq!(m.required_width_bits, 26);
        // 128 bins × 2 × 26 bits = 6656 bits = 832 B per pixel.
        assert_eq!(m.bits_per_pixel, 6656);
        assert_eq!(m.bytes_per_pixel, 832);
        // 10^7 × 14 bits = 17.5 MB; 17.5e6 / 832 = 21,033.65…: 21,034×, not the printed 22,400×.
        assert_eq!(m.raw_bytes_per_frame, 17.5e6);
        assert_eq!(m.compression_vs_raw.round(), 21_034.0);
        assert_eq!(m.frames_per_second, 1.0);
        assert_eq!(m.readout_bytes_per_second, 832.0);
    }

    #[test]
    fn codes_0_to_10_need_28_bits_twos_complement() {
        // 10·10^7 = 10^8 needs 27 magnitude bits (2^26 < 10^8 < 2^27) + sign.
        assert_eq!(
            paper(WidthConvention::TwosComplement, 10, None).required_width_bits,
            28
        );
        // and the depth → operand path: depths 30..40 mm, window at 30 mm, 1 mm LSB.
        assert_eq!(max_abs_operand(30.0, 40.0, 30.0, 1.0, 0).unwrap(), 10);
        assert_eq!(max_abs_operand(30.0, 40.0, 35.0, 1.0, 0).unwrap(), 5);
        assert_eq!(max_abs_operand(30.0, 40.0, 30.0, 1.0, 4).unwrap(), 160);
    }

    #[test]
    fn haar_ratios_match_the_paper() {
        // 127 coefficients for 100,000 timestamps: 787×; 500,000: 3937×.
        let haar = |n| {
            memory(&MemoryInput {
                registers: 127,
                frame_pulses: n,
                max_abs_operand: 10,
                configured_width: None,
                convention: WidthConvention::TwosComplement,
                timestamp_bits: 14,
                laser_rate_hz: 10e6,
            })
            .unwrap()
        };
        assert_eq!(haar(100_000).compression_in_values.floor(), 787.0);
        assert_eq!(haar(500_000).compression_in_values.floor(), 3937.0);
    }

    #[test]
    fn scene_codes_follow_depth_jitter_and_background() {
        // Default scene: 30 ± 0.1 mm, σ = 7.5 mm, LSB 0.75 mm, 80 codes from 0 mm:
        // (29.9 − 37.5)/0.75 < 0 → 0; (30.1 + 37.5)/0.75 = 90.1 → clipped to 79.
        assert_eq!(
            scene_codes((29.9, 30.1), 0.0, 0.75, 7.5, 80, false),
            (0, 79)
        );
        // No jitter: 30 ± 0.1 mm → codes 39 and 40.
        assert_eq!(
            scene_codes((29.9, 30.1), 0.0, 0.75, 0.0, 80, false),
            (39, 40)
        );
        assert_eq!(scene_codes((29.9, 30.1), 0.0, 0.75, 0.0, 80, true), (0, 79));
        // The margin is the pixel crate's 6σ (what `width = "auto"` sizes for), not 5σ:
        // 50 mm ± 6·1 mm in 1 mm codes → 44..56 (5σ would give 45..55).
        assert_eq!(SIZING_SIGMAS, 6.0);
        assert_eq!(
            scene_codes((50.0, 50.0), 0.0, 1.0, 1.0, 100, false),
            (44, 56)
        );
        // Z = 40, F = 6: max(|39 − 40|, |40 − 40|)·64 = 64.
        assert_eq!(operand_from_codes(39, 40, 40, 6), 64);
        assert_eq!(operand_from_codes(0, 79, 0, 6), 79 * 64);
    }

    #[test]
    fn width_edges_and_flags() {
        assert_eq!(register_width(1, 1, WidthConvention::TwosComplement), 2);
        // 2^k exactly needs k+1 magnitude bits.
        assert_eq!(
            register_width(1, 1 << 20, WidthConvention::MagnitudeOnly),
            21
        );
        assert_eq!(
            register_width(1, (1 << 20) - 1, WidthConvention::MagnitudeOnly),
            20
        );
        let m = paper(WidthConvention::TwosComplement, 10, Some(24));
        assert!(m.width_too_small && m.width_bits == 24);
        let err = max_abs_operand(0.0, 1.0, 0.0, 0.0, 0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("tdc_lsb_mm") && err.contains("> 0"), "{err}");
    }
}
