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
//! The streaming drivers (`TransactionModel::run`, the folded driver) run the primed
//! Fourier front end through [`FourierStream`]: [`Datapath::fourier_pulse`]'s arithmetic
//! without faults, regrouped so that the loop-carried chain is two operations (see there).

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

/// Pulses per block of [`FourierStream::run`] (a block's decoding, prefilter and sums stay
/// within the processor's reorder window, so they overlap).
pub const STREAM_BLOCK: usize = 32;
/// The decoded code of a pulse without a detection (codes are masked to T ≤ 16 bits).
const NO_CODE: u32 = u32::MAX;

/// The primed Fourier front end over runs of pulses ([`FourierStream::run`]): exactly
/// [`Datapath::fourier_pulse`] of a primed pixel without faults (tested against it through
/// the drivers, crates/pixel/tests/it/fold.rs), in another grouping.
///
/// - The detections are decoded to their T-bit codes a block at a time without a branch
///   (whether a pulse has one is the scene's coin flip; see `decode`).
/// - The hold is a select of the rounded target t = ((tdc − Z) << F) + r (t of the pulse,
///   or the held one), and the prefilter x ← x + ((t − x) >>> S) is carried as the
///   distance u = t − x: with s = u >>> S, x ← x + s and u ← u + (t' − t) − s, t' the
///   target after this pulse's hold. The chain from one pulse to the next is `>>>` and `−`
///   (the target difference is added beside it), where the direct form has `−`, `>>>`
///   and `+`.
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

impl FourierStream {
    /// Runs `detections` (the TDC code of a detected photon, or `None`) through the front
    /// end: per pulse the prefilter steps towards the held depth, then the hold takes the
    /// detection. Hands the operands x >>> (F − G) to `sink` in pulse order, in slices of
    /// at most [`STREAM_BLOCK`].
    #[inline(always)]
    pub fn run(&mut self, detections: &[Option<u32>], mut sink: impl FnMut(&[i64])) {
        let mut codes = [0u32; STREAM_BLOCK];
        let mut targets = [0i64; STREAM_BLOCK];
        let mut ops = [0i64; STREAM_BLOCK];
        let (mask, frac_bits) = (self.mask, self.frac_bits);
        // t = ((code − Z) << F) + r = (code << F) + offset; NO_CODE (2^32 − 1 > any T-bit
        // code) maps to a target above every detection's, `none`.
        let offset = self.half - (self.zoom << frac_bits);
        let none = (i64::from(NO_CODE) << frac_bits) + offset;
        let (shift, register_shift) = (self.shift, self.register_shift);
        let (mut target, mut x, mut u) = (self.target, self.x, self.u);
        let (whole, tail) = detections.as_chunks::<STREAM_BLOCK>();
        let tail_codes = tail.iter().map(|d| d.map_or(NO_CODE, |c| c & mask));
        for block in whole.iter().map(Some).chain(std::iter::once(None)) {
            let n = match block {
                Some(block) => {
                    decode(block, mask, &mut codes);
                    STREAM_BLOCK
                }
                None => {
                    codes
                        .iter_mut()
                        .zip(tail_codes.clone())
                        .for_each(|(c, t)| *c = t);
                    tail.len()
                }
            };
            for (t, &c) in targets.iter_mut().zip(&codes) {
                *t = (i64::from(c) << frac_bits) + offset;
            }
            let mut state = (target, x, u);
            if register_shift == 0 {
                // G = F (the default): the operand is x itself.
                prefilter::<false>(&targets[..n], &mut ops[..n], none, shift, 0, &mut state);
            } else {
                prefilter::<true>(
                    &targets[..n],
                    &mut ops[..n],
                    none,
                    shift,
                    register_shift,
                    &mut state,
                );
            }
            (target, x, u) = state;
            if n > 0 {
                sink(&ops[..n]);
            }
        }
        (self.target, self.x, self.u) = (target, x, u);
        if let Some(c) = detections.iter().rev().find_map(|d| *d) {
            self.held = i64::from(c & mask) - self.zoom;
        }
    }
}

/// The prefilter and hold of [`FourierStream::run`] over a block of targets (`none`: no
/// detection): the operands into `ops`, the state (t, x, u) carried in `state`. `SHIFTS`:
/// whether the operand drops fraction bits (F > G).
#[inline(always)]
fn prefilter<const SHIFTS: bool>(
    targets: &[i64],
    ops: &mut [i64],
    none: i64,
    shift: u32,
    register_shift: u32,
    state: &mut (i64, i64, i64),
) {
    let (mut target, mut x, mut u) = *state;
    for (op, &t) in ops.iter_mut().zip(targets) {
        let next = std::hint::select_unpredictable(t != none, t, target);
        let s = u >> shift;
        // v = u + (t' − t) is used twice, so the compiler keeps it whole and the chain
        // u → u' stays `>>>` beside `+`, then `−`.
        let v = u + (next - target);
        u = v - s;
        x = (next - v) + s;
        *op = if SHIFTS { x >> register_shift } else { x };
        target = next;
    }
    *state = (target, x, u);
}

/// The codes of `STREAM_BLOCK` pulses masked to T bits, [`NO_CODE`] where there is no
/// detection. Not inlined on purpose: behind a reference to a whole array the compiler may
/// read every payload, so the select needs no branch (it vectorises); inlined into a loop
/// over a slice, it would branch on each pulse's detection.
#[inline(never)]
fn decode(detections: &[Option<u32>; STREAM_BLOCK], mask: u32, codes: &mut [u32; STREAM_BLOCK]) {
    let (ds, cs) = (detections.as_chunks::<8>().0, codes.as_chunks_mut::<8>().0);
    for (d, c) in ds.iter().zip(cs) {
        decode8(d, mask, c);
    }
}

/// The codes of 8 pulses masked to T bits, [`NO_CODE`] without a detection (fully unrolled:
/// constant offsets from the array).
#[inline(always)]
fn decode8(detections: &[Option<u32>; 8], mask: u32, codes: &mut [u32; 8]) {
    for (d, c) in detections.iter().zip(codes) {
        let code = d.unwrap_or(0) & mask;
        *c = if d.is_some() { code } else { NO_CODE };
    }
}
