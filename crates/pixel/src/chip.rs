//! The chip's one sequencer, register by register as `templates/sequencer.v` builds it: the
//! pulse strobes (one every C cycles, N a frame, each with its probe ROM address), then the
//! readout walk over the pixels (row-major, one readout strobe every slot), single-buffered
//! after the frame, double-buffered beside the next one. The single pixel's reference
//! sequencer ([`crate::Sequencer`]) steps it walking one pixel (slot R + 1); the array's
//! register-level model (`tofprobe_array::rtl_model`) steps it walking the array. Neither counts
//! the schedule itself, so the two tops cannot disagree about it.

/// What the readout walks: the pixels, the row's length, the slot and the buffering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Walk {
    /// Pixels read out per frame (PIXELS).
    pub pixels: u64,
    /// Pixels per row (COLS): the walk's column wraps after it.
    pub cols: u64,
    /// Cycles between two pixels' readout strobes (SLOT).
    pub slot: u64,
    /// The walk runs beside the next frame's pulses (DOUBLE_BUFFER).
    pub double_buffer: bool,
}

impl Walk {
    /// The single pixel's walk: one pixel, its readout strobe and the R + 1 cycles its
    /// words take (`registers` = R).
    pub fn single(registers: usize) -> Walk {
        Walk {
            pixels: 1,
            cols: 1,
            slot: registers as u64 + 1,
            double_buffer: false,
        }
    }

    /// Cycles of the walk: PIXELS · SLOT + 1 (saturating: a refused shape never overflows).
    pub fn cycles(&self) -> u64 {
        self.pixels.saturating_mul(self.slot).saturating_add(1)
    }
}

/// The sequencer's outputs during a cycle (before its edge).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Strobes {
    /// A pulse is presented: the pixels sample `valid`/`tdc` this cycle.
    pub pulse: bool,
    /// The readout strobe of pixel `q`.
    pub readout: bool,
    /// Double-buffered: the shadows take the registers (the walk's first cycle).
    pub swap: bool,
    /// The pixel the walk is at (PIXELS once it is done).
    pub q: u64,
    /// Its row.
    pub row: u64,
    /// Its column.
    pub col: u64,
    /// The probe ROM address of the pulse (pulse index mod L).
    pub addr: u64,
}

/// The sequencer's registers (`ro_phase`, `hold`, `ph`, `pidx`, `qi`, `sc`, `qr`, `qc`,
/// `wt`, `ai` of `templates/sequencer.v`) and its constants.
#[derive(Debug, Clone)]
pub struct ChipSequencer {
    n: u64,
    c: u64,
    rom_depth: u64,
    walk: Walk,
    /// Double-buffered: the cycles the pulses wait after a frame's last one beyond the
    /// swap cycle, max(PIXELS·SLOT + 1 − N·C − 1, 0).
    wait: u64,
    ro_phase: bool,
    hold: bool,
    ph: u64,
    pidx: u64,
    q: u64,
    sc: u64,
    qr: u64,
    qc: u64,
    wt: u64,
    addr: u64,
}

impl ChipSequencer {
    /// In its reset state: frames of `frame_pulses` pulses, `cycles_per_pulse` cycles
    /// apart, ROM addresses mod `rom_depth` (each at least 1), then `walk`.
    pub fn new(frame_pulses: u64, cycles_per_pulse: u64, rom_depth: u64, walk: Walk) -> Self {
        let (n, c) = (frame_pulses.max(1), cycles_per_pulse.max(1));
        let acc = n.saturating_mul(c);
        let wait = if walk.double_buffer {
            walk.cycles().saturating_sub(acc.saturating_add(1))
        } else {
            0
        };
        ChipSequencer {
            n,
            c,
            rom_depth: rom_depth.max(1),
            walk,
            wait,
            ro_phase: false,
            hold: false,
            ph: 0,
            pidx: 0,
            q: 0,
            sc: 0,
            qr: 0,
            qc: 0,
            wt: 0,
            addr: 0,
        }
    }

    /// The walk it follows.
    pub fn walk(&self) -> Walk {
        self.walk
    }

    /// The pulses wait: for the walk (single-buffered) or the hold (double-buffered).
    fn waiting(&self) -> bool {
        if self.walk.double_buffer {
            self.hold
        } else {
            self.ro_phase
        }
    }

    /// The outputs during this cycle, with `rst` high or low.
    #[inline]
    pub fn strobes(&self, rst: bool) -> Strobes {
        let walk_start = self.ro_phase && self.sc == 0;
        Strobes {
            pulse: !rst && !self.waiting() && self.ph == 0,
            readout: !rst && walk_start && self.q != self.walk.pixels,
            swap: self.walk.double_buffer && !rst && walk_start && self.q == 0,
            q: self.q,
            row: self.qr,
            col: self.qc,
            addr: self.addr,
        }
    }

