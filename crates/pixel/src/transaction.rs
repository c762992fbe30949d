//! The transaction-level model: one call per laser pulse, integers only, the same state and
//! arithmetic as the contract (docs/pixel-contract.md) without the clock: the one
//! [`Datapath`] driven once per pulse (and once per register operation, in the order of the
//! one [`Schedule`]). Sweeps use it.
//!
//! Two entry points compute the same thing:
//! - [`TransactionModel::pulse`] updates the register file after every pulse (what the
//!   equivalence tests compare cycle by cycle);
//! - [`TransactionModel::run`] streams many pulses. Because Y\[r\] = Σₙ ±xₙ is linear and the
//!   wrap is exact modulo 2^W, it may regroup the sum: for each byte of the ROM word it adds
//!   x into one of 256 partial sums indexed by that byte's value (4 adds per pulse at
//!   B = 16 instead of 32), and distributes the partial sums to the registers with their ±
//!   signs only at the end of the call. Everything is 64-bit wrapping arithmetic, reduced to
//!   W bits at the end, so the result is bit-identical to `pulse` (tested).

use tofprobe_dsp::RomImage;

use crate::datapath::Datapath;
use crate::detections::{Detections, Window};
use crate::error::PixelError;
use crate::fixed::wrap;
use crate::params::{Mode, PixelParams};
use crate::readout::Readout;
use crate::schedule::Schedule;

/// The transaction-level pixel.
#[derive(Debug, Clone)]
pub struct TransactionModel {
    params: PixelParams,
    regs: Vec<i64>,
    dp: Datapath,
    schedule: Schedule,
    pcount: u64,
    refused: u64,
    /// Partial sums of [`TransactionModel::run`]: one table of 256 per ROM byte.
    tables: Vec<[i64; 256]>,
}

