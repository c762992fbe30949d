//! The cycle-accurate model: one [`CycleModel::step`] per rising clock edge on the RTL's
//! pins, implementing docs/pixel-contract.md line by line (accept rule, accumulate
//! schedule, priming, readout protocol, reset). The state names follow the contract.
//!
//! A Verilator harness that does "set inputs, eval, sample outputs, clk 0→1, eval,
//! clk 1→0" sees exactly what `step` returns, and the register writes of that edge are in
//! [`CycleModel::writes`].
//!
//! The accumulate is pipelined (the contract's "Pipeline"): each adder's register operand,
//! register and sign are read one edge ahead (`CycleModel::read_ahead`, after the edge's
//! writes, which is the forward), and the write edge adds to that operand. With the forward
//! that operand is the register's value at the write edge, so the fault-free copy of the
//! edge reads it there (`CycleModel::accumulate_slot`) and skips the stage; the faulty copy
//! keeps it, since two faults (`MissingForward`, `ScheduleLate`) live in it.
//!
//! The arithmetic is the one [`Datapath`]'s, the slot order the one [`Schedule`]'s. The
//! golden vectors are recorded from this model (tofprobe-rtlgen), and the mutation tests
//! run it with a [`Fault`] ([`CycleModel::with_fault`]) to predict where a broken RTL
//! first differs.

use crate::datapath::Datapath;
use crate::error::PixelError;
use crate::fault::Fault;
use crate::fixed::{mask, to_raw, wrap};
use crate::params::{Mode, PixelParams};
use crate::schedule::Schedule;

/// The pixel's inputs during one clock cycle (sampled at its rising edge).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PinsIn<'a> {
    /// Synchronous reset, active high; wins over everything.
    pub rst: bool,
    /// A laser pulse's detection result is presented this cycle.
    pub pulse: bool,
    /// With `pulse`: a photon was detected.
    pub valid: bool,
    /// With `pulse` and `valid`: the TDC code (only its low T bits are wired).
    pub tdc: u32,
    /// Fourier, with `pulse`: the packed ROM word, bit r = 1 adds to Y\[r\].
    pub rom_word: &'a [u64],
    /// Start the readout-and-clear of the register file.
    pub readout: bool,
}

/// The pixel's outputs during one cycle, before its rising edge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PinsOut {
    /// Combinational: a `pulse` or `readout` this cycle would be accepted (Haar: a pulse
    /// also needs the frame not to be full).
    pub ready: bool,
    /// Registered: `rd_data` holds readout word `rd_index`.
    pub rd_valid: bool,
    /// Registered: 0..R−1 a register, R the status word.
    pub rd_index: u32,
    /// Registered: the raw W-bit word.
    pub rd_data: u64,
}

/// One register write made at a clock edge (a trace event).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegWrite {
    /// Register index r.
    pub register: u32,
    /// The new value, as its raw W-bit pattern.
    pub value: u64,
}

/// The cycle-accurate pixel.
#[derive(Debug, Clone)]
pub struct CycleModel {
    p: PixelParams,
    r: usize,
    k: usize,
    schedule: Schedule,
    log2_n: u32,
    fault: Option<Fault>,
    // Contract state (`primed`, `held` and `x` in the datapath).
    dp: Datapath,
    op: i64,
    bits: Vec<u64>,
    n_lat: u64,
    pcount: u64,
    refused: u64,
    acc_en: bool,
    active: bool,
    slot: usize,
    rd_active: bool,
    rd_ptr: usize,
    y: Vec<i64>,
    /// Read-ahead stage (the faulty copy's): per adder of the next slot, (register, add,
    /// `yin`); the first `pre_len` entries are valid.
    pre: Vec<(usize, bool, i64)>,
    pre_len: usize,
    /// All-ones in the low W bits (the raw word of a register).
    raw_mask: u64,
    // Registered outputs.
    rd_valid: bool,
    rd_index: u32,
    rd_data: u64,
    // Bookkeeping (not hardware).
    writes: Vec<RegWrite>,
    cycle: u64,
    accepted_last: bool,
    /// ScheduleLate fault: the writes computed at the last edge, applied at this one.
    late: Vec<RegWrite>,
    /// MissingForward fault: the register file before this edge's writes.
    stale: Vec<i64>,
}

