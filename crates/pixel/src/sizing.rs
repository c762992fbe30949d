//! Register-width sizing: how many bits each register needs so that its *final* value fits
//! (the wrap makes intermediate overflow harmless, see [`crate::fixed`]), readout bytes per
//! pixel, and the compression against raw timestamps.
//!
//! A register accumulates Y = Σₙ sₙ·opₙ with sₙ = ±1. If every operand lies in [a, b] and the
//! frame has n₊ additions and n₋ subtractions, then exactly
//!   n₊·a − n₋·b ≤ Y ≤ n₊·b − n₋·a,
//! and both ends are reached by some input, so this is the tight bound. With the ROM known,
//! n₊ and n₋ are its exact bit counts over the frame (this is where the window gain and the
//! zoom's DC show up: the DC term is c·(n₊ − n₋) for an operand centred at c). Without the
//! ROM, the worst case over all sign patterns is |Y| ≤ N·max(|a|, |b|).

use tofprobe_dsp::RomImage;

use crate::params::{Mode, PixelParams};

/// Bits of a two's-complement register that holds every value in [min, max].
pub fn twos_complement_bits(min: i128, max: i128) -> u32 {
    let mut w = 1;
    while w < 127 && !(min >= -(1i128 << (w - 1)) && max < (1i128 << (w - 1))) {
        w += 1;
    }
    w
}

/// Bits of an unsigned register (no sign bit) that holds 0..=max (the paper's convention).
pub fn unsigned_bits(max: u128) -> u32 {
    (128 - max.leading_zeros()).max(1)
}

/// The exact range of Σ sₙ·opₙ with n₊ terms added and n₋ subtracted, every operand in
/// [a, b].
pub fn signed_sum_range(a: i64, b: i64, n_plus: u64, n_minus: u64) -> (i128, i128) {
    let (a, b) = (i128::from(a), i128::from(b));
    let (np, nm) = (i128::from(n_plus), i128::from(n_minus));
    (np * a - nm * b, np * b - nm * a)
}

/// The range of Σ sₙ·opₙ over N terms for *any* ±1 signs, operands in [a, b].
pub fn any_sign_range(a: i64, b: i64, n: u64) -> (i128, i128) {
    let m = i128::from(a.unsigned_abs().max(b.unsigned_abs()));
    let n = i128::from(n);
    (-n * m, n * m)
}

/// Per-register (n₊, n₋): how often each of the first `registers` ROM bits is 1 (add) and
/// 0 (subtract) over a frame of `n` pulses reading addresses 0, 1, … mod L.
pub fn rom_sign_counts(rom: &RomImage, registers: usize, n: u64) -> Vec<(u64, u64)> {
    let depth = rom.depth() as u64;
    if depth == 0 {
        return vec![(0, 0); registers];
    }
    let periods = n / depth;
    let rest = n % depth;
    (0..registers)
        .map(|r| {
            let mut ones_period = 0u64;
            let mut ones_rest = 0u64;
            for a in 0..depth {
                if rom.bit(a as usize, r) {
                    ones_period += 1;
                    if a < rest {
                        ones_rest += 1;
                    }
                }
            }
            let plus = periods * ones_period + ones_rest;
            (plus, n - plus)
        })
        .collect()
}

/// The operand range [a, b] (in operand LSBs: codes·2^G in Fourier mode, G = the register
/// fraction bits) for depths whose TDC codes lie in [`code_min`, `code_max`], after the zoom
/// Z. The prefilter output always lies between held values, so the held range bounds it;
/// the operand x >>> (F − G) floors x, and a held value times 2^F floors to itself times
/// 2^G, so the bound holds at G bits too.
pub fn operand_range(params: &PixelParams, code_min: u32, code_max: u32) -> (i64, i64) {
    let f = params.register_frac_bits();
    let z = i64::from(params.zoom);
    (
        (i64::from(code_min) - z) << f,
        (i64::from(code_max) - z) << f,
    )
}

/// The width each register needs so that its final value of a frame is exact, for
/// operands whose codes lie in [`code_min`, `code_max`] (register order). With a ROM
/// (Fourier) the exact per-register sign counts are used; Haar uses its exact counts
/// (scale u adds and subtracts N/2^(u+1) times, all its registers alike); without a ROM
/// every register gets the any-sign bound.
pub fn register_widths(
    params: &PixelParams,
    code_min: u32,
    code_max: u32,
    rom: Option<&RomImage>,
) -> Vec<u32> {
    let (a, b) = operand_range(params, code_min, code_max);
    let n = params.frame_pulses;
    let ranges: Vec<(i128, i128)> = match (params.mode, rom) {
        (Mode::Fourier, Some(rom)) => rom_sign_counts(rom, params.registers(), n)
            .into_iter()
            .map(|(p, m)| signed_sum_range(a, b, p, m))
            .collect(),
        (Mode::Fourier, None) => vec![any_sign_range(a, b, n); params.registers()],
        (Mode::Haar, _) => (0..=params.haar_scales)
            .flat_map(|u| {
                let half = n >> (u + 1);
                std::iter::repeat_n(signed_sum_range(a, b, half, half), 1 << u)
            })
            .collect(),
    };
    ranges
        .into_iter()
        .map(|(lo, hi)| twos_complement_bits(lo, hi).max(params.operand_bits()))
        .collect()
}