    /// Every register to zero (a cycle with `rst` high).
    pub fn reset(&mut self) {
        *self = ChipSequencer::new(self.n, self.c, self.rom_depth, self.walk);
    }

    /// One rising edge with `rst` as given.
    #[inline]
    pub fn edge(&mut self, rst: bool) {
        if rst {
            return self.reset();
        }
        // Every decision reads the registers before the edge (Verilog's non-blocking
        // assignments): the walk's end must not free this edge's pulses.
        let waiting = self.waiting();
        let frame_end = !waiting && self.ph == self.c - 1 && self.pidx == self.n - 1;
        if self.ro_phase {
            self.walk_edge();
        }
        if self.walk.double_buffer && self.hold {
            if self.wt == 0 {
                self.hold = false;
            } else {
                self.wt -= 1;
            }
        } else if !waiting {
            if self.ph == self.c - 1 {
                self.ph = 0;
                self.pidx = if self.pidx == self.n - 1 {
                    0
                } else {
                    self.pidx + 1
                };
                self.addr = if self.addr == self.rom_depth - 1 {
                    0
                } else {
                    self.addr + 1
                };
            } else {
                self.ph += 1;
            }
        }
        // The frame's end starts the walk, after the updates above so the restart wins.
        if frame_end {
            self.ro_phase = true;
            self.hold = self.walk.double_buffer;
            self.wt = self.wait;
            (self.q, self.sc, self.qr, self.qc, self.addr) = (0, 0, 0, 0, 0);
        }
    }

    /// The walk's edge: a slot of SLOT cycles per pixel, row-major, then its last cycle.
    fn walk_edge(&mut self) {
        if self.q == self.walk.pixels {
            self.ro_phase = false;
        } else if self.sc == self.walk.slot - 1 {
            self.sc = 0;
            self.q += 1;
            if self.qc == self.walk.cols - 1 {
                (self.qc, self.qr) = (0, self.qr + 1);
            } else {
                self.qc += 1;
            }
        } else {
            self.sc += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The single pixel's frame: N pulses C apart, the readout strobe right after the last
    /// pulse's C cycles, R + 1 more cycles, then the next frame — N·C + R + 2 cycles, as
    /// docs/pixel-contract.md "The reference sequencer" states.
    #[test]
    fn the_single_walk_is_the_reference_frame() {
        let (n, c, r) = (5u64, 3u64, 4usize);
        let mut s = ChipSequencer::new(n, c, 2, Walk::single(r));
        let frame = n * c + r as u64 + 2;
        let mut seen = Vec::new();
        for t in 0..2 * frame {
            let o = s.strobes(false);
            seen.push((o.pulse, o.readout, o.addr));
            s.edge(false);
            let within = t % frame;
            let want_pulse = within < n * c && within.is_multiple_of(c);
            assert_eq!(o.pulse, want_pulse, "cycle {t}");
            assert_eq!(o.readout, within == n * c, "cycle {t}");
            if want_pulse {
                assert_eq!(o.addr, (within / c) % 2, "cycle {t}");
            }
            assert!(!o.swap);
        }
        assert_eq!(seen[..frame as usize], seen[frame as usize..]);
    }

    /// Double-buffered, the walk overlaps the next frame: the swap is its first cycle, one
    /// readout strobe per pixel SLOT apart, and the next frame's first pulse comes
    /// max(N·C + 1, PIXELS·SLOT + 1) cycles after the last frame's first.
    #[test]
    fn the_double_buffered_walk_overlaps_the_next_frame() {
        let walk = Walk {
            pixels: 6,
            cols: 3,
            slot: 4,
            double_buffer: true,
        };
        let (n, c) = (4u64, 2u64);
        let mut s = ChipSequencer::new(n, c, 1, walk);
        let mut pulses = Vec::new();
        let mut strobes = Vec::new();
        let mut swaps = Vec::new();
        for t in 0..60u64 {
            let o = s.strobes(false);
            if o.pulse {
                pulses.push(t);
            }
            if o.readout {
                strobes.push((t, o.row, o.col));
            }
            if o.swap {
                swaps.push(t);
            }
            s.edge(false);
        }
        let period = (n * c + 1).max(walk.cycles());
        assert_eq!(pulses[..5], [0, 2, 4, 6, period]);
        assert_eq!(swaps[0], n * c);
        let want: Vec<(u64, u64, u64)> = (0..6).map(|q| (n * c + 4 * q, q / 3, q % 3)).collect();
        assert_eq!(strobes[..6], want[..]);
    }
}
