//! The contract's reference sequencer: 2 reset cycles, then per frame N pulses one every C
//! cycles (ROM address = pulse index in the frame mod L), then one readout cycle and R+1
//! idle cycles, and one trailing cycle to see the last status word. Yields the inputs cycle by cycle without materialising the cycle stream.

use crate::model::PinsIn;
use crate::params::PixelParams;

/// Cycle-by-cycle inputs for `frames` frames of the given per-pulse stimulus.
#[derive(Debug, Clone)]
pub struct Sequencer<'a> {
    stim: &'a [Option<u32>],
    n: u64,
    c: u64,
    l: u64,
    ro_cycles: u64,
    frames: u64,
    cycle: u64,
    /// Global index of the next pulse to present.
    next_pulse: u64,
}

/// One cycle of the sequence: the inputs plus the bookkeeping a checker needs.
#[derive(Debug, Clone, Copy)]
pub struct SeqCycle {
    pub cycle: u64,
    pub pins: PinsIn,
    /// Global pulse index presented this cycle, if any.
    pub pulse_index: Option<u64>,
}

impl<'a> Sequencer<'a> {
    /// `stim` holds frames·N pulses (`Some(code)` = detection).
    pub fn new(p: &PixelParams, stim: &'a [Option<u32>], frames: u64) -> Self {
        Sequencer {
            stim,
            n: p.frame_pulses,
            c: p.cycles_per_pulse as u64,
            l: p.rom_depth as u64,
            ro_cycles: p.registers() as u64 + 2,
            frames,
            cycle: 0,
            next_pulse: 0,
        }
    }

    /// Cycles of one frame: N·C pulse cycles plus the readout cycle and R+1 idle cycles.
    pub fn frame_cycles(&self) -> u64 {
        self.n * self.c + self.ro_cycles
    }

    /// Total cycles: 2 reset cycles, the frames, and one trailing cycle in which the last
    /// frame's status word (registered at the edge ending its last idle cycle) is seen. That
    /// cycle presents the next frame's first pulse with no detection, as the hardware
    /// sequencer does.
    pub fn total_cycles(&self) -> u64 {
        2 + self.frames * self.frame_cycles() + 1
    }
}

impl Iterator for Sequencer<'_> {
    type Item = SeqCycle;

    fn next(&mut self) -> Option<SeqCycle> {
        let cycle = self.cycle;
        if cycle >= self.total_cycles() {
            return None;
        }
        self.cycle += 1;
        let mut pins = PinsIn::default();
        let mut pulse_index = None;
        if cycle < 2 {
            pins.rst = true;
        } else {
            let t = (cycle - 2) % self.frame_cycles();
            let pulse_phase = self.n * self.c;
            if t < pulse_phase {
                if t.is_multiple_of(self.c) {
                    let n_in_frame = t / self.c;
                    let g = self.next_pulse;
                    self.next_pulse += 1;
                    let det = self.stim.get(g as usize).copied().flatten();
                    pins.pulse = true;
                    pins.valid = det.is_some();
                    pins.tdc = det.unwrap_or(0);
                    pins.rom_addr = (n_in_frame % self.l) as usize;
                    pulse_index = Some(g);
                }
            } else if t == pulse_phase {
                pins.readout = true;
            }
        }
        Some(SeqCycle {
            cycle,
            pins,
            pulse_index,
        })
    }
}
