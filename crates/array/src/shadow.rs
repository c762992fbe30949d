//! The double-buffered pixel's shadow copy and its readout (docs/pixel-contract.md "Double
//! buffer"), as `templates/pixel.v` renders them with `[array] double_buffer`: at the
//! `swap` edge the registers and the status word are copied into the shadow (the pixel's
//! cycle model then clears its own, `CycleModel::swap_clear`); a readout strobe streams
//! the shadow's R words and its status word, one a cycle, on the pixel's `rd_*` outputs,
//! without touching the registers or the pipeline — the next frame accumulates meanwhile.

use tofprobe_pixel::{CycleModel, PinsOut};

/// One pixel's shadow registers and the readout that reads them.
#[derive(Debug, Clone)]
pub struct Shadow {
    /// The R registers' raw W-bit words at the last swap.
    words: Vec<u64>,
    /// The refused-pulse counter at the last swap (the status word).
    status: u64,
    mask: u64,
    rd_active: bool,
    rd_ptr: usize,
    rd_valid: bool,
    rd_index: u32,
    rd_data: u64,
}

impl Shadow {
    /// The shadow of a pixel of `registers` registers of `width` bits, empty, in reset.
    pub fn new(registers: usize, width: u32) -> Shadow {
        Shadow {
            words: vec![0; registers],
            status: 0,
            mask: if width >= 64 {
                u64::MAX
            } else {
                (1u64 << width) - 1
            },
            rd_active: false,
            rd_ptr: 0,
            rd_valid: false,
            rd_index: 0,
            rd_data: 0,
        }
    }

    /// The pixel's readout outputs during this cycle (`ready` is the pixel's own).
    pub fn outputs(&self, ready: bool) -> PinsOut {
        PinsOut {
            ready,
            rd_valid: self.rd_valid,
            rd_index: self.rd_index,
            rd_data: self.rd_data,
        }
    }

    /// The shadow's words at the last swap (raw W bits) and the status word.
    pub fn words(&self) -> (&[u64], u64) {
        (&self.words, self.status)
    }

    /// One rising edge: `rst`, the `readout` strobe and the `swap` strobe, with `pixel`'s
    /// registers and counter as they stood before this edge (`sampled`; `None` when no
    /// swap). The readout reads the old shadow at the edge that loads the new one. The
    /// shadow has no reset and its load is not gated by it (as in the RTL: a swap during
    /// reset loads it; nothing reads it before the next swap).
    pub fn step(&mut self, rst: bool, readout: bool, sampled: Option<(&[i64], u64)>) {
        if rst {
            // The pixel's readout control resets.
            (self.rd_active, self.rd_ptr) = (false, 0);
            (self.rd_valid, self.rd_index, self.rd_data) = (false, 0, 0);
        } else {
            self.readout_edge(readout);
        }
        if let Some((y, refused)) = sampled {
            for (s, &v) in self.words.iter_mut().zip(y) {
                *s = v as u64 & self.mask;
            }
            self.status = refused & self.mask;
        }
    }

    /// The readout's edge: the next shadow word out, or the status word, which ends it; a
    /// strobe (re)starts it.
    fn readout_edge(&mut self, readout: bool) {
        let r = self.words.len();
        if self.rd_active {
            self.rd_valid = true;
            if self.rd_ptr < r {
                self.rd_data = self.words[self.rd_ptr];
                self.rd_index = self.rd_ptr as u32;
                self.rd_ptr += 1;
            } else {
                self.rd_data = self.status & self.mask;
                self.rd_index = r as u32;
                self.rd_active = false;
            }
        } else {
            self.rd_valid = false;
        }
        if readout {
            (self.rd_active, self.rd_ptr) = (true, 0);
        }
    }
}

/// What the swap edge samples of `pixel`: its registers and its refused-pulse counter.
pub fn sample(pixel: &CycleModel) -> (Vec<i64>, u64) {
    (pixel.registers().to_vec(), pixel.refused())
}
