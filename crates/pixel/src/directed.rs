//! The directed sequencer: a stimulus schedule beside the reference one that drives every
//! path of the contract the reference sequencer never takes (docs/pixel-contract.md, "The
//! directed sequencer"): pulses into a busy pipeline, during a readout, at the status edge
//! and after a full Haar frame (all refused), the refused counter to saturation, a readout
//! and a pulse in the same cycle, readout strobes while busy or reading (ignored), a reset
//! in the middle of a frame with a pulse in flight, and a frame longer than the width was
//! sized for (wrap-around against saturation).
//!
//! The schedule is a [`Program`] of [`Step`]s, defined here once: the model's
//! [`crate::Sequencer::directed`] walks it, and tofprobe-rtlgen renders the same steps as the
//! case table of the generated top's directed sequencer, so model and RTL are driven
//! identically. A program loops; each loop ends with a readout and its drain, so the ROM
//! address (pulse strobes since the last readout strobe, mod L) is 0 at every loop start.

use crate::error::PixelError;
use crate::params::PixelParams;

/// At most this many refusals are aimed at the refused counter per frame: the counter
/// saturates within the schedule when 2^W − 1 ≤ this (W ≤ 12), and a wide counter does not
/// make the schedule long.
pub const SATURATION_CAP: u64 = 4095;

/// One step of a program: `count` strobe periods of `every` cycles; the first cycle of each
/// period presents `pulse` and/or `readout`, the other cycles are idle. A step with neither
/// is `count · every` idle cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// The strobe presents a pulse.
    pub pulse: bool,
    /// The strobe presents a readout.
    pub readout: bool,
    /// The strobe resets the pixel (`rst` for that one cycle, never with a pulse or a
    /// readout): a reset in the middle of a frame. The ROM address restarts.
    pub reset: bool,
    /// Cycles per strobe period (≥ 1).
    pub every: u64,
    /// Strobe periods (≥ 1).
    pub count: u64,
    /// What the step is for (a comment in the rendered RTL).
    pub purpose: &'static str,
}

impl Step {
    fn cycles(&self) -> u64 {
        self.every * self.count
    }
}

/// The knobs of the directed schedule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DirectedOptions {
    /// The long frame presents this many times N pulses (Fourier accumulates them all, so
    /// registers sized for N wrap; a Haar frame refuses beyond N). ≥ 1.
    pub long_frame: u64,
    /// Pulse strobes at the start of every frame (after each readout strobe, and after
    /// reset) presented without a detection: the priming rule and the hold of misses.
    pub lead_misses: u64,
}

impl Default for DirectedOptions {
    fn default() -> Self {
        DirectedOptions {
            long_frame: 1,
            lead_misses: 2,
        }
    }
}

/// Where one cycle of a program's loop stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct At {
    /// The step.
    pub step: usize,
    /// A pulse is presented.
    pub pulse: bool,
    /// A readout is presented.
    pub readout: bool,
    /// The pixel is reset (one cycle of `rst`).
    pub reset: bool,
    /// With `pulse`: pulse strobes of the loop before this one.
    pub pulse_in_loop: u64,
    /// With `pulse`: the ROM address, unreduced (pulse strobes since the last readout
    /// strobe before this cycle).
    pub address: u64,
    /// With `pulse`: pulse strobes since the last readout strobe or the loop start, before
    /// this one (what [`DirectedOptions::lead_misses`] counts).
    pub in_frame: u64,
}

/// A looping stimulus schedule with its per-step tables.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Program {
    steps: Vec<Step>,
    start: Vec<u64>,
    pulses_before: Vec<u64>,
    address_start: Vec<u64>,
    loop_cycles: u64,
    loop_pulses: u64,
    lead_misses: u64,
}

