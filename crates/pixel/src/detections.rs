//! The one input of the transaction-level drivers: a stream of pulses, each a detection's
//! TDC code or no detection ([`Detections`]).
//!
//! The drivers ([`crate::TransactionModel::run`], [`crate::FoldModel::run`],
//! [`crate::FrameDriver::run`], the lane driver [`crate::lanes`]) are generic over it, so
//! a caller hands over the pulses in the form it holds them, with no conversion pass:
//!
//! - `[u32]`, the compact form: a code per pulse (4 bytes), [`NO_DETECTION`] for none. What
//!   the Monte Carlo writes (`PhotonSource::fill_codes`) and what the array streams;
//! - `[Option<u32>]` (8 bytes a pulse), the form of the records, vectors and the cycle
//!   model's tests;
//! - any other shape through the trait (the Python package reads numpy's (valid, tdc)
//!   directly: crates/python).
//!
//! A code is truncated to the pixel's T bits by the datapath (its T pins), in every form:
//! `Some(c)` and the compact `c` (≠ [`NO_DETECTION`]) are the same pulse. Codes are at most
//! 16 bits, so [`NO_DETECTION`] is never a code the compact form needs.

use crate::params::MAX_TDC_BITS;

/// The compact form's code of a pulse without a detection (the Monte Carlo's, one
/// definition: `tofprobe_scene::NO_DETECTION`).
pub use tofprobe_scene::NO_DETECTION;

/// A stream of pulses, pulse i a detection's TDC code or none (see the module notes).
pub trait Detections {
    /// Number of pulses.
    fn len(&self) -> usize;

    /// Whether there are no pulses.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Pulse `i` (< [`Detections::len`]): `Some(code)` or `None`.
    fn get(&self, i: usize) -> Option<u32>;

    /// The codes of pulses `start .. start + n` in the compact form ([`NO_DETECTION`] for
    /// none; n ≤ `buf.len()`, `start + n` ≤ [`Detections::len`]): the stream itself when it
    /// is stored that way, else decoded into `buf` without a branch per pulse.
    fn codes<'a>(&'a self, start: usize, n: usize, buf: &'a mut [u32]) -> &'a [u32];

    /// The code of the last detection among pulses `start .. end`, if any.
    fn last_detection(&self, start: usize, end: usize) -> Option<u32> {
        (start..end).rev().find_map(|i| self.get(i))
    }
}

impl Detections for [u32] {
    #[inline(always)]
    fn len(&self) -> usize {
        <[u32]>::len(self)
    }

    #[inline(always)]
    fn get(&self, i: usize) -> Option<u32> {
        let c = self[i];
        (c != NO_DETECTION).then_some(c)
    }

    #[inline(always)]
    fn codes<'a>(&'a self, start: usize, n: usize, _buf: &'a mut [u32]) -> &'a [u32] {
        &self[start..start + n]
    }
}

impl Detections for [Option<u32>] {
    #[inline(always)]
    fn len(&self) -> usize {
        <[Option<u32>]>::len(self)
    }

    #[inline(always)]
    fn get(&self, i: usize) -> Option<u32> {
        self[i]
    }

    #[inline(always)]
    fn codes<'a>(&'a self, start: usize, n: usize, buf: &'a mut [u32]) -> &'a [u32] {
        let out = &mut buf[..n];
        for (c, d) in out.iter_mut().zip(&self[start..start + n]) {
            *c = compact(*d);
        }
        out
    }
}

/// The compact code of one pulse: `Some(c)` → c truncated to [`MAX_TDC_BITS`] bits (the
/// datapath truncates it to T ≤ [`MAX_TDC_BITS`] anyway), `None` → [`NO_DETECTION`];
/// branch-free.
#[inline(always)]
pub fn compact(d: Option<u32>) -> u32 {
    let code = d.unwrap_or(0) & ((1 << MAX_TDC_BITS) - 1);
    if d.is_some() { code } else { NO_DETECTION }
}

impl<const N: usize> Detections for [u32; N] {
    fn len(&self) -> usize {
        N
    }
    fn get(&self, i: usize) -> Option<u32> {
        self.as_slice()
            .get(i)
            .copied()
            .filter(|&c| c != NO_DETECTION)
    }
    fn codes<'a>(&'a self, start: usize, n: usize, buf: &'a mut [u32]) -> &'a [u32] {
        self.as_slice().codes(start, n, buf)
    }
}

impl Detections for Vec<u32> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }
    fn get(&self, i: usize) -> Option<u32> {
        Detections::get(self.as_slice(), i)
    }
    fn codes<'a>(&'a self, start: usize, n: usize, buf: &'a mut [u32]) -> &'a [u32] {
        self.as_slice().codes(start, n, buf)
    }
}

impl Detections for Vec<Option<u32>> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }
    fn get(&self, i: usize) -> Option<u32> {
        self[i]
    }
    fn codes<'a>(&'a self, start: usize, n: usize, buf: &'a mut [u32]) -> &'a [u32] {
        self.as_slice().codes(start, n, buf)
    }
}

/// The pulses `start .. end` of a stream, itself a stream (how the drivers cut a stream
/// into frames and chunks without copying it).
#[derive(Debug, Clone, Copy)]
pub struct Window<'a, D: ?Sized> {
    stream: &'a D,
    start: usize,
    end: usize,
}

impl<'a, D: Detections + ?Sized> Window<'a, D> {
    /// Pulses `range` of `stream` (clamped to its length).
    pub fn new(stream: &'a D, range: std::ops::Range<usize>) -> Self {
        let end = range.end.min(stream.len());
        Window {
            stream,
            start: range.start.min(end),
            end,
        }
    }
}

impl<D: Detections + ?Sized> Detections for Window<'_, D> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.end - self.start
    }
    #[inline(always)]
    fn get(&self, i: usize) -> Option<u32> {
        assert!(
            i < self.len(),
            "pulse {i} outside a window of {}",
            self.len()
        );
        self.stream.get(self.start + i)
    }
    #[inline(always)]
    fn codes<'b>(&'b self, start: usize, n: usize, buf: &'b mut [u32]) -> &'b [u32] {
        assert!(start + n <= self.len(), "pulses beyond a window");
        self.stream.codes(self.start + start, n, buf)
    }
    fn last_detection(&self, start: usize, end: usize) -> Option<u32> {
        self.stream
            .last_detection(self.start + start, self.start + end.min(self.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_forms_agree() {
        let opts = [Some(3), None, Some(0), Some(0x1_0005), None];
        let codes: Vec<u32> = opts.iter().map(|&d| compact(d)).collect();
        assert_eq!(codes, [3, NO_DETECTION, 0, 5, NO_DETECTION]);
        let mut buf = [0u32; 8];
        assert_eq!(opts[..].codes(1, 3, &mut buf), &codes[1..4]);
        assert_eq!(Detections::get(&codes[..], 1), None);
        assert_eq!(Detections::get(&codes[..], 3), Some(5));
        assert_eq!(opts[..].last_detection(0, 2), Some(3));
        assert_eq!(codes[..].last_detection(1, 2), None);
        let w = Window::new(&codes[..], 1..4);
        assert_eq!((w.len(), w.get(0), w.get(2)), (3, None, Some(5)));
        assert_eq!(w.last_detection(0, 1), None);
        assert_eq!(w.last_detection(0, 3), Some(5));
    }
}
