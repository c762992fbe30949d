//! The superpixel front end (`[array] superpixel = G`, docs/pixel-contract.md "Superpixel"):
//! G × G SPADs share one pixel's registers and adders, and each pulse their detections are
//! averaged into the one (valid, code) the pixel's datapath consumes. It sits in front of
//! the one datapath, it is not a second one: the drivers run unchanged on the combined
//! stream ([`Superpixel::combine_streams`]).
//!
//! The rule, per pulse, for the n = number of valid SPADs among the G²:
//!
//! - valid' = (n ≥ 1);
//! - each valid SPAD's code is first truncated to the pixel's T bits (its T pins, as the
//!   datapath does), s = the sum of those codes;
//! - code' = ⌊(s + ⌊n/2⌋) / n⌋, the mean rounded half up (for odd n no tie exists), so
//!   |code' − s/n| ≤ ½ LSB, and code' < 2^T;
//! - the division is a multiply and a shift by a reciprocal table, no divider:
//!   code' = ((s + ⌊n/2⌋) · M\[n\]) >> k with M\[n\] = ⌈2^k / n⌉ for n = 1 ..= G² and
//!   k = T + 2·⌈log2 G²⌉. With x = s + ⌊n/2⌋ < n·2^T, M\[n\]·n − 2^k = e ∈ \[0, n − 1\], so
//!   x·M/2^k = x/n + x·e/(n·2^k) and x·e < n²·2^T ≤ 2^k: the product never reaches the
//!   next multiple of 1/n and the floor is exact (crates/pixel/tests/it/superpixel.rs checks
//!   every (s, n) for G ≤ 4 against the exact quotient and the float mean).
//!
//! A power-of-two shift alone would be exact only for n = 1, 2, 4, 8, 16: the table costs
//! G² words of at most k + 1 bits and serves every n.

use crate::detections::NO_DETECTION;
use crate::error::PixelError;
use crate::params::{MAX_TDC_BITS, ceil_log2};

/// Largest G (a superpixel of 4 × 4 = 16 SPADs).
pub const MAX_SUPERPIXEL: u32 = 4;

/// The averaging of G × G SPADs' detections, for T-bit codes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Superpixel {
    side: u32,
    tdc_bits: u32,
    shift: u32,
    /// M[n − 1] = ⌈2^k / n⌉, n = 1 ..= G².
    table: Vec<u64>,
}

impl Superpixel {
    /// The front end of G × G SPADs (`side` = G, 1 ..= [`MAX_SUPERPIXEL`]) for a pixel of
    /// `tdc_bits` = T (1 ..= 16) TDC bits.
    pub fn new(side: u32, tdc_bits: u32) -> Result<Self, PixelError> {
        if !(1..=MAX_SUPERPIXEL).contains(&side) {
            return Err(PixelError::invalid(
                "superpixel",
                side,
                format!("G × G SPADs per pixel, G in 1..={MAX_SUPERPIXEL} (1: no superpixel)"),
                side.clamp(1, MAX_SUPERPIXEL),
            ));
        }
        if !(1..=MAX_TDC_BITS).contains(&tdc_bits) {
            return Err(PixelError::invalid(
                "tdc_bits",
                tdc_bits,
                format!("1..={MAX_TDC_BITS}"),
                tdc_bits.clamp(1, MAX_TDC_BITS),
            ));
        }
        let n_max = side * side;
        let shift = tdc_bits + 2 * ceil_log2(u64::from(n_max));
        let table = (1..=u64::from(n_max))
            .map(|n| (1u64 << shift).div_ceil(n))
            .collect();
        Ok(Superpixel {
            side,
            tdc_bits,
            shift,
            table,
        })
    }

    /// G.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// G²: SPADs per pixel.
    pub fn spads(&self) -> usize {
        (self.side * self.side) as usize
    }

    /// T.
    pub fn tdc_bits(&self) -> u32 {
        self.tdc_bits
    }

    /// k: the shift after the multiply.
    pub fn shift(&self) -> u32 {
        self.shift
    }

    /// The reciprocal table, M[n − 1] = ⌈2^k / n⌉ for n = 1 ..= G².
    pub fn table(&self) -> &[u64] {
        &self.table
    }

    /// Bits of one table word (the largest, M\[1\] = 2^k, needs k + 1).
    pub fn table_bits(&self) -> u32 {
        self.shift + 1
    }

    /// Bits of the sum of G² T-bit codes.
    pub fn sum_bits(&self) -> u32 {
        self.tdc_bits + ceil_log2(self.spads() as u64)
    }

    /// The rounded mean ⌊(s + ⌊n/2⌋) / n⌋ of `n` (1 ..= G²) codes summing to `sum`
    /// (≤ n·(2^T − 1)), by the table: the hardware's multiply and shift.
    #[inline(always)]
    pub fn mean(&self, sum: u32, n: u32) -> u32 {
        let x = u64::from(sum) + u64::from(n / 2);
        ((x * self.table[n as usize - 1]) >> self.shift) as u32
    }

    /// One pulse: the G² SPADs' compact codes ([`NO_DETECTION`] for none; row-major within
    /// the superpixel, though the rule does not depend on the order) → the pixel's compact
    /// code.
    #[inline(always)]
    pub fn combine(&self, codes: &[u32]) -> u32 {
        let mask = (1u32 << self.tdc_bits) - 1;
        let (mut sum, mut n) = (0u32, 0u32);
        for &c in codes {
            let v = u32::from(c != NO_DETECTION);
            sum += (c & mask) * v;
            n += v;
        }
        if n == 0 {
            NO_DETECTION
        } else {
            self.mean(sum, n)
        }
    }

    /// A chunk of pulses: `streams` holds the G² SPADs' codes of the same pulses (equal
    /// lengths ≥ `out.len()`), `out` receives the pixel's codes. Returns the pulses with a
    /// detection (valid').
    pub fn combine_streams(&self, streams: &[&[u32]], out: &mut [u32]) -> u64 {
        assert_eq!(streams.len(), self.spads(), "one stream per SPAD");
        let mut codes = [0u32; (MAX_SUPERPIXEL * MAX_SUPERPIXEL) as usize];
        let mut detections = 0u64;
        for (i, o) in out.iter_mut().enumerate() {
            for (c, s) in codes.iter_mut().zip(streams) {
                *c = s[i];
            }
            *o = self.combine(&codes[..streams.len()]);
            detections += u64::from(*o != NO_DETECTION);
        }
        detections
    }
}
