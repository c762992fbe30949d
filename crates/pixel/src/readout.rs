//! A frame's readout (the R register words and the status word), and the collector that
//! rebuilds it from the cycle model's (or the RTL's) readout bus.

use crate::cycle::PinsOut;
use crate::fixed::sign_extend;

/// One frame's readout: the R registers, sign-extended from W bits, and the status word
/// (pulses refused since the previous status word).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Readout {
    /// Register words in register order (Fourier: 2k = I of bin k, 2k+1 = Q of bin k).
    pub words: Vec<i64>,
    /// Refused pulse strobes (saturating at 2^W − 1).
    pub refused: u64,
}

/// Assembles [`Readout`]s from the `rd_valid`/`rd_index`/`rd_data` outputs, one cycle at a
/// time, as a testbench would.
#[derive(Debug, Clone)]
pub struct ReadoutCollector {
    registers: usize,
    width: u32,
    words: Vec<Option<i64>>,
}

impl ReadoutCollector {
    /// A collector for `registers` words of `width` bits.
    pub fn new(registers: usize, width: u32) -> Self {
        ReadoutCollector {
            registers,
            width,
            words: vec![None; registers],
        }
    }

    /// Feeds one cycle's outputs; returns the frame when its status word arrives. Words
    /// that never arrived read as 0 (a protocol error the caller's comparison will show).
    pub fn push(&mut self, out: &PinsOut) -> Option<Readout> {
        if !out.rd_valid {
            return None;
        }
        let i = out.rd_index as usize;
        if i < self.registers {
            self.words[i] = Some(sign_extend(out.rd_data, self.width));
            None
        } else {
            let words = self.words.iter().map(|w| w.unwrap_or(0)).collect();
            self.words.iter_mut().for_each(|w| *w = None);
            Some(Readout {
                words,
                refused: out.rd_data,
            })
        }
    }
}
