//! Runs the pixel crate's reference sequencer (with its status cycle) through the pixel
//! crate's cycle-accurate model, the one model of the pixel, and records what a simulator
//! must reproduce: the readout of each frame, the register-write trace and output-pin changes
//! (in full inside a cycle window), and a digest of both per window of pulses everywhere.
//!
//! Digest (also implemented by testbench/harness.cpp): events are hashed in cycle order,
//! each as four u64 words folded by `h = (h ^ word) * 0x100000001b3` (FNV-1a's prime, word
//! by word), starting each window at 0xcbf29ce484222325. A write event is
//! [1, cycle, register, value]; a pin-change event is
//! [2, cycle, ready | rd_valid << 1 | rd_index << 2, rd_data]. Digest window w covers the
//! cycles from the presentation of pulse w·D (D = `digest_pulses`) up to, not including,
//! that of pulse (w+1)·D; the reset cycles belong to window 0 and a frame's readout to the
//! window of its last pulse. Pins are compared from cycle 1 on (before the first reset edge
//! the RTL's state is undefined); cycle 1's pins are always an event.

use std::borrow::Cow;

use tofprobe_dsp::RomImage;
use tofprobe_pixel::{
    CycleModel, DirectedOptions, Fault, Mode, PinsOut, PixelParams, Program, Sequencer,
    directed_program,
};

use crate::error::RtlError;

/// FNV-1a offset basis: the digest of an empty window.
pub const DIGEST_INIT: u64 = tofprobe_io::FNV_OFFSET;

/// Folds one event into a window digest (FNV-1a's prime, a whole u64 word at a time).
#[inline]
pub fn digest_event(h: u64, words: [u64; 4]) -> u64 {
    words
        .iter()
        .fold(h, |h, w| (h ^ w).wrapping_mul(tofprobe_io::FNV_PRIME))
}

/// Packs the pins as in the digest and pins.hex.
pub fn pack_pins(o: &PinsOut) -> u64 {
    u64::from(o.ready) | u64::from(o.rd_valid) << 1 | u64::from(o.rd_index) << 2
}

/// What the golden run recorded.
#[derive(Debug, Clone, Default)]
pub struct Golden {
    /// Per frame: R register words then the status word, raw W-bit patterns.
    pub readouts: Vec<Vec<u64>>,
    /// Per frame: the cycle its readout's last word (the status word) is on the pins, which
    /// closes the frame for reports that attribute a mismatch to a frame (JUnit).
    pub readout_end_cycles: Vec<u64>,
    /// (cycle, register, value) inside the trace window.
    pub trace: Vec<(u64, u32, u64)>,
    /// (cycle, pins) changes inside the trace window.
    pub pins: Vec<(u64, PinsOut)>,
    /// Per digest window: (event count, digest).
    pub digests: Vec<(u64, u64)>,
    pub cycles: u64,
    pub pulses: u64,
}

/// Options of a golden run.
#[derive(Debug, Clone, Copy)]
pub struct GoldenOptions {
    pub frames: u64,
    /// Pulses per digest window (≥ 1).
    pub digest_pulses: u64,
    /// Cycles [lo, hi) recorded in full.
    pub trace_window: (u64, u64),
}

/// The probe ROM image of `rom` (L × ceil(R/64) packed words) for the pixel crate's
/// sequencer; `None` in Haar mode (no ROM).
pub fn rom_image(p: &PixelParams, rom: &[u64]) -> Option<RomImage> {
    (p.mode == Mode::Fourier)
        .then(|| RomImage::from_words(p.rom_depth, p.registers(), rom.to_vec()))
}

/// The stimuli of `frames` whole frames: `stim` cut to frames·N pulses, padded with pulses
/// without a detection when shorter.
pub fn frame_stimuli<'a>(
    p: &PixelParams,
    stim: &'a [Option<u32>],
    frames: u64,
) -> Cow<'a, [Option<u32>]> {
    let n = usize::try_from(frames.saturating_mul(p.frame_pulses)).unwrap_or(usize::MAX);
    if stim.len() >= n {
        Cow::Borrowed(&stim[..n])
    } else {
        let mut v = stim.to_vec();
        v.resize(n, None);
        Cow::Owned(v)
    }
}

/// The contract's reference sequence for the golden vectors: `frames` frames and the
/// status cycle.
pub fn sequence<'a>(
    p: &PixelParams,
    stim: &'a [Option<u32>],
    rom: Option<&'a RomImage>,
) -> Result<Sequencer<'a>, RtlError> {
    Ok(Sequencer::new(p, stim, rom)?.with_status_cycle())
}

/// The pulse strobes of `frames` runs of the sequencer: frames·N for the reference one,
/// frames loops of the directed program otherwise.
pub fn pulses_for(p: &PixelParams, frames: u64, program: Option<&Program>) -> u64 {
    match program {
        Some(prog) => frames.saturating_mul(prog.loop_pulses()),
        None => frames.saturating_mul(p.frame_pulses),
    }
}

/// A run's stimuli (cut or padded to its pulse strobes) and the directed program, if any.
pub type RunStimuli<'a> = (Cow<'a, [Option<u32>]>, Option<Program>);

