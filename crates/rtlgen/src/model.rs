//! A cycle-accurate reference of docs/pixel-contract.md, written from the contract alone,
//! plus the contract's reference sequencer. The golden vectors are produced from it; it
//! also carries the deliberate faults (`Fault`) that the mutation tests inject into the
//! RTL, so the cycle where each fault first shows is computed by the model, independently
//! of any simulator.

use crate::params::{Mode, PixelParams};

/// Inputs of one clock cycle (contract "Pins").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PinsIn {
    pub rst: bool,
    pub pulse: bool,
    pub valid: bool,
    pub tdc: u32,
    /// ROM address of the word presented with `pulse` (the word itself is read from the
    /// ROM image the model was given, as the chip's ROM does).
    pub rom_addr: usize,
    pub readout: bool,
}

/// Outputs as seen during a cycle, before its rising edge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PinsOut {
    pub ready: bool,
    pub rd_valid: bool,
    pub rd_index: u32,
    /// Raw W-bit pattern.
    pub rd_data: u64,
}

/// A deliberate RTL fault, mirrored in the model so its first visible cycle is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Every accumulate subtracts where it should add and vice versa.
    SignFlip,
    /// Register writes land one clock edge late.
    ScheduleLate,
    /// Register 0 is one bit narrower (W−1 bits, sign-extended when read).
    NarrowRegister,
    /// The hold takes the TDC code of pulses without a detection too.
    HoldInvalid,
    /// The prefilter shifts logically instead of arithmetically.
    LogicalShift,
}

impl Fault {
    /// All faults, in a fixed order.
    pub const ALL: [Fault; 5] = [
        Fault::SignFlip,
        Fault::ScheduleLate,
        Fault::NarrowRegister,
        Fault::HoldInvalid,
        Fault::LogicalShift,
    ];

    /// The name used by templates and reports.
    pub fn name(self) -> &'static str {
        match self {
            Fault::SignFlip => "sign_flip",
            Fault::ScheduleLate => "schedule_late",
            Fault::NarrowRegister => "narrow_register",
            Fault::HoldInvalid => "hold_invalid",
            Fault::LogicalShift => "logical_shift",
        }
    }
}

fn mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// Sign-extends the low `bits` bits of `v`.
pub fn sext(v: u64, bits: u32) -> i64 {
    let s = 64 - bits;
    ((v << s) as i64) >> s
}

/// The pixel at the clock edge.
#[derive(Debug, Clone)]
pub struct CycleModel {
    mode: Mode,
    r: usize,
    p: usize,
    a: usize,
    k: usize,
    z: i64,
    s: u32,
    f: u32,
    w: u32,
    n: u64,
    log2n: u32,
    xw: u32,
    fault: Option<Fault>,
    rom: Vec<u64>,
    rom_words: usize,
    // state
    primed: bool,
    held: i64,
    x: i64,
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
    y: Vec<u64>,
    out: PinsOut,
    writes: Vec<(u32, u64)>,
    pending: Vec<(u32, u64)>,
}

impl CycleModel {
    /// A model in its pre-reset state (everything zero). `rom` holds `words_per_entry`
    /// u64 words per address (bit r of an entry = register r), Haar ignores it.
    pub fn new(p: &PixelParams, rom: &[u64], fault: Option<Fault>) -> Self {
        let r = p.registers();
        CycleModel {
            mode: p.mode,
            r,
            p: p.ops_per_pulse(),
            a: p.adders,
            k: p.slots(),
            z: i64::from(p.zoom),
            s: p.shift,
            f: p.effective_frac_bits(),
            w: p.width,
            n: p.frame_pulses,
            log2n: p.log2_frame(),
            xw: p.operand_bits(),
            fault,
            rom: rom.to_vec(),
            rom_words: r.div_ceil(64),
            primed: false,
            held: 0,
            x: 0,
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
            out: PinsOut::default(),
            writes: Vec::with_capacity(r),
            pending: Vec::new(),
        }
    }

    /// Register writes made at the last edge, in adder order: (register, raw W-bit value).
    pub fn writes(&self) -> &[(u32, u64)] {
        &self.writes
    }

    /// The register file, raw W-bit patterns.
    pub fn registers(&self) -> &[u64] {
        &self.y
    }

    fn free(&self) -> bool {
        !self.rd_active && (!self.active || self.slot == self.k - 1)
    }