impl Program {
    /// A program of `steps`. Fails unless every step has `every, count ≥ 1`, a reset
    /// step presents nothing else and the loop ends with a readout strobe followed by no
    /// pulse strobe (the ROM address restarts with every loop).
    pub fn new(steps: Vec<Step>, lead_misses: u64) -> Result<Self, PixelError> {
        if let Some(s) = steps.iter().find(|s| s.every == 0 || s.count == 0) {
            return Err(PixelError::invalid(
                "directed step",
                format!("every = {}, count = {}", s.every, s.count),
                "a step needs every ≥ 1 and count ≥ 1",
                "every = 1, count = 1",
            ));
        }
        if let Some(s) = steps.iter().find(|s| s.reset && (s.pulse || s.readout)) {
            return Err(PixelError::invalid(
                "directed step",
                format!("reset with pulse = {}, readout = {}", s.pulse, s.readout),
                "a reset step presents no pulse and no readout",
                "reset alone",
            ));
        }
        let last_readout = steps.iter().rposition(|s| s.readout);
        let ends_clean = last_readout.is_some_and(|i| {
            let both = steps[i].pulse && steps[i].count > 1;
            !both && steps[i + 1..].iter().all(|s| !s.pulse)
        });
        if !ends_clean {
            return Err(PixelError::invalid(
                "directed program",
                format!("{} steps", steps.len()),
                "the loop must end with a readout strobe and no pulse after it",
                "a last step with readout only",
            ));
        }
        let (mut start, mut pulses_before, mut address_start) = (vec![], vec![], vec![]);
        let (mut cycle, mut pulses, mut address) = (0u64, 0u64, 0u64);
        for s in &steps {
            start.push(cycle);
            pulses_before.push(pulses);
            address_start.push(address);
            cycle += s.cycles();
            if s.pulse {
                pulses += s.count;
            }
            address = match (s.pulse, s.readout || s.reset) {
                (_, true) => 0,
                (true, false) => address + s.count,
                (false, false) => address,
            };
        }
        Ok(Program {
            steps,
            start,
            pulses_before,
            address_start,
            loop_cycles: cycle,
            loop_pulses: pulses,
            lead_misses,
        })
    }

    /// The steps, in order.
    pub fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// Cycles of one loop.
    pub fn loop_cycles(&self) -> u64 {
        self.loop_cycles
    }

    /// Pulse strobes of one loop.
    pub fn loop_pulses(&self) -> u64 {
        self.loop_pulses
    }

    /// Pulse strobes at the start of each frame presented without a detection.
    pub fn lead_misses(&self) -> u64 {
        self.lead_misses
    }

    /// Cycle `t` of a loop (t < [`Program::loop_cycles`]).
    pub fn at(&self, t: u64) -> At {
        let i = self.start.partition_point(|&s| s <= t) - 1;
        let s = &self.steps[i];
        let within = t - self.start[i];
        let strobe = within.is_multiple_of(s.every);
        let j = within / s.every;
        let pulse = strobe && s.pulse;
        let address = if s.readout && j > 0 {
            0
        } else {
            self.address_start[i] + if s.readout { 0 } else { j }
        };
        At {
            step: i,
            pulse,
            readout: strobe && s.readout,
            reset: strobe && s.reset,
            pulse_in_loop: self.pulses_before[i] + if s.pulse { j } else { 0 },
            address,
            in_frame: address,
        }
    }

    /// Applies the lead misses to `stimuli` (one entry per pulse strobe, loop after loop).
    pub fn miss_frame_leads(&self, stimuli: &mut [Option<u32>]) {
        if self.lead_misses == 0 || self.loop_pulses == 0 {
            return;
        }
        for t in 0..self.loop_cycles {
            let a = self.at(t);
            if a.pulse && a.in_frame < self.lead_misses {
                let mut i = a.pulse_in_loop as usize;
                while let Some(d) = stimuli.get_mut(i) {
                    *d = None;
                    i += self.loop_pulses as usize;
                }
            }
        }
    }
}

