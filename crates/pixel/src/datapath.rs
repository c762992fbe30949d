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
//!
//! The streaming drivers (the folded driver, the lane driver) run the primed Fourier front
//! end through [`FourierStream`]: [`Datapath::fourier_pulse`]'s arithmetic without faults,
//! regrouped so that the loop-carried chain is two operations (see there). The transaction
//! driver, their judge, calls [`Datapath::fourier_pulse`] itself.

use crate::detections::{Detections, NO_DETECTION};
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
        // ±op without a branch: the sign is a ROM bit, as good as random, and a branch on
        // it (what the compiler makes of `(op ^ m) − m` once op is hoisted out of a loop)
        // mispredicts every other register.
        let signed = std::hint::select_unpredictable(add, op, op.wrapping_neg());
        wrap(y.wrapping_add(signed), self.width)
    }

    /// The primed Fourier front end as a [`FourierStream`], for a streaming driver to step
    /// pulse by pulse and hand back with [`Datapath::end_stream`]. `None` unless the
    /// datapath is a Fourier one and primed (before priming, step [`Datapath::pulse`]).
    pub fn stream(&self) -> Option<FourierStream> {
        if self.mode != Mode::Fourier || !self.primed {
            return None;
        }
        let half = self.rounding.half(self.shift);
        let target = (self.held << self.frac_bits) + half;
        Some(FourierStream {
            mask: mask(self.tdc_bits) as u32,
            zoom: i64::from(self.zoom),
            frac_bits: self.frac_bits,
            half,
            shift: self.shift,
            register_shift: self.register_shift,
            held: self.held,
            target,
            x: self.x,
            u: target - self.x,
        })
    }

    /// Takes back the state of a stream made by [`Datapath::stream`] (held and x).
    pub fn end_stream(&mut self, stream: FourierStream) {
        self.held = stream.held;
        self.x = stream.x;
    }

    /// Back to the reset state (`rst`).
    pub fn reset(&mut self) {
        self.primed = false;
        self.held = 0;
        self.x = 0;
    }
}

/// Pulses per block of [`FourierStream::accumulate`] (the codes of a stream not stored in
/// the compact form are decoded a block at a time into a buffer on the stack).
pub const STREAM_BLOCK: usize = 256;

/// The primed Fourier front end over runs of pulses ([`FourierStream::accumulate`]):
/// exactly [`Datapath::fourier_pulse`] of a primed pixel without faults (tested against it
/// through the drivers, crates/pixel/tests/it/fold.rs), in another grouping.
///
/// - The pulses are read in the compact form ([`Detections::codes`]: a code, or
///   [`NO_DETECTION`]), borrowed where the stream is stored that way.
/// - The hold is a select of the rounded target t = ((tdc − Z) << F) + r (t of the pulse,
///   or the held one), and the prefilter x ← x + ((t − x) >>> S) is carried as the
///   distance u = t − x: with s = u >>> S, x ← x + s and u ← u + (t' − t) − s, t' the
///   target after this pulse's hold. The chain from one pulse to the next is `>>>` and `−`
///   (the target difference is added beside it), where the direct form has `−`, `>>>`
///   and `+`.
/// - Each pulse's operand is added into its own cell in the same loop (the folded driver's
///   phase sums): no buffer of operands between the front end and the sums.
/// - The held depth itself is the last detection's, looked up at the end of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FourierStream {
    mask: u32,
    zoom: i64,
    frac_bits: u32,
    half: i64,
    shift: u32,
    register_shift: u32,
    held: i64,
    target: i64,
    x: i64,
    u: i64,
}

/// The constants of the stream's per-pulse step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepConsts {
    /// The T-bit code mask.
    pub mask: u32,
    /// F.
    pub frac_bits: u32,
    /// r − (Z << F): the target of code c is (c << F) + offset.
    pub offset: i64,
    /// S.
    pub shift: u32,
    /// F − G.
    pub register_shift: u32,
}

impl FourierStream {
    /// The per-pulse constants.
    pub(crate) fn consts(&self) -> StepConsts {
        StepConsts {
            mask: self.mask,
            frac_bits: self.frac_bits,
            offset: self.half - (self.zoom << self.frac_bits),
            shift: self.shift,
            register_shift: self.register_shift,
        }
    }

    /// The loop-carried state (t, x, u).
    pub(crate) fn state(&self) -> (i64, i64, i64) {
        (self.target, self.x, self.u)
    }

    /// Takes back the loop-carried state and the held depth of the last detection (if
    /// the pulses run since [`FourierStream::state`] had one; its code).
    pub(crate) fn set_state(&mut self, state: (i64, i64, i64), last: Option<u32>) {
        (self.target, self.x, self.u) = state;
        if let Some(c) = last {
            self.held = i64::from(c & self.mask) - self.zoom;
        }
    }

    /// Runs pulses `start .. start + cells.len()` of `detections` through the front end
    /// (per pulse the prefilter steps towards the held depth, then the hold takes the
    /// detection) and adds the operand x >>> (F − G) of pulse `start + i` into `cells[i]`
    /// (wrapping).
    #[inline(always)]
    pub fn accumulate<D: Detections + ?Sized>(
        &mut self,
        detections: &D,
        start: usize,
        cells: &mut [i64],
    ) {
        let k = self.consts();
        let mut state = self.state();
        let mut buf = [0u32; STREAM_BLOCK];
        for (b, block) in cells.chunks_mut(STREAM_BLOCK).enumerate() {
            let codes = detections.codes(start + b * STREAM_BLOCK, block.len(), &mut buf);
            if k.register_shift == 0 {
                // G = F (the default): the operand is x itself.
                step::<false>(codes, block, &k, &mut state);
            } else {
                step::<true>(codes, block, &k, &mut state);
            }
        }
        let last = detections.last_detection(start, start + cells.len());
        self.set_state(state, last);
    }
}

/// The prefilter and hold of [`FourierStream::accumulate`] over a block of compact codes,
/// each pulse's operand added into its cell, the state (t, x, u) carried in `state`.
/// `SHIFTS`: whether the operand drops fraction bits (F > G).
#[inline(always)]
pub(crate) fn step<const SHIFTS: bool>(
    codes: &[u32],
    cells: &mut [i64],
    k: &StepConsts,
    state: &mut (i64, i64, i64),
) {
    let (mut target, mut x, mut u) = *state;
    for (cell, &c) in cells.iter_mut().zip(codes) {
        let t = (i64::from(c & k.mask) << k.frac_bits) + k.offset;
        let next = std::hint::select_unpredictable(c != NO_DETECTION, t, target);
        let s = u >> k.shift;
        // v = u + (t' − t) is used twice, so the compiler keeps it whole and the chain
        // u → u' stays `>>>` beside `+`, then `−`.
        let v = u + (next - target);
        u = v - s;
        x = (next - v) + s;
        let op = if SHIFTS { x >> k.register_shift } else { x };
        *cell = cell.wrapping_add(op);
        target = next;
    }
    *state = (target, x, u);
}