impl CycleModel {
    /// A pixel in its reset state. Fails if the parameters do not validate.
    pub fn new(params: &PixelParams) -> Result<Self, PixelError> {
        Self::with_fault(params, None)
    }

    /// A pixel carrying a deliberate fault (`None`: the correct pixel), for the mutation
    /// tests: the same model with the fault's hook switched on.
    pub fn with_fault(params: &PixelParams, fault: Option<Fault>) -> Result<Self, PixelError> {
        params.validate()?;
        Ok(Self::fresh(params, fault))
    }

    /// The reset state of validated parameters.
    fn fresh(params: &PixelParams, fault: Option<Fault>) -> Self {
        let r = params.registers();
        CycleModel {
            p: params.clone(),
            r,
            k: params.slots(),
            schedule: Schedule::new(params),
            log2_n: params.log2_frame(),
            fault,
            dp: Datapath::new(params),
            op: 0,
            bits: vec![0; r.div_ceil(64)],
            n_lat: 0,
            pcount: 0,
            refused: 0,
            acc_en: false,
            active: false,
            slot: 0,
            rd_active: false,
            rd_ptr: 0,
            y: vec![0; r],
            pre: vec![(0, false, 0); params.adders],
            pre_len: 0,
            raw_mask: mask(params.width),
            rd_valid: false,
            rd_index: 0,
            rd_data: 0,
            writes: Vec::with_capacity(r),
            cycle: 0,
            accepted_last: false,
            late: Vec::new(),
            stale: Vec::new(),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &PixelParams {
        &self.p
    }

    /// The register file, sign-extended from W bits.
    pub fn registers(&self) -> &[i64] {
        &self.y
    }

    /// The held depth.
    pub fn held(&self) -> i64 {
        self.dp.held()
    }

    /// The prefilter state x (units of 2^−F codes).
    pub fn prefilter_state(&self) -> i64 {
        self.dp.prefilter_state()
    }

    /// Whether a first valid detection has been seen since reset.
    pub fn primed(&self) -> bool {
        self.dp.primed()
    }

    /// The fault this model carries (`None`: the correct pixel).
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }

    /// Accepted pulses since the last status word.
    pub fn pcount(&self) -> u64 {
        self.pcount
    }

    /// Refused strobes since the last status word.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The double-buffered array's swap, after this edge's [`CycleModel::step`] (docs/
    /// pixel-contract.md "Double buffer"): the registers, the refused-pulse counter and
    /// the Haar pulse count clear, winning over any write of the same edge, as the RTL's
    /// swap does. The caller copies [`CycleModel::registers`] and [`CycleModel::refused`]
    /// into the shadow *before* that step (the values the swap edge samples).
    pub fn swap_clear(&mut self) {
        self.y.fill(0);
        self.refused = 0;
        self.pcount = 0;
    }

    /// Whether the accumulate pipeline is working on a pulse.
    pub fn busy(&self) -> bool {
        self.active || self.rd_active
    }

    /// Edges stepped since construction.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Whether the last edge accepted a pulse.
    pub fn accepted_pulse(&self) -> bool {
        self.accepted_last
    }

    /// Register writes made at the last edge, in adder order (readout clears included).
    pub fn writes(&self) -> &[RegWrite] {
        &self.writes
    }

    /// The pipeline is free at this edge (the contract's accept rule).
    fn free(&self) -> bool {
        !self.rd_active && (!self.active || self.slot == self.k - 1)
    }

    /// The outputs during the current cycle (before its edge).
    pub fn outputs(&self) -> PinsOut {
        PinsOut {
            ready: self.free(),
            rd_valid: self.rd_valid,
            rd_index: self.rd_index,
            rd_data: self.rd_data,
        }
    }

    /// One clock cycle: returns the outputs as seen during the cycle, then applies the
    /// rising edge with inputs `pins`.
    ///
    /// A pixel without a fault runs a copy of the edge compiled without the fault hooks
    /// (`FAULTY = false`), so they cost nothing when off.
    /// Most edges of a frame are quiet (`CycleModel::quiet_edge`: no reset, pulse or
    /// readout strobe, no readout running), and take a shorter copy of the edge.
    #[inline]
    pub fn step(&mut self, pins: &PinsIn) -> PinsOut {
        if self.fault.is_none() {
            if !(pins.rst || pins.pulse || pins.readout || self.rd_active) {
                return self.quiet_edge();
            }
            self.edge::<false>(pins)
        } else {
            self.edge::<true>(pins)
        }
    }

    /// The fault-free edge when nothing but the pipeline moves: no reset, no pulse or
    /// readout strobe and no readout running (the pixel busy accumulating, or idle). Then
    /// [`CycleModel::edge`] takes nothing, refuses nothing and counts nothing: what is left
    /// is the slot's adds, the slot counter, and `rd_valid` falling. Equal to the full edge
    /// (`tests::the_quiet_edge_is_the_full_edge`, and every co-simulation).
    #[inline(always)]
    fn quiet_edge(&mut self) -> PinsOut {
        let out = self.outputs();
        self.writes.clear();
        self.cycle += 1;
        self.accepted_last = false;
        if self.active {
            if self.acc_en {
                self.accumulate_slot();
            }
            if self.slot == self.k - 1 {
                self.active = false;
            }
            self.slot += 1;
        }
        self.rd_valid = false;
        out
    }

    /// Whether the model carries fault `f` (always false in the fault-free copy).
    #[inline(always)]
    fn has<const FAULTY: bool>(&self, f: Fault) -> bool {
        FAULTY && self.fault == Some(f)
    }

    /// [`CycleModel::step`], with (`FAULTY`) or without the fault hooks.
    #[inline(always)]
    fn edge<const FAULTY: bool>(&mut self, pins: &PinsIn) -> PinsOut {
        let out = self.outputs();
        self.writes.clear();
        self.cycle += 1;
        self.accepted_last = false;
        if pins.rst {
            self.reset();
            return out;
        }
        let free = self.free();
        let haar_room = self.p.mode == Mode::Fourier
            || self.pcount < self.p.frame_pulses
            || self.has::<FAULTY>(Fault::HaarFrameLimit);
        let take_readout = pins.readout && free;
        let take_pulse = pins.pulse && free && !pins.readout && haar_room;
        let refuse_pulse = pins.pulse && !take_pulse;

        if self.has::<FAULTY>(Fault::MissingForward) {
            self.stale.clone_from(&self.y);
        }
        // Accumulate one slot with the old op/acc_en: register, sign and register operand
        // were read ahead at the last edge; the datapath adds.
        if self.active {
            if self.acc_en {
                if FAULTY {
                    for i in 0..self.pre_len {
                        let (reg, add, yin) = self.pre[i];
                        let v = self.dp.accumulate(yin, self.op, add, self.fault);
                        self.write::<FAULTY>(reg, v);
                    }
                } else {
                    self.accumulate_slot();
                }
            }
            if self.slot == self.k - 1 {
                self.active = false;
            }
            self.slot += 1;
        }

        // Readout progress; at every edge without it rd_valid falls.
        let mut refused_next = self.refused;
        let status_edge = self.rd_active && self.rd_ptr == self.r;
        if self.rd_active {
            self.readout_edge::<FAULTY>(&mut refused_next);
        } else {
            self.rd_valid = false;
        }
        // RefusedCounter: only the status edge's `refused ← 0 or 1` remains.
        let counts = !self.has::<FAULTY>(Fault::RefusedCounter) || status_edge;
        if refuse_pulse && counts {
            refused_next = (refused_next + 1).min(self.p.refused_max());
        }
        self.refused = refused_next;

        if take_pulse {
            self.accept::<FAULTY>(pins);
        }
        if take_readout {
            self.rd_active = true;
            self.rd_ptr = 0;
        }
        // The fault-free copy reads its operands at the write edge instead
        // ([`CycleModel::accumulate_slot`]): the same values, without the stage.
        if FAULTY && self.active {
            self.read_ahead::<FAULTY>();
        }
        if self.has::<FAULTY>(Fault::ScheduleLate) {
            self.apply_late();
        }
        out
    }

    /// One edge of the readout: the next register word out (and cleared), or the status
    /// word, which ends the readout.
    #[inline(always)]
    fn readout_edge<const FAULTY: bool>(&mut self, refused_next: &mut u64) {
        if self.rd_ptr < self.r {
            self.rd_data = self.y[self.rd_ptr] as u64 & self.raw_mask;
            self.rd_index = self.rd_ptr as u32;
            self.rd_valid = true;
            self.write::<FAULTY>(self.rd_ptr, 0);
            self.rd_ptr += 1;
        } else {
            // StatusWord: the RTL's word multiplexer, whose default arm (index R) is 0.
            self.rd_data = if self.has::<FAULTY>(Fault::StatusWord) {
                0
            } else {
                self.refused & self.raw_mask
            };
            self.rd_index = self.r as u32;
            self.rd_valid = true;
            *refused_next = 0;
            self.pcount = 0;
            self.rd_active = false;
        }
    }

    /// The read stage of the pipeline, for the slot the next edge performs: the schedule
    /// selects register and sign (from the `bits`/`n_lat` latched now at an accepting
    /// edge), and the register is read after this edge's writes: the forward of a K = 1
    /// pulse's write to the next pulse's read of the same register.
    #[inline(always)]
    fn read_ahead<const FAULTY: bool>(&mut self) {
        let mut len = 0;
        for i in 0..self.p.adders {
            let Some(operation) = self.schedule.at(self.slot, i) else {
                break;
            };
            let (reg, add) = operation.target(self.n_lat, self.log2_n, &self.bits);
            let yin = if self.has::<FAULTY>(Fault::MissingForward) {
                self.stale[reg]
            } else {
                self.y[reg]
            };
            self.pre[i] = (reg, add, yin);
            len += 1;
        }
        self.pre_len = len;
    }

    /// The fault-free accumulate of the current slot, its operands read at this edge: the
    /// read-ahead stage's values exactly, since it reads after the last edge's writes (the
    /// forward) and nothing writes the register file, the slot, the latched ROM word or
    /// pulse index between that read and this edge's adds (a slot's operations touch
    /// distinct registers). `MissingForward` and `ScheduleLate` break that equality, so the
    /// faulty copy keeps the stage.
    #[inline(always)]
    fn accumulate_slot(&mut self) {
        let (op, n_lat, log2_n) = (self.op, self.n_lat, self.log2_n);
        for i in 0..self.p.adders {
            let Some(operation) = self.schedule.at(self.slot, i) else {
                break;
            };
            let (reg, add) = operation.target(n_lat, log2_n, &self.bits);
            let v = self.dp.accumulate(self.y[reg], op, add, None);
            self.write::<false>(reg, v);
        }
    }

    /// A register write of this edge (a trace event).
    #[inline(always)]
    fn write<const FAULTY: bool>(&mut self, reg: usize, v: i64) {
        if FAULTY {
            return self.write_faulty(reg, v);
        }
        self.y[reg] = v;
        self.writes.push(RegWrite {
            register: reg as u32,
            value: v as u64 & self.raw_mask,
        });
    }

    /// The register-file faults: register 0 one bit narrow, or every write one edge late.
    #[cold]
    fn write_faulty(&mut self, reg: usize, v: i64) {
        let w = self.p.width;
        let v = if self.fault == Some(Fault::NarrowRegister) && reg == 0 {
            wrap(v, w - 1)
        } else {
            v
        };
        let event = RegWrite {
            register: reg as u32,
            value: to_raw(v, w),
        };
        if self.fault != Some(Fault::ScheduleLate) {
            self.y[reg] = v;
        }
        self.writes.push(event);
    }

    /// ScheduleLate: the writes computed at this edge wait; those of the previous edge
    /// land now (and are this edge's trace events).
    #[cold]
    fn apply_late(&mut self) {
        let computed = std::mem::take(&mut self.writes);
        let landing = std::mem::replace(&mut self.late, computed);
        for e in &landing {
            self.y[e.register as usize] = wrap(e.value as i64, self.p.width);
        }
        self.writes = landing;
    }

    /// The state changes at the edge that accepts a pulse: the datapath's zoom, hold and
    /// prefilter select the operand; the ROM word or pulse index is latched for the slots.
    #[inline(always)]
    fn accept<const FAULTY: bool>(&mut self, pins: &PinsIn) {
        let fault = if FAULTY { self.fault } else { None };
        let operand = self.dp.pulse(pins.valid, pins.tdc, fault);
        self.acc_en = operand.is_some();
        if let Some(op) = operand {
            self.op = op;
        }
        match self.p.mode {
            Mode::Fourier => {
                for (i, b) in self.bits.iter_mut().enumerate() {
                    *b = pins.rom_word.get(i).copied().unwrap_or(0);
                }
                // Only R bits are wired.
                if let Some(last) = self.bits.last_mut() {
                    let used = self.r - 64 * (self.r.div_ceil(64) - 1);
                    *last &= mask(used as u32);
                }
            }
            // The RTL latches pcount's low log2(N) bits (only beyond a full frame, under
            // the HaarFrameLimit fault, does that differ from pcount).
            Mode::Haar => self.n_lat = self.pcount & (self.p.frame_pulses - 1),
        }
        self.pcount += 1;
        self.active = true;
        self.slot = 0;
        self.accepted_last = true;
    }

    fn reset(&mut self) {
        let cycle = self.cycle;
        *self = Self::fresh(&self.p, self.fault);
        self.cycle = cycle;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quiet edge ([`CycleModel::step`]'s short copy) against the full edge
    /// ([`CycleModel::edge`] called for every edge) on random pins: pulses (with and
    /// without detections) at random gaps, so some land while busy and are refused,
    /// readouts, the odd reset, over Fourier and Haar pixels with one and several slots.
    /// Every edge's outputs, writes and whole state must be equal. A quiet copy that
    /// forgot `rd_valid` falling, or a slot, fails here.
    #[test]
    fn the_quiet_edge_is_the_full_edge() {
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let fourier = PixelParams {
            frame_pulses: 64,
            rom_depth: 64,
            ..PixelParams::fourier_default(30, 64, 64)
        };
        let haar = PixelParams {
            mode: Mode::Haar,
            haar_scales: 2,
            frame_pulses: 8,
            ..PixelParams::default()
        };
        let mut quiet_edges = 0;
        for params in [fourier, haar] {
            params.validate().unwrap();
            let words = params.registers().div_ceil(64);
            let mut fast = CycleModel::new(&params).unwrap();
            let mut full = fast.clone();
            for _ in 0..20_000 {
                let r = next();
                let rom: Vec<u64> = (0..words).map(|_| next()).collect();
                let pins = PinsIn {
                    rst: r % 997 == 0,
                    pulse: r % 7 == 0,
                    valid: r % 3 != 0,
                    tdc: (r >> 20) as u32 & 0xff,
                    rom_word: &rom,
                    readout: r % 151 == 1,
                };
                let quiet = !(pins.rst || pins.pulse || pins.readout || fast.rd_active);
                quiet_edges += usize::from(quiet);
                let a = fast.step(&pins);
                let b = full.edge::<false>(&pins);
                assert_eq!(a, b, "outputs at edge {}", full.cycle());
                assert_eq!(
                    fast.writes(),
                    full.writes(),
                    "writes at edge {}",
                    full.cycle()
                );
                assert_eq!(
                    format!("{fast:?}"),
                    format!("{full:?}"),
                    "state at edge {}",
                    full.cycle()
                );
            }
        }
        assert!(quiet_edges > 20_000, "{quiet_edges} quiet edges");
    }
}