/// The contract's directed schedule for `p` (docs/pixel-contract.md, "The directed
/// sequencer"). First half a frame and a reset while its last pulse is in flight (the
/// frame restarts: `mid_frame_reset`), then three frames per loop:
///
/// 0. N pulses one every C cycles; a readout with a pulse in the same cycle (readout taken,
///    pulse refused); pulses at every cycle of the readout (refused, the one at the status
///    edge counted into the next frame) and one after it (accepted).
/// 1. pulses at every cycle for 2K cycles (a busy pipeline refuses K − 1 of every K); N
///    pulses one every C cycles (a Haar frame is full: refused); a burst at every cycle long
///    enough to saturate the refused counter (2·min(2^W, 4096) cycles: Haar refuses all,
///    Fourier with K ≥ 2 at least half); K idle cycles; K + 1 readout strobes (the first
///    taken, the rest ignored during the readout) and R + 2 idle cycles.
/// 2. `long_frame`·N − 1 pulses (at least 1) one every C cycles, the last one C cycles
///    later too, and K + 1 readout strobes at the cycles after it (ignored while the
///    pipeline is busy, K ≥ 3: with `long_frame` = 1 a Haar frame takes that last pulse,
///    its N-th); registers sized for N wrap; R + 2 idle cycles.
pub fn directed_program(p: &PixelParams, o: &DirectedOptions) -> Result<Program, PixelError> {
    p.validate()?;
    if o.long_frame == 0 {
        return Err(PixelError::invalid(
            "directed long_frame",
            0,
            "the long frame presents long_frame·N pulses, long_frame ≥ 1",
            1,
        ));
    }
    let (n, c, k, r) = (
        p.frame_pulses,
        p.cycles_per_pulse as u64,
        p.slots() as u64,
        p.registers() as u64,
    );
    let saturate = p.refused_max().min(SATURATION_CAP) + 1;
    let step = |pulse, readout, every, count, purpose| Step {
        pulse,
        readout,
        reset: false,
        every,
        count,
        purpose,
    };
    let mut steps = mid_frame_reset(n, c);
    steps.extend([
        step(true, false, c, n, "frame 0: N pulses, one every C cycles"),
        step(
            true,
            true,
            1,
            1,
            "readout and pulse together: the pulse is refused",
        ),
        step(true, false, 1, r + 2, "pulses during the readout: refused"),
        step(
            true,
            false,
            1,
            2 * k,
            "frame 1: pulses into a busy pipeline",
        ),
        step(
            true,
            false,
            c,
            n,
            "N pulses: a full Haar frame refuses them",
        ),
        step(
            true,
            false,
            1,
            2 * saturate,
            "burst: the refused counter saturates",
        ),
        step(false, false, 1, k, "the pipeline drains"),
        step(
            false,
            true,
            1,
            k + 1,
            "readout strobes: one taken, the rest ignored",
        ),
        step(false, false, 1, r + 2, "the words come out"),
        step(
            true,
            false,
            c,
            (o.long_frame * n - 1).max(1),
            "frame 2: the long frame, but its last pulse",
        ),
        step(
            true,
            false,
            1,
            1,
            "its last pulse, then readout strobes while busy",
        ),
        step(false, true, 1, k + 1, "readout strobes: ignored while busy"),
        step(false, false, 1, r + 2, "the words come out"),
    ]);
    Program::new(steps, o.lead_misses)
}

/// The loop's first steps: half a frame of pulses one every C cycles, the last of them
/// followed at the next cycle by one cycle of reset, while its slots are in flight
/// (`active`, the register file being written), then the rest of that pulse's period.
/// Model and RTL both restart: every register, the pipeline, the priming, the refused
/// counter, the Haar pulse count and the ROM address.
fn mid_frame_reset(n: u64, c: u64) -> Vec<Step> {
    let before = (n / 2).max(1);
    let pulses = |every, count, purpose| Step {
        pulse: true,
        readout: false,
        reset: false,
        every,
        count,
        purpose,
    };
    let mut steps = Vec::new();
    if before > 1 {
        steps.push(pulses(
            c,
            before - 1,
            "half a frame: pulses one every C cycles",
        ));
    }
    steps.push(pulses(
        1,
        1,
        "its last pulse, whose slots the reset interrupts",
    ));
    steps.push(Step {
        pulse: false,
        readout: false,
        reset: true,
        every: c.saturating_sub(1).max(1),
        count: 1,
        purpose: "reset in the middle of the frame, the pulse's slots in flight",
    });
    steps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_follow_the_steps() {
        let p = PixelParams::default();
        let prog = directed_program(&p, &DirectedOptions::default()).unwrap();
        let total: u64 = prog.steps().iter().map(|s| s.every * s.count).sum();
        assert_eq!(prog.loop_cycles(), total);
        // Walk the loop naively and compare every cycle with the tables.
        let (mut pulses, mut address) = (0u64, 0u64);
        let mut t = 0;
        for (i, s) in prog.steps().iter().enumerate() {
            for j in 0..s.count {
                for e in 0..s.every {
                    let a = prog.at(t);
                    assert_eq!(a.step, i, "cycle {t}");
                    assert_eq!(
                        (a.pulse, a.readout),
                        (e == 0 && s.pulse, e == 0 && s.readout)
                    );
                    if a.pulse {
                        assert_eq!((a.pulse_in_loop, a.address), (pulses, address), "cycle {t}");
                        pulses += 1;
                        address += 1;
                    }
                    if a.readout || a.reset {
                        address = 0;
                    }
                    let _ = j;
                    t += 1;
                }
            }
        }
        assert_eq!(pulses, prog.loop_pulses());
        assert_eq!(address, 0, "the loop ends with the address restarted");
    }

    #[test]
    fn a_loop_ending_in_pulses_is_refused() {
        let s = |pulse, readout| Step {
            pulse,
            readout,
            reset: false,
            every: 1,
            count: 1,
            purpose: "",
        };
        assert!(Program::new(vec![s(true, false), s(false, true)], 0).is_ok());
        assert!(Program::new(vec![s(false, true), s(true, false)], 0).is_err());
        assert!(Program::new(vec![s(true, false)], 0).is_err());
    }
}