    /// Returns the outputs seen during this cycle, then applies its rising edge.
    pub fn step(&mut self, i: &PinsIn) -> PinsOut {
        let seen = PinsOut {
            ready: self.free(),
            ..self.out
        };
        self.writes.clear();
        if i.rst {
            self.reset();
            return seen;
        }
        let wmask = mask(self.w);
        let free = self.free();
        let accept_ro = i.readout && free;
        let haar_room = self.mode == Mode::Fourier || self.pcount < self.n;
        let accept_pulse = i.pulse && free && !i.readout && haar_room;
        let refuse = i.pulse && !accept_pulse;

        // Accumulate slot (uses the old op/bits/n_lat/acc_en).
        let mut new_writes: Vec<(u32, u64)> = Vec::new();
        if self.active {
            if self.acc_en {
                let opx = (self.op as u64) & wmask;
                for ad in 0..self.a {
                    let j = self.slot * self.a + ad;
                    if j >= self.p {
                        break;
                    }
                    let (reg, mut add) = match self.mode {
                        Mode::Fourier => (j, (self.bits[j / 64] >> (j % 64)) & 1 == 1),
                        Mode::Haar => {
                            let u = j as u32;
                            let v = self.n_lat >> (self.log2n - u);
                            let reg = (1usize << u) - 1 + v as usize;
                            (reg, (self.n_lat >> (self.log2n - u - 1)) & 1 == 0)
                        }
                    };
                    if self.fault == Some(Fault::SignFlip) {
                        add = !add;
                    }
                    let old = self.y[reg];
                    let val = if add {
                        old.wrapping_add(opx)
                    } else {
                        old.wrapping_sub(opx)
                    } & wmask;
                    new_writes.push((reg as u32, val));
                }
            }
            if self.slot == self.k - 1 {
                self.active = false;
            }
            self.slot += 1;
        }

        // Readout (exclusive with an active pipeline).
        let mut status_edge = false;
        if self.rd_active {
            if self.rd_ptr < self.r {
                self.out = PinsOut {
                    ready: false,
                    rd_valid: true,
                    rd_index: self.rd_ptr as u32,
                    rd_data: self.y[self.rd_ptr],
                };
                new_writes.push((self.rd_ptr as u32, 0));
                self.rd_ptr += 1;
            } else {
                self.out = PinsOut {
                    ready: false,
                    rd_valid: true,
                    rd_index: self.r as u32,
                    rd_data: self.refused,
                };
                status_edge = true;
                self.pcount = 0;
                self.rd_active = false;
            }
        } else {
            self.out.rd_valid = false;
        }
        if accept_ro {
            self.rd_active = true;
            self.rd_ptr = 0;
        }
        if status_edge {
            self.refused = u64::from(refuse);
        } else if refuse && self.refused != wmask {
            self.refused += 1;
        }

        if accept_pulse {
            let d = i64::from(i.tdc) - self.z;
            let take = i.valid || self.fault == Some(Fault::HoldInvalid);
            match self.mode {
                Mode::Fourier => {
                    if self.primed {
                        let diff = (self.held << self.f) - self.x;
                        let step = if self.fault == Some(Fault::LogicalShift) {
                            ((diff as u64 & mask(self.xw + 1)) >> self.s) as i64
                        } else {
                            diff >> self.s
                        };
                        let x_new = sext((self.x + step) as u64, self.xw);
                        self.x = x_new;
                        self.op = x_new;
                        self.acc_en = true;
                    } else {
                        self.acc_en = false;
                    }
                    if take {
                        self.held = d;
                    }
                    if i.valid && !self.primed {
                        self.primed = true;
                        self.x = d << self.f;
                    }
                    let e = i.rom_addr * self.rom_words;
                    self.bits.copy_from_slice(&self.rom[e..e + self.rom_words]);
                }
                Mode::Haar => {
                    let h = if take { d } else { self.held };
                    self.held = h;
                    self.op = h;
                    self.acc_en = self.primed || i.valid;
                    self.primed |= i.valid;
                    self.n_lat = self.pcount;
                }
            }
            self.pcount += 1;
            self.active = true;
            self.slot = 0;
        }

        // Register file update (possibly one edge late, for the fault).
        let applied = if self.fault == Some(Fault::ScheduleLate) {
            std::mem::replace(&mut self.pending, new_writes)
        } else {
            new_writes
        };
        for &(reg, val) in &applied {
            let stored = if self.fault == Some(Fault::NarrowRegister) && reg == 0 {
                (sext(val, self.w - 1) as u64) & wmask
            } else {
                val
            };
            self.y[reg as usize] = stored;
            self.writes.push((reg, stored));
        }
        seen
    }

    /// `rst`: every state element to zero (the ROM and configuration stay).
    fn reset(&mut self) {
        self.primed = false;
        self.held = 0;
        self.x = 0;
        self.op = 0;
        self.bits.iter_mut().for_each(|b| *b = 0);
        self.n_lat = 0;
        self.pcount = 0;
        self.refused = 0;
        self.acc_en = false;
        self.active = false;
        self.slot = 0;
        self.rd_active = false;
        self.rd_ptr = 0;
        self.y.iter_mut().for_each(|v| *v = 0);
        self.out = PinsOut::default();
        self.pending.clear();
    }
}
