//! A frame held as two arrays, `valid[i]` and `tdc[i]` (the form of a numpy caller, a
//! waveform dump or a user's own TDC stream), as the drivers' input ([`ValidCodes`]): read
//! in place, decoded a block at a time into the compact form the drivers step, with the
//! range check of the valid codes riding along. One decode for every caller that holds
//! such a frame (the Python package converts numpy's arrays to slices and calls this).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::detections::{Detections, NO_DETECTION};
use crate::error::PixelError;

/// An integer type a TDC code may arrive in (the unsigned and signed integers up to 64
/// bits; a negative code is out of range).
pub trait TdcCode: Copy + Into<i128> + Send + Sync {
    /// The code as u32 (wrapping: only read once [`TdcCode::within`] holds).
    fn wrapped(self) -> u32;
    /// 0 ≤ code ≤ `max`.
    fn within(self, max: u32) -> bool;
}

macro_rules! tdc_code {
    ($wide:ty: $($t:ty),*) => {$(
        impl TdcCode for $t {
            #[inline(always)]
            fn wrapped(self) -> u32 {
                self as u32
            }
            #[inline(always)]
            fn within(self, max: u32) -> bool {
                // One unsigned compare in the type's own width (or 32 bits): a negative
                // code sign-extends to above any max, so the pass vectorises in narrow
                // lanes.
                (self as $wide) <= <$wide>::from(max)
            }
        }
    )*};
}
tdc_code!(u32: u8, u16, u32, i8, i16, i32);
tdc_code!(u64: u64, i64);

/// The frame (`valid`, `tdc`) as a pulse stream: pulse i is a detection of code `tdc[i]`
/// where `valid[i]`, none elsewhere (the code of an invalid pulse is ignored). A valid code
/// outside 0 ..= `max_code` reads as no detection and is remembered; [`ValidCodes::check`]
/// then refuses the frame, naming the first such pulse, so a driver's registers are read
/// only after it.
#[derive(Debug)]
pub struct ValidCodes<'a, T> {
    valid: &'a [bool],
    tdc: &'a [T],
    max_code: u32,
    bad: AtomicBool,
}

impl<'a, T: TdcCode> ValidCodes<'a, T> {
    /// The frame; refused unless `valid` and `tdc` have one entry per pulse.
    pub fn new(valid: &'a [bool], tdc: &'a [T], max_code: u32) -> Result<Self, PixelError> {
        if valid.len() != tdc.len() {
            return Err(PixelError::mismatch(
                "`tdc` (one code per pulse of `valid`)",
                format!("{} codes", tdc.len()),
                format!("{} codes, one per pulse", valid.len()),
            ));
        }
        Ok(ValidCodes {
            valid,
            tdc,
            max_code,
            bad: AtomicBool::new(false),
        })
    }

    /// `Ok` unless a valid code read so far was out of range: then the error naming the
    /// first such pulse, its code and the range.
    pub fn check(&self) -> Result<(), PixelError> {
        if !self.bad.load(Ordering::Relaxed) {
            return Ok(());
        }
        self.scan()
    }

    /// The range check of every valid code, without running a driver.
    pub fn scan(&self) -> Result<(), PixelError> {
        match self
            .valid
            .iter()
            .zip(self.tdc)
            .position(|(&v, &c)| v && !c.within(self.max_code))
        {
            None => Ok(()),
            Some(i) => Err(out_of_range(i, self.tdc[i].into(), self.max_code)),
        }
    }

    /// The whole frame in the compact form ([`NO_DETECTION`] for none), range-checked.
    pub fn compact(&self) -> Result<Vec<u32>, PixelError> {
        let mut out = vec![0; self.valid.len()];
        if mask_codes(self.valid, self.tdc, self.max_code, &mut out) {
            self.scan()?;
        }
        Ok(out)
    }

    /// The whole frame as `Option`s (the form of the float references), range-checked.
    pub fn options(&self) -> Result<Vec<Option<u32>>, PixelError> {
        Ok(self
            .compact()?
            .into_iter()
            .map(|c| (c != NO_DETECTION).then_some(c))
            .collect())
    }
}

/// The error of a valid pulse `i` whose code `c` is outside 0 ..= `max_code`.
fn out_of_range(i: usize, c: i128, max_code: u32) -> PixelError {
    PixelError::CodeOutOfRange {
        pulse: i,
        code: c.to_string(),
        max: max_code,
        bits: u32::BITS - max_code.leading_zeros(),
    }
}

impl<T: TdcCode> Detections for ValidCodes<'_, T> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.valid.len()
    }

    fn get(&self, i: usize) -> Option<u32> {
        let (v, c) = (self.valid[i], self.tdc[i]);
        let ok = c.within(self.max_code);
        if v && !ok {
            self.bad.store(true, Ordering::Relaxed);
        }
        (v && ok).then(|| c.wrapped())
    }

    #[inline]
    fn codes<'b>(&'b self, start: usize, n: usize, buf: &'b mut [u32]) -> &'b [u32] {
        let out = &mut buf[..n];
        let bad = mask_codes(
            &self.valid[start..start + n],
            &self.tdc[start..start + n],
            self.max_code,
            out,
        );
        if bad {
            self.bad.store(true, Ordering::Relaxed);
        }
        out
    }
}

/// The compact codes of (`valid`, `codes`) into `out` (same lengths): masks instead of
/// selects (a valid pulse's mask is all ones, an in-range code's too; the code OR the
/// complement of both masks is the code or all ones, `NO_DETECTION`), so the pass has no
/// branch and vectorises. Returns whether a valid code was out of 0 ..= `max_code`.
#[inline(always)]
fn mask_codes<T: TdcCode>(valid: &[bool], codes: &[T], max_code: u32, out: &mut [u32]) -> bool {
    const _: () = assert!(NO_DETECTION == u32::MAX, "the masks make all ones");
    let mut bad = 0u32;
    for ((o, &v), &c) in out.iter_mut().zip(valid).zip(codes) {
        let valid_mask = u32::from(v).wrapping_neg();
        let ok_mask = u32::from(c.within(max_code)).wrapping_neg();
        bad |= valid_mask & !ok_mask;
        *o = c.wrapped() | !(valid_mask & ok_mask);
    }
    bad != 0
}
