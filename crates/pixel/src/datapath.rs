//! The pixel's one datapath (docs/pixel-contract.md): zoom, hold and prefilter of an accepted
//! pulse ([`Datapath::pulse`], the operand select) and the register operation
//! ([`Datapath::accumulate`], the add). The transaction model calls it once per pulse and
//! once per register; the cycle model once per accepted pulse and once per scheduled
//! operation of each slot. The read-ahead stage (the contract's "Pipeline": register
//! operand, register and sign read one edge before the add) sits between these two calls in
//! the cycle model, nowhere else.
//!
//! Fault hooks (`Option<Fault>`, for the mutation tests) sit on the same lines as the
//! behaviour they break; the transaction model passes `None`, which compiles them away.

use crate::fault::Fault;
use crate::fixed::{mask, prefilter_step_rounded, sign_extend, wrap, zoomed};
use crate::params::{Mode, PixelParams, Rounding};

/// The datapath's constants and its front-end state (`primed`, `held`, `x`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Datapath {
    mode: Mode,
    tdc_bits: u32,
    zoom: u32,
    shift: u32,
    rounding: Rounding,
    frac_bits: u32,
    /// F − G: the fraction bits of x the register operand drops (x >>> (F − G)).
    register_shift: u32,
    /// T+1+F: the width of x.
    prefilter_bits: u32,
    width: u32,
    primed: bool,
    held: i64,
    x: i64,
}

impl Datapath {
    /// The datapath of validated parameters, in its reset state.
    pub fn new(p: &PixelParams) -> Self {
        Datapath {
            mode: p.mode,
            tdc_bits: p.tdc_bits,
            zoom: p.zoom,
            shift: p.shift,
            rounding: p.prefilter_rounding,
            frac_bits: p.effective_frac_bits(),
            register_shift: p.effective_frac_bits() - p.register_frac_bits(),
            prefilter_bits: p.prefilter_bits(),
            width: p.width,
            primed: false,
            held: 0,
            x: 0,
        }
    }

    /// Whether a first valid detection has been seen since reset.
    pub fn primed(&self) -> bool {
        self.primed
    }

    /// The held depth (last valid d = tdc − Z; 0 before the first detection).
    pub fn held(&self) -> i64 {
        self.held
    }

    /// The prefilter state x in units of 2^−F codes (Fourier; 0 in Haar mode).
    pub fn prefilter_state(&self) -> i64 {
        self.x
    }

    /// Register width W.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Zoom, hold and prefilter of one accepted pulse (`valid`: a detection with code
    /// `tdc`). Returns the operand the pulse adds to or subtracts from the registers, or
    /// `None` when it contributes nothing (the contract's priming rule).
    #[inline(always)]
    pub fn pulse(&mut self, valid: bool, tdc: u32, fault: Option<Fault>) -> Option<i64> {
        match self.mode {
            Mode::Fourier => self.fourier_pulse(valid, tdc, fault),
            Mode::Haar => {
                let d = zoomed(tdc, self.tdc_bits, self.zoom);
                let take = valid || fault == Some(Fault::HoldInvalid);
                if take {
                    self.held = d;
                }
                let op = (self.primed || valid).then_some(self.held);
                self.primed |= valid;
                op
            }
        }
    }

    /// [`Datapath::pulse`] of a Fourier pixel (prefiltered operand), without the mode
    /// test: the transaction model's streaming loop calls it directly. The operand is
    /// x >>> (F − G): the registers keep G of the prefilter's F fraction bits (floor).
    #[inline(always)]
    pub fn fourier_pulse(&mut self, valid: bool, tdc: u32, fault: Option<Fault>) -> Option<i64> {
        let op = if self.primed {
            self.x = self.prefilter(fault);
            Some(self.x >> self.register_shift)
        } else {
            None
        };
        if valid || fault == Some(Fault::HoldInvalid) {
            self.held = zoomed(tdc, self.tdc_bits, self.zoom);
        }
        if valid && !self.primed {
            self.primed = true;
            // The filter starts at the first depth, not at zero: no start transient.
            self.x = self.held << self.frac_bits;
        }
        op
    }

    /// x + ((((held << F) − x) + r) >>> S), r = 0 (floor) or 2^(S−1) (nearest).
    #[inline(always)]
    fn prefilter(&self, fault: Option<Fault>) -> i64 {
        if fault == Some(Fault::LogicalShift) {
            return self.logical_shift_prefilter();
        }
        prefilter_step_rounded(self.x, self.held, self.frac_bits, self.shift, self.rounding)
    }

    /// The LogicalShift fault: the T+2+F-bit difference shifted in as unsigned, the sum
    /// wrapped to the T+1+F bits of x (what the broken RTL computes).
    #[cold]
    fn logical_shift_prefilter(&self) -> i64 {
        let diff = (self.held << self.frac_bits) - self.x;
        let step = ((diff as u64 & mask(self.prefilter_bits + 1)) >> self.shift) as i64;
        sign_extend((self.x + step) as u64, self.prefilter_bits)
    }

    /// One register operation: Y ± op (`add`: +), wrapped to W bits.
    #[inline(always)]
    pub fn accumulate(&self, y: i64, op: i64, add: bool, fault: Option<Fault>) -> i64 {
        let add = add != (fault == Some(Fault::SignFlip));
        // m = 0 (add) or −1 (subtract); (op ^ m) − m = ±op, without a branch.
        let m = i64::from(add) - 1;
        wrap(y.wrapping_add((op ^ m).wrapping_sub(m)), self.width)
    }

    /// Back to the reset state (`rst`).
    pub fn reset(&mut self) {
        self.primed = false;
        self.held = 0;
        self.x = 0;
    }
}