/// The sequence that drives a run: the reference sequencer for `frames` frames, or with
/// `directed` `frames` loops of the directed program (docs/pixel-contract.md, "The directed
/// sequencer"); the status cycle appended either way. Returns the stimuli cut (or padded
/// with misses) to the run's pulse strobes, for the sequence to borrow.
pub fn stimuli_and_program<'a>(
    p: &PixelParams,
    stim: &'a [Option<u32>],
    frames: u64,
    directed: Option<&DirectedOptions>,
) -> Result<RunStimuli<'a>, RtlError> {
    let program = directed.map(|o| directed_program(p, o)).transpose()?;
    let n = usize::try_from(pulses_for(p, frames, program.as_ref())).unwrap_or(usize::MAX);
    let stim = if stim.len() >= n {
        Cow::Borrowed(&stim[..n])
    } else {
        let mut v = stim.to_vec();
        v.resize(n, None);
        Cow::Owned(v)
    };
    Ok((stim, program))
}

/// The sequence for stimuli from [`stimuli_and_program`]: the reference one, or `frames`
/// loops of `program`; with the status cycle.
pub fn sequence_for<'a>(
    p: &PixelParams,
    stim: &'a [Option<u32>],
    rom: Option<&'a RomImage>,
    frames: u64,
    program: Option<Program>,
) -> Result<Sequencer<'a>, RtlError> {
    match program {
        Some(prog) => Ok(Sequencer::directed(p, prog, stim, rom, frames)?.with_status_cycle()),
        None => sequence(p, stim, rom),
    }
}

/// Runs the pixel crate's cycle model through `seq` and records the golden data.
///
/// The sequence is walked as an iterator (its counters, no division per cycle), and the
/// pulse index is counted: pulse strobes are presented in index order in both sequencers
/// (`Sequencer::pulse_index` of the cycle, tested in crates/rtlgen/tests), so the k-th
/// strobe is pulse k − 1 and a digest window closes after every D strobes.
pub fn run(p: &PixelParams, seq: &Sequencer<'_>, o: &GoldenOptions) -> Result<Golden, RtlError> {
    let mut model = CycleModel::new(p)?;
    let mut g = Golden {
        cycles: seq.total_cycles(),
        ..Golden::default()
    };
    let r = p.registers();
    let mut frame_words = Vec::with_capacity(r + 1);
    let mut prev = PinsOut::default();
    let (mut count, mut h) = (0u64, DIGEST_INIT);
    let digest_pulses = o.digest_pulses.max(1);
    // Pulse strobes left in the current digest window.
    let mut window_left = digest_pulses;
    let (lo, hi) = o.trace_window;
    // The cycle counted beside the iterator, not zipped with it: the zipped (cycle, pins)
    // pair was copied through memory with an 8-byte load over the bytes just stored (a
    // store-forwarding stall, half the golden run's time under perf).
    let mut next_cycle = 0u64;
    #[allow(clippy::explicit_counter_loop)] // `enumerate` pairs them again: the stall above
    for pins in seq.clone() {
        let c = next_cycle;
        next_cycle += 1;
        if pins.pulse {
            if window_left == 0 {
                g.digests.push((count, h));
                (count, h) = (0, DIGEST_INIT);
                window_left = digest_pulses;
            }
            window_left -= 1;
            g.pulses += 1;
        }
        let out = model.step(&pins);
        let full = c >= lo && c < hi;
        if c >= 1 && (c == 1 || out != prev) {
            h = digest_event(h, [2, c, pack_pins(&out), out.rd_data]);
            count += 1;
            if full {
                g.pins.push((c, out));
            }
        }
        prev = out;
        if out.rd_valid {
            frame_words.push(out.rd_data);
            if out.rd_index as usize == r {
                g.readouts.push(std::mem::take(&mut frame_words));
                g.readout_end_cycles.push(c);
            }
        }
        for w in model.writes() {
            h = digest_event(h, [1, c, u64::from(w.register), w.value]);
            count += 1;
            if full {
                g.trace.push((c, w.register, w.value));
            }
        }
    }
    g.digests.push((count, h));
    Ok(g)
}

/// The first cycle at which the cycle model carrying `fault` differs from the correct one
/// in any observable (register writes of the edge, or output pins from cycle 1 on), with
/// the pulse index presented last by then. `None` if the fault never shows.
pub fn first_divergence(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    frames: u64,
    fault: Fault,
) -> Result<Option<(u64, u64)>, RtlError> {
    first_divergence_with(p, stim, rom, frames, None, fault)
}

/// [`first_divergence`] under the reference sequencer (`directed` `None`) or `frames`
/// loops of the directed one.
pub fn first_divergence_with(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    frames: u64,
    directed: Option<&DirectedOptions>,
    fault: Fault,
) -> Result<Option<(u64, u64)>, RtlError> {
    let (stim, program) = stimuli_and_program(p, stim, frames, directed)?;
    let image = rom_image(p, rom);
    let seq = sequence_for(p, &stim, image.as_ref(), frames, program)?;
    let mut good = CycleModel::new(p)?;
    let mut bad = CycleModel::with_fault(p, Some(fault))?;
    let mut pulse = 0;
    for c in 0..seq.total_cycles() {
        if let Some(pi) = seq.pulse_index(c) {
            pulse = pi;
        }
        let pins = seq.pins(c);
        let a = good.step(&pins);
        let b = bad.step(&pins);
        if (c >= 1 && a != b) || good.writes() != bad.writes() {
            return Ok(Some((c, pulse)));
        }
    }
    Ok(None)
}