/// The register width W the pixel needs: the largest of [`register_widths`] (and at least
/// one operand).
pub fn required_width(
    params: &PixelParams,
    code_min: u32,
    code_max: u32,
    rom: Option<&RomImage>,
) -> u32 {
    register_widths(params, code_min, code_max, rom)
        .into_iter()
        .max()
        .unwrap_or(1)
        .max(params.operand_bits())
}

/// Jitter σ on each side of a scene's depth range that the sizing covers, for
/// `width = "auto"` and `tofprobe size` alike: a detection beyond 6σ has probability
/// 2·10⁻⁹ (≈ 0.02 of the 10⁷ pulses of a frame), and the width bound already assumes every
/// sample at the extreme code, which a real frame's sum is far from.
pub const SIZING_SIGMAS: f64 = 6.0;

/// The TDC codes a scene's detections can take: the depth range [`depth_min_mm`,
/// `depth_max_mm`] (static depth ± the motion's maximum amplitude) widened by `k_sigma`
/// jitter σ, in codes of `lsb_mm` from the window start, clamped to the window's `codes`.
/// With background photons (`background`), any code of the window can occur: the whole
/// window.
#[allow(clippy::too_many_arguments)]
pub fn scene_code_range(
    depth_min_mm: f64,
    depth_max_mm: f64,
    jitter_mm: f64,
    k_sigma: f64,
    window_start_mm: f64,
    lsb_mm: f64,
    codes: u32,
    background: bool,
) -> (u32, u32) {
    let top = codes.saturating_sub(1);
    if background || lsb_mm.is_nan() || lsb_mm <= 0.0 {
        return (0, top);
    }
    let to_code = |mm: f64| ((mm - window_start_mm) / lsb_mm).floor();
    let lo = to_code(depth_min_mm - k_sigma * jitter_mm);
    let hi = to_code(depth_max_mm + k_sigma * jitter_mm);
    let clamp = |c: f64| {
        if c.is_nan() {
            0
        } else {
            c.clamp(0.0, f64::from(top)) as u32
        }
    };
    (clamp(lo), clamp(hi))
}

/// A pixel's sizing summary for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SizingReport {
    /// Codes the operands were sized for (inclusive).
    pub code_range: (u32, u32),
    /// Width each register needs, register order.
    pub register_widths: Vec<u32>,
    /// The common width W (the largest).
    pub width: u32,
    /// Readout bytes per pixel (R words of W bits, status word excluded).
    pub readout_bytes: f64,
    /// Raw timestamp bytes for the same frame.
    pub raw_bytes: f64,
    /// raw_bytes / readout_bytes.
    pub compression: f64,
}

impl SizingReport {
    /// Sizes `params` for codes [`code_min`, `code_max`] (and the ROM if given) against raw
    /// timestamps of `timestamp_bits` bits.
    pub fn new(
        params: &PixelParams,
        code_min: u32,
        code_max: u32,
        rom: Option<&RomImage>,
        timestamp_bits: u32,
    ) -> Self {
        let register_widths = register_widths(params, code_min, code_max, rom);
        let width = register_widths
            .iter()
            .copied()
            .max()
            .unwrap_or(1)
            .max(params.operand_bits());
        let readout = readout_bytes(params.registers(), width, false);
        let raw = raw_timestamp_bytes(params.frame_pulses, timestamp_bits);
        SizingReport {
            code_range: (code_min, code_max),
            register_widths,
            width,
            readout_bytes: readout,
            raw_bytes: raw,
            compression: raw / readout,
        }
    }
}

/// Readout size of one pixel in bytes: R words of W bits plus the W-bit status word,
/// packed.
pub fn readout_bytes(registers: usize, width: u32, with_status: bool) -> f64 {
    let words = registers as f64 + if with_status { 1.0 } else { 0.0 };
    words * f64::from(width) / 8.0
}

/// Bytes of raw timestamps for the same frame: N timestamps of `timestamp_bits` each.
pub fn raw_timestamp_bytes(pulses: u64, timestamp_bits: u32) -> f64 {
    pulses as f64 * f64::from(timestamp_bits) / 8.0
}

/// Compression factor of the readout against raw timestamps.
pub fn compression(pulses: u64, timestamp_bits: u32, registers: usize, width: u32) -> f64 {
    raw_timestamp_bytes(pulses, timestamp_bits) / readout_bytes(registers, width, false)
}
