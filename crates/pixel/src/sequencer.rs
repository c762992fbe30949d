//! The contract's reference sequencer: the cycle-by-cycle pin stimulus that testbenches and
//! golden vectors drive, generated lazily from per-pulse detections and the ROM.
//!
//! First `rst` high for 2 cycles. Then per frame: for each pulse n, one `pulse` cycle (with
//! `valid`, `tdc` and ROM word n mod L) and C − 1 idle cycles; after the last pulse, one
//! `readout` cycle and R + 1 idle cycles while the words come out. The golden vectors add
//! one cycle ([`Sequencer::with_status_cycle`]) in which the last status word is seen.
//!
//! [`Sequencer::directed`] walks the directed schedule instead ([`crate::directed`]): the
//! same reset, then loop after loop of its [`Program`].

use tofprobe_dsp::RomImage;

use crate::chip::{ChipSequencer, Walk};
use crate::cycle::PinsIn;
use crate::directed::Program;
use crate::error::PixelError;
use crate::params::{Mode, PixelParams};
use crate::transaction::{check_rom, frame_len};

/// Cycles of reset at the start.
pub const RESET_CYCLES: u64 = 2;

/// What a cycle of the reference sequence is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Reset cycle.
    Reset,
    /// Pulse `pulse` of frame `frame` is presented.
    Pulse {
        /// Frame index.
        frame: u64,
        /// Pulse index in the frame.
        pulse: u64,
    },
    /// Idle cycle after a pulse.
    Idle,
    /// The readout strobe of frame `frame`.
    Readout {
        /// Frame index.
        frame: u64,
    },
    /// Idle cycle while the words come out.
    Draining,
}

/// Iterator over the reference sequencer's [`PinsIn`], one per clock cycle.
#[derive(Debug, Clone)]
pub struct Sequencer<'a> {
    stimuli: &'a [Option<u32>],
    rom: Option<&'a RomImage>,
    n: u64,
    c: u64,
    frame_cycles: u64,
    total: u64,
    cycle: u64,
    rom_depth: u64,
    /// The directed schedule, when this is not the reference sequencer.
    program: Option<Program>,
    /// The chip's one sequencer walking this one pixel: what [`Iterator::next`] steps (the
    /// same registers as the RTL's `<prefix>_sequencer`; [`Sequencer::phase`] divides the
    /// cycle index instead, for any cycle, and the two are tested equal).
    chip: ChipSequencer,
    /// Pulses presented so far: the next one's detection index.
    presented: u64,
}

/// Presents no detection for pulses beyond the stimuli (the status cycle's pulse).
fn detection(stimuli: &[Option<u32>], index: u64) -> Option<u32> {
    usize::try_from(index)
        .ok()
        .and_then(|i| stimuli.get(i))
        .copied()
        .flatten()
}

impl<'a> Sequencer<'a> {
    /// The sequence for `stimuli.len() / N` frames (the stimuli must be whole frames). A
    /// Fourier pixel needs the ROM; a Haar pixel ignores it.
    pub fn new(
        params: &PixelParams,
        stimuli: &'a [Option<u32>],
        rom: Option<&'a RomImage>,
    ) -> Result<Self, PixelError> {
        params.validate()?;
        let n = frame_len(params, stimuli.len())? as u64;
        let rom = match params.mode {
            Mode::Fourier => Some(check_rom(params, rom)?),
            Mode::Haar => None,
        };
        let c = params.cycles_per_pulse as u64;
        let frame_cycles = n * c + params.registers() as u64 + 2;
        let frames = stimuli.len() as u64 / n;
        let rom_depth = params.rom_depth.max(1) as u64;
        Ok(Sequencer {
            stimuli,
            rom,
            n,
            c,
            frame_cycles,
            total: RESET_CYCLES + frames * frame_cycles,
            cycle: 0,
            rom_depth,
            program: None,
            chip: ChipSequencer::new(n, c, rom_depth, Walk::single(params.registers())),
            presented: 0,
        })
    }

    /// The directed sequence: reset, then `loops` loops of `program` (built for `params`
    /// by [`crate::directed::directed_program`]). `stimuli` holds one detection per pulse
    /// strobe (`loops` · [`Program::loop_pulses`]; strobes beyond it present no detection).
    /// A Fourier pixel needs the ROM; a Haar pixel ignores it.
    pub fn directed(
        params: &PixelParams,
        program: Program,
        stimuli: &'a [Option<u32>],
        rom: Option<&'a RomImage>,
        loops: u64,
    ) -> Result<Self, PixelError> {
        params.validate()?;
        let rom = match params.mode {
            Mode::Fourier => Some(check_rom(params, rom)?),
            Mode::Haar => None,
        };
        let loop_cycles = program.loop_cycles();
        let (n, c) = (params.frame_pulses, params.cycles_per_pulse as u64);
        let rom_depth = params.rom_depth.max(1) as u64;
        Ok(Sequencer {
            stimuli,
            rom,
            n,
            c,
            frame_cycles: loop_cycles,
            total: RESET_CYCLES + loops * loop_cycles,
            cycle: 0,
            rom_depth,
            program: Some(program),
            chip: ChipSequencer::new(n, c, rom_depth, Walk::single(params.registers())),
            presented: 0,
        })
    }

    /// The directed schedule this sequence walks (`None`: the reference sequencer).
    pub fn program(&self) -> Option<&Program> {
        self.program.as_ref()
    }