impl TransactionModel {
    /// A pixel just out of reset. Fails if the parameters do not validate.
    pub fn new(params: &PixelParams) -> Result<Self, PixelError> {
        params.validate()?;
        Ok(TransactionModel {
            params: params.clone(),
            regs: vec![0; params.registers()],
            dp: Datapath::new(params),
            schedule: Schedule::new(params),
            pcount: 0,
            refused: 0,
            tables: Vec::new(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PixelParams {
        &self.params
    }

    /// The register file, each value sign-extended from W bits.
    pub fn registers(&self) -> &[i64] {
        &self.regs
    }

    /// The held depth (last valid d = tdc − Z; 0 before the first detection).
    pub fn held(&self) -> i64 {
        self.dp.held()
    }

    /// The prefilter state x in units of 2^−F codes (Fourier; 0 in Haar mode).
    pub fn prefilter_state(&self) -> i64 {
        self.dp.prefilter_state()
    }

    /// Whether a first valid detection has been seen since reset.
    pub fn primed(&self) -> bool {
        self.dp.primed()
    }

    /// Pulses accepted since the last readout.
    pub fn pulses_in_frame(&self) -> u64 {
        self.pcount
    }

    /// Pulses refused since the last readout (Haar: pulses beyond N).
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// Counts a refused pulse strobe (the hardware's saturating counter).
    pub fn refuse(&mut self) {
        self.refused = (self.refused + 1).min(self.params.refused_max());
    }

    /// One laser pulse: `detection` is the TDC code of a detected photon (`None`: no
    /// detection), `rom_entry` the packed ROM word for this pulse (Fourier; bit r = 1 adds
    /// to Y\[r\]; ignored in Haar mode). Returns whether the pulse was accepted: a Haar frame
    /// that already has N pulses refuses (and counts) further pulses until read out.
    pub fn pulse(&mut self, detection: Option<u32>, rom_entry: &[u64]) -> bool {
        match self.params.mode {
            Mode::Fourier => {
                if let Some(x) = self.advance(detection) {
                    let dp = self.dp;
                    for (wi, chunk) in self.regs.chunks_mut(64).enumerate() {
                        let bits = rom_entry.get(wi).copied().unwrap_or(0);
                        for (i, y) in chunk.iter_mut().enumerate() {
                            *y = dp.accumulate(*y, x, (bits >> i) & 1 == 1, None);
                        }
                    }
                }
                self.pcount += 1;
                true
            }
            Mode::Haar => self.pulse_haar(detection),
        }
    }

    /// The datapath's zoom, hold and prefilter for one pulse: the operand, if the pulse
    /// contributes.
    #[inline(always)]
    fn advance(&mut self, detection: Option<u32>) -> Option<i64> {
        self.dp
            .pulse(detection.is_some(), detection.unwrap_or(0), None)
    }

    fn pulse_haar(&mut self, detection: Option<u32>) -> bool {
        if self.pcount >= self.params.frame_pulses {
            self.refuse();
            return false;
        }
        if let Some(h) = self.advance(detection) {
            let l = self.params.log2_frame();
            for operation in self.schedule.pulse() {
                let (r, add) = operation.target(self.pcount, l, &[]);
                self.regs[r] = self.dp.accumulate(self.regs[r], h, add, None);
            }
        }
        self.pcount += 1;
        true
    }

    /// Runs many pulses: pulse i reads ROM address (`first_address` + i) mod L. Same result
    /// as calling [`TransactionModel::pulse`] for each, faster (see the module notes).
    /// Fails if the ROM's depth or width does not match the parameters (Fourier).
    pub fn run<D: Detections + ?Sized>(
        &mut self,
        detections: &D,
        rom: Option<&RomImage>,
        first_address: u64,
    ) -> Result<(), PixelError> {
        let total = detections.len();
        if self.params.mode == Mode::Haar {
            for i in 0..total {
                self.pulse_haar(detections.get(i));
            }
            return Ok(());
        }
        let rom = check_rom(&self.params, rom)?;
        let r = self.regs.len();
        let nbytes = r.div_ceil(8);
        let wpe = rom.words_per_entry();
        let words = rom.words();
        let depth = rom.depth();
        let mut addr = (first_address % depth as u64) as usize;
        // Until the first detection nothing accumulates (the priming rule): step singly.
        let mut pos = 0usize;
        while !self.dp.primed() && pos < total {
            self.advance(detections.get(pos));
            pos += 1;
            addr += 1;
            if addr == depth {
                addr = 0;
            }
        }
        // Two table sets, for even and odd pulses: consecutive pulses often share a ROM byte,
        // and alternating sets halves the store-to-load chains on one cell.
        let mut tables = std::mem::take(&mut self.tables);
        tables.clear();
        tables.resize(2 * nbytes, [0; 256]);
        let (even, odd) = tables.split_at_mut(nbytes);
        let mut dp = self.dp;
        for i in 0..total - pos {
            let det = detections.get(pos + i);
            // Primed: every pulse contributes its operand.
            let x = dp
                .fourier_pulse(det.is_some(), det.unwrap_or(0), None)
                .unwrap_or(0);
            let set = if i & 1 == 0 { &mut *even } else { &mut *odd };
            if wpe == 1 {
                // R ≤ 64 (B ≤ 32): one word per entry, the common case.
                let mut word = words[addr];
                for table in set.iter_mut() {
                    let cell = &mut table[(word & 0xff) as usize];
                    *cell = cell.wrapping_add(x);
                    word >>= 8;
                }
            } else {
                let entry = &words[addr * wpe..addr * wpe + wpe];
                for (j, table) in set.iter_mut().enumerate() {
                    let byte = (entry[j / 8] >> ((j % 8) * 8)) as u8;
                    let cell = &mut table[byte as usize];
                    *cell = cell.wrapping_add(x);
                }
            }
            addr += 1;
            if addr == depth {
                addr = 0;
            }
        }
        self.dp = dp;
        for j in 0..nbytes {
            let (a, b) = tables.split_at_mut(nbytes);
            for (ca, cb) in a[j].iter_mut().zip(b[j].iter_mut()) {
                *ca = ca.wrapping_add(std::mem::take(cb));
            }
        }
        tables.truncate(nbytes);
        self.pcount += total as u64;
        distribute(&mut tables, &mut self.regs, self.params.width);
        self.tables = tables;
        Ok(())
    }

    /// Reads the frame out and clears the registers and the frame counters. The depth
    /// tracking (`primed`, held, x) continues across frames, as in the hardware.
    pub fn readout(&mut self) -> Readout {
        let words = self.regs.clone();
        self.regs.iter_mut().for_each(|y| *y = 0);
        let refused = std::mem::take(&mut self.refused);
        self.pcount = 0;
        Readout { words, refused }
    }

    /// Runs whole frames the way the reference sequencer drives them: frame after frame of
    /// N pulses, pulse n of a frame reading ROM address n mod L, a readout after each.
    pub fn run_frames<D: Detections + ?Sized>(
        &mut self,
        stimuli: &D,
        rom: Option<&RomImage>,
    ) -> Result<Vec<Readout>, PixelError> {
        let n = frame_len(&self.params, stimuli.len())?;
        let mut out = Vec::with_capacity(stimuli.len() / n.max(1));
        for start in (0..stimuli.len()).step_by(n.max(1)) {
            self.run(&Window::new(stimuli, start..start + n), rom, 0)?;
            out.push(self.readout());
        }
        Ok(out)
    }
}

/// Adds the byte tables into the registers and wraps them to `width` bits, emptying the
/// tables: the pulses whose ROM byte j had value v added ±(their x sum) to the eight
/// registers of that byte, with the sign of each bit of v. Shared by [`TransactionModel::run`]
/// and the folded driver ([`crate::fold`]).
pub(crate) fn distribute(tables: &mut [[i64; 256]], regs: &mut [i64], width: u32) {
    let r = regs.len();
    for (j, table) in tables.iter_mut().enumerate() {
        for (v, cell) in table.iter_mut().enumerate() {
            let h = std::mem::take(cell);
            if h == 0 {
                continue;
            }
            for b in 0..8 {
                let reg = 8 * j + b;
                if reg >= r {
                    break;
                }
                let s = if (v >> b) & 1 == 1 {
                    h
                } else {
                    h.wrapping_neg()
                };
                regs[reg] = regs[reg].wrapping_add(s);
            }
        }
    }
    for y in regs.iter_mut() {
        *y = wrap(*y, width);
    }
}

/// Checks that `rom` is there and fits (Fourier mode) and returns it.
pub(crate) fn check_rom<'a>(
    params: &PixelParams,
    rom: Option<&'a RomImage>,
) -> Result<&'a RomImage, PixelError> {
    let rom = rom.ok_or_else(|| PixelError::mismatch("ROM", "none", "a ROM in Fourier mode"))?;
    if rom.registers() < params.registers() {
        return Err(PixelError::mismatch(
            "ROM bits per entry",
            rom.registers(),
            format!("at least R = {}", params.registers()),
        ));
    }
    if rom.depth() != params.rom_depth {
        return Err(PixelError::mismatch(
            "ROM depth",
            rom.depth(),
            format!("L = {}", params.rom_depth),
        ));
    }
    Ok(rom)
}

/// N as a usize, checking that the stimuli are whole frames.
pub(crate) fn frame_len(params: &PixelParams, len: usize) -> Result<usize, PixelError> {
    let n = usize::try_from(params.frame_pulses)
        .map_err(|_| PixelError::mismatch("frame length", params.frame_pulses, "N ≤ usize::MAX"))?;
    if !len.is_multiple_of(n) {
        return Err(PixelError::mismatch(
            "stimulus length",
            len,
            format!("a whole number of frames of N = {n} pulses"),
        ));
    }
    Ok(n)
}
