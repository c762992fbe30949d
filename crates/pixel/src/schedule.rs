//! The adder schedule, defined once (docs/pixel-contract.md, "Accumulate schedule"): which
//! register operation each adder performs in each slot of a pulse, and which register it
//! touches with which sign. The cycle model executes it slot by slot, the transaction model
//! pulse by pulse, and tofprobe-rtlgen renders its case tables from it.
//!
//! Operation j = slot·A + a (0 ≤ j < P) belongs to adder a in slot `slot`:
//! - Fourier: register r = j, added when ROM bit r is 1;
//! - Haar: scale u = j, register 2^u − 1 + (n >> (L − u)) of the latched pulse index n
//!   (L = log2 N), added when bit L − u − 1 of n is 0 (first half of the wavelet).

use std::ops::Range;

use crate::params::{Mode, PixelParams};

/// One register operation of a pulse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Operation {
    /// Fourier: `register` ± the operand, by ROM bit `register`.
    Fourier {
        /// Register r (and ROM bit r).
        register: usize,
    },
    /// Haar: the register of scale `scale` selected by the pulse index.
    Haar {
        /// Scale u.
        scale: u32,
    },
}

impl Operation {
    /// The register and sign (`true` = add) of this operation for latched pulse index
    /// `n_lat` in a frame of 2^`log2_n` pulses (Haar) or ROM word `bits` (Fourier).
    #[inline(always)]
    pub fn target(self, n_lat: u64, log2_n: u32, bits: &[u64]) -> (usize, bool) {
        match self {
            Operation::Fourier { register } => (register, rom_bit(bits, register)),
            Operation::Haar { scale } => haar_target(n_lat, scale, log2_n),
        }
    }

    /// The registers this operation may touch (one for Fourier, the 2^u of scale u for
    /// Haar), in selector order.
    pub fn registers(self) -> Range<usize> {
        match self {
            Operation::Fourier { register } => register..register + 1,
            Operation::Haar { scale } => (1usize << scale) - 1..(1usize << (scale + 1)) - 1,
        }
    }

    /// Haar: the pulse-index bits (high, low) that select the register within the scale,
    /// `None` when the scale has one register (u = 0) or in Fourier mode.
    pub fn select_bits(self, log2_n: u32) -> Option<(u32, u32)> {
        match self {
            Operation::Haar { scale } if scale > 0 => Some((log2_n - 1, log2_n - scale)),
            _ => None,
        }
    }

    /// Haar: the pulse-index bit whose 0 means add (L − u − 1); `None` in Fourier mode
    /// (the sign is ROM bit r).
    pub fn sign_bit(self, log2_n: u32) -> Option<u32> {
        match self {
            Operation::Haar { scale } => Some(log2_n - scale - 1),
            Operation::Fourier { .. } => None,
        }
    }
}

/// The schedule of one configuration: P operations on A adders over K slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Schedule {
    mode: Mode,
    adders: usize,
    ops: usize,
    slots: usize,
}

impl Schedule {
    /// The schedule of `p` (validated parameters: 1 ≤ A ≤ P).
    pub fn new(p: &PixelParams) -> Self {
        Schedule {
            mode: p.mode,
            adders: p.adders,
            ops: p.ops_per_pulse(),
            slots: p.slots(),
        }
    }

    /// K: slots per pulse.
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// A: adders.
    pub fn adders(&self) -> usize {
        self.adders
    }

    /// Operation j of a pulse (0 ≤ j < P).
    #[inline(always)]
    pub fn operation(&self, j: usize) -> Operation {
        match self.mode {
            Mode::Fourier => Operation::Fourier { register: j },
            Mode::Haar => Operation::Haar { scale: j as u32 },
        }
    }

    /// What adder `adder` does in slot `slot`: operation j = slot·A + a, `None` when
    /// j ≥ P (the adder idles in the pulse's last slot).
    #[inline(always)]
    pub fn at(&self, slot: usize, adder: usize) -> Option<Operation> {
        let j = slot * self.adders + adder;
        (j < self.ops).then(|| self.operation(j))
    }

    /// The operations of slot `slot`, in adder order.
    #[inline(always)]
    pub fn slot(&self, slot: usize) -> impl Iterator<Item = Operation> + '_ {
        (0..self.adders).map_while(move |a| self.at(slot, a))
    }

    /// The operations of adder `adder` over a pulse, as (slot, operation).
    pub fn adder(&self, adder: usize) -> impl Iterator<Item = (usize, Operation)> + '_ {
        (0..self.slots).filter_map(move |s| self.at(s, adder).map(|op| (s, op)))
    }

    /// All operations of a pulse, in operation order j = 0..P.
    pub fn pulse(&self) -> impl Iterator<Item = Operation> + '_ {
        (0..self.ops).map(|j| self.operation(j))
    }
}

/// Register and sign of Haar scale `u` for pulse `n` of a frame of 2^`log2_n` pulses:
/// register 2^u − 1 + v with v = n >> (L − u); `true` (add) in the first half of the
/// wavelet's support, i.e. when bit L − u − 1 of n is 0.
#[inline(always)]
pub fn haar_target(n: u64, u: u32, log2_n: u32) -> (usize, bool) {
    let v = (n >> (log2_n - u)) as usize;
    let add = (n >> (log2_n - u - 1)) & 1 == 0;
    ((1usize << u) - 1 + v, add)
}

/// Bit r of a packed ROM word (bits beyond the supplied words read as 0).
#[inline(always)]
pub fn rom_bit(word: &[u64], r: usize) -> bool {
    word.get(r / 64).is_some_and(|w| (w >> (r % 64)) & 1 == 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default Fourier pixel (P = 32, A = 2): slot c runs registers 2c and 2c + 1;
    /// a Haar pixel with U = 4, A = 2 (P = 5, K = 3): adder 1 idles in slot 2.
    #[test]
    fn slots_follow_j_equals_slot_times_a_plus_adder() {
        let p = PixelParams::fourier_default(39, 1 << 20, 64);
        let s = Schedule::new(&p);
        assert_eq!(
            s.slot(5).collect::<Vec<_>>(),
            [
                Operation::Fourier { register: 10 },
                Operation::Fourier { register: 11 }
            ]
        );
        let mut h = p.clone();
        h.mode = Mode::Haar;
        let s = Schedule::new(&h);
        assert_eq!(s.slots(), 3);
        assert_eq!(
            s.slot(2).collect::<Vec<_>>(),
            [Operation::Haar { scale: 4 }]
        );
        assert_eq!(
            s.adder(1).collect::<Vec<_>>(),
            [
                (0, Operation::Haar { scale: 1 }),
                (1, Operation::Haar { scale: 3 })
            ]
        );
        // Scale 3 of N = 2^20, pulse n = 0b1011 << 16: v = n >> 17 = 5, sign bit 16 = 1.
        let op = Operation::Haar { scale: 3 };
        assert_eq!(op.target(0b1011 << 16, 20, &[]), (7 + 5, false));
        assert_eq!(op.registers(), 7..15);
        assert_eq!(
            (op.select_bits(20), op.sign_bit(20)),
            (Some((19, 17)), Some(16))
        );
    }
}