    /// The sequence with one more cycle at its end, in which the last frame's status word
    /// (registered at the edge ending its last idle cycle) is seen on the pins. Like the
    /// chip's sequencer, that cycle presents the next frame's first pulse (no detection,
    /// ROM address 0).
    pub fn with_status_cycle(mut self) -> Self {
        self.total += 1;
        self
    }

    /// The global index (frame·N + pulse) of the pulse presented in cycle `cycle`, if any.
    pub fn pulse_index(&self, cycle: u64) -> Option<u64> {
        if let Some(prog) = &self.program {
            let t = cycle.checked_sub(RESET_CYCLES)?;
            let a = prog.at(t % prog.loop_cycles());
            return a
                .pulse
                .then(|| t / prog.loop_cycles() * prog.loop_pulses() + a.pulse_in_loop);
        }
        match self.phase(cycle) {
            Phase::Pulse { frame, pulse } => Some(frame * self.n + pulse),
            _ => None,
        }
    }

    /// Total cycles of the sequence: 2 + frames·(N·C + R + 2) (+ 1 with the status cycle).
    pub fn total_cycles(&self) -> u64 {
        self.total
    }

    /// Cycles per frame, N·C + R + 2 (directed: cycles per loop).
    pub fn frame_cycles(&self) -> u64 {
        self.frame_cycles
    }

    /// What cycle `cycle` of the sequence does (directed: `frame` counts loops, `pulse`
    /// the pulse strobes of the loop; a cycle with both strobes is a `Pulse`, a reset
    /// strobe in the middle of a frame a `Reset`).
    pub fn phase(&self, cycle: u64) -> Phase {
        if cycle < RESET_CYCLES {
            return Phase::Reset;
        }
        let t = cycle - RESET_CYCLES;
        if let Some(prog) = &self.program {
            let frame = t / prog.loop_cycles();
            let a = prog.at(t % prog.loop_cycles());
            return match (a.pulse, a.readout) {
                (true, _) => Phase::Pulse {
                    frame,
                    pulse: a.pulse_in_loop,
                },
                (false, true) => Phase::Readout { frame },
                (false, false) if a.reset => Phase::Reset,
                (false, false) => Phase::Idle,
            };
        }
        let frame = t / self.frame_cycles;
        let within = t % self.frame_cycles;
        let pulses = self.n * self.c;
        if within < pulses {
            if within.is_multiple_of(self.c) {
                Phase::Pulse {
                    frame,
                    pulse: within / self.c,
                }
            } else {
                Phase::Idle
            }
        } else if within == pulses {
            Phase::Readout { frame }
        } else {
            Phase::Draining
        }
    }

    /// The pins of cycle `cycle`.
    pub fn pins(&self, cycle: u64) -> PinsIn<'a> {
        if let (Some(prog), Some(t)) = (&self.program, cycle.checked_sub(RESET_CYCLES)) {
            let a = prog.at(t % prog.loop_cycles());
            if !a.pulse {
                return PinsIn {
                    rst: a.reset,
                    readout: a.readout,
                    ..PinsIn::default()
                };
            }
            let index = t / prog.loop_cycles() * prog.loop_pulses() + a.pulse_in_loop;
            let det = detection(self.stimuli, index);
            return PinsIn {
                pulse: true,
                valid: det.is_some(),
                tdc: det.unwrap_or(0),
                rom_word: self.rom_word(a.address),
                readout: a.readout,
                ..PinsIn::default()
            };
        }
        match self.phase(cycle) {
            Phase::Reset => PinsIn {
                rst: true,
                ..PinsIn::default()
            },
            Phase::Pulse { frame, pulse } => {
                let det = detection(self.stimuli, frame * self.n + pulse);
                let rom_word = self.rom_word(pulse);
                PinsIn {
                    pulse: true,
                    valid: det.is_some(),
                    tdc: det.unwrap_or(0),
                    rom_word,
                    ..PinsIn::default()
                }
            }
            Phase::Readout { .. } => PinsIn {
                readout: true,
                ..PinsIn::default()
            },
            Phase::Idle | Phase::Draining => PinsIn::default(),
        }
    }
}

impl<'a> Sequencer<'a> {
    /// The ROM word of pulse `n` of a frame (address n mod L; empty in Haar mode).
    fn rom_word(&self, n: u64) -> &'a [u64] {
        self.rom
            .map(|rom| rom.entry((n % self.rom_depth) as usize))
            .unwrap_or(&[])
    }
}

impl<'a> Iterator for Sequencer<'a> {
    type Item = PinsIn<'a>;

    #[inline]
    fn next(&mut self) -> Option<PinsIn<'a>> {
        if self.cycle >= self.total {
            return None;
        }
        if self.program.is_some() || self.cycle < RESET_CYCLES {
            let pins = self.pins(self.cycle);
            self.cycle += 1;
            return Some(pins);
        }
        // The reference sequence by stepping the chip's sequencer: the same pins as
        // `pins(cycle)` (tested).
        let o = self.chip.strobes(false);
        let pins = if o.pulse {
            let det = detection(self.stimuli, self.presented);
            self.presented += 1;
            PinsIn {
                pulse: true,
                valid: det.is_some(),
                tdc: det.unwrap_or(0),
                rom_word: self
                    .rom
                    .map(|rom| rom.entry(o.addr as usize))
                    .unwrap_or(&[]),
                ..PinsIn::default()
            }
        } else {
            PinsIn {
                readout: o.readout,
                ..PinsIn::default()
            }
        };
        self.chip.edge(false);
        self.cycle += 1;
        Some(pins)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = usize::try_from(self.total - self.cycle).unwrap_or(usize::MAX);
        (left, Some(left))
    }
}

impl ExactSizeIterator for Sequencer<'_> {}
