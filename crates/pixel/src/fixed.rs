//! Fixed-width two's-complement arithmetic of the one datapath ([`crate::datapath`]): how a
//! value wraps, shifts and extends.
//!
//! Registers are kept as `i64` holding the *sign-extended* W-bit value. Wrapping a sum to W
//! bits is exact modulo 2^W, which is why the models may add in 64 bits and wrap later:
//! (a + b) mod 2^W = ((a mod 2^W) + (b mod 2^W)) mod 2^W.

/// Reduces `value` modulo 2^`width` and sign-extends the result (1 ≤ width ≤ 64).
#[inline(always)]
pub fn wrap(value: i64, width: u32) -> i64 {
    let s = 64 - width;
    (value << s) >> s
}

/// The raw W-bit pattern of a value (what the RTL's `rd_data` bus carries).
#[inline(always)]
pub fn to_raw(value: i64, width: u32) -> u64 {
    (value as u64) & mask(width)
}

/// Sign-extends a raw W-bit pattern.
#[inline(always)]
pub fn sign_extend(raw: u64, width: u32) -> i64 {
    let s = 64 - width;
    ((raw << s) as i64) >> s
}

/// All-ones in the low `width` bits.
#[inline(always)]
pub fn mask(width: u32) -> u64 {
    if width >= 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    }
}

/// The zoomed depth d = tdc − Z of a T-bit code (the code is truncated to its T pins, as the
/// hardware sees it). The result lies in (−2^T, 2^T): T+1 signed bits, never wrapped.
#[inline(always)]
pub fn zoomed(tdc: u32, tdc_bits: u32, zoom: u32) -> i64 {
    i64::from(tdc & (mask(tdc_bits) as u32)) - i64::from(zoom)
}

/// One step of the shift prefilter: x + (((held << F) − x) >>> S), `>>>` an arithmetic
/// (floor) shift. The result lies between x and held·2^F inclusive, so it never needs more
/// than T+1+F bits.
#[inline(always)]
pub fn prefilter_step(x: i64, held: i64, frac_bits: u32, shift: u32) -> i64 {
    prefilter_step_rounded(x, held, frac_bits, shift, crate::params::Rounding::Floor)
}

/// [`prefilter_step`] with the shift rounded as `rounding` says: `Nearest` adds 2^(S−1)
/// before the arithmetic shift (round half up; S = 0 is exact either way). The step still
/// lies between 0 and the difference, so x_new stays between x and held << F and keeps
/// its width.
#[inline(always)]
pub fn prefilter_step_rounded(
    x: i64,
    held: i64,
    frac_bits: u32,
    shift: u32,
    rounding: crate::params::Rounding,
) -> i64 {
    x + ((((held << frac_bits) - x) + rounding.half(shift)) >> shift)
}
