//! The driver of the array's register-level model ([`crate::rtl_model`]): frames through
//! the array at the clock edge ([`run`]): reset, then every pulse's per-pixel detections
//! presented while `pulse_o`, the array's ports recorded every cycle,
//! each frame's words reassembled from the stream at the contract's beat cycles
//! ([`ArrayRun`], the golden vectors of `tofprobe cosim` on an array). [`run_with_reset`]
//! adds one cycle of `rst` in the middle of the first frame: the array restarts, and its
//! frames follow from the cycle after it.

use tofprobe_design::readout::Readout;
use tofprobe_pixel::sequencer::RESET_CYCLES;

use crate::error::ArrayError;
use crate::rtl_model::{ArrayModel, ArrayPins, TAIL_CYCLES};

/// What the array's ports showed over a run, cycle by cycle.
#[derive(Debug, Clone)]
pub struct ArrayRun {
    /// The readout followed.
    pub readout: Readout,
    /// G: SPADs per pixel side (the inputs are the pixels' × G²).
    pub superpixel: usize,
    /// Frames run.
    pub frames: u64,
    /// The outputs of every cycle.
    pub pins: Vec<ArrayPins>,
    /// Per `pulse_o` cycle (in order): the cycle.
    pub pulse_cycles: Vec<u64>,
    /// The readout positions of the pixels present (all of them unless a tile), in order.
    pub positions: Vec<usize>,
    /// Per frame, per pixel present (readout order: `positions`), the R + 1 words the
    /// stream carried (raw W bits, reassembled from the beats).
    pub words: Vec<Vec<Vec<u64>>>,
    /// The cycle of a one-cycle reset in the middle of the run ([`run_with_reset`]), if any.
    pub reset_at: Option<u64>,
}

/// The cycle frame `frame` starts at: after power-up's reset, or after a mid-run reset at
/// `reset_at` (the array then stands where it stood after power-up's last reset cycle).
fn frame_start_after(ro: &Readout, reset_at: Option<u64>, frame: u64) -> u64 {
    let first = reset_at.map_or(RESET_CYCLES, |c| c + 1);
    first + frame * ro.frame_cycles()
}

/// The cycle of [`mid_frame_reset`]: the cycle after the pixels sample pulse N/2 of the first
/// frame (they are accumulating it: `active`, the register file being written).
pub fn mid_frame_reset(ro: &Readout) -> u64 {
    RESET_CYCLES
        + (ro.frame_pulses / 2) * ro.cycles_per_pulse
        + tofprobe_design::readout::BROADCAST_LATENCY
        + 1
}

impl ArrayRun {
    /// The cycles run.
    pub fn cycles(&self) -> u64 {
        self.pins.len() as u64
    }

    /// The cycle of beat (frame, q, word, part) by the contract's formula.
    pub fn beat_cycle(&self, frame: u64, q: usize, word: usize, part: usize) -> u64 {
        let ro = &self.readout;
        self.frame_start(frame) + ro.accumulate_cycles() + ro.beat_offset(q, word, part)
    }

    /// The cycle frame `frame` starts at (its sequencer's first pulse).
    pub fn frame_start(&self, frame: u64) -> u64 {
        frame_start_after(&self.readout, self.reset_at, frame)
    }

    /// Says what the array was doing at `cycle`, in the contract's terms: the beat on the
    /// port (pixel (r, c), register or status word, part, frame and its pulses), or the
    /// pulse being presented, or the phase.
    pub fn explain(&self, cycle: u64) -> String {
        let ro = &self.readout;
        let f = ro.frame_cycles();
        let n = ro.frame_pulses;
        let first = self.frame_start(0);
        let frame_of = |c: u64| c.saturating_sub(first) / f;
        // Pulses sampled before a mid-frame reset took the first detections.
        let before = self.pulse_cycles.iter().take_while(|&&c| c < first).count() as u64;
        if cycle < RESET_CYCLES || Some(cycle) == self.reset_at {
            return format!("cycle {cycle}: reset");
        }
        if cycle < first {
            return format!(
                "cycle {cycle}: the frame the reset at cycle {} restarts",
                first - 1
            );
        }
        // The beat whose slot holds this cycle (the latest beat at or before it).
        for fr in (0..=frame_of(cycle)).rev().take(2) {
            let base = self.frame_start(fr) + ro.accumulate_cycles() + ro.beat_offset(0, 0, 0);
            if cycle < base {
                continue;
            }
            let idx = (cycle - base) / ro.beat_cycles;
            if idx < ro.beats_per_frame() && fr < self.frames {
                let b = ro.beat(idx);
                let word = if b.word == ro.registers {
                    "status word (refused pulses)".to_string()
                } else {
                    format!("register {}", b.word)
                };
                return format!(
                    "cycle {cycle}: frame {fr}'s readout, pixel ({}, {}) (position {} of the order), \
                     {word}, beat {} of {}; its frame is pulses {}..{}",
                    b.row,
                    b.col,
                    b.position,
                    b.part,
                    ro.beats_per_word,
                    before + fr * n,
                    before + fr * n + n - 1
                );
            }
        }
        let fr = frame_of(cycle);
        let within = cycle - self.frame_start(fr);
        let lat = tofprobe_design::readout::BROADCAST_LATENCY;
        if within >= lat && within < ro.accumulate_cycles() + lat {
            // The pulse the pixels are working on: presented `lat` cycles after the sequencer's.
            let k = (within - lat) / ro.cycles_per_pulse;
            let pulse = before + fr * n + k;
            format!(
                "cycle {cycle}: frame {fr}, pulse {pulse} (presented to the pixels at cycle {}, \
                 slot {} of its {} cycles)",
                self.frame_start(fr) + lat + k * ro.cycles_per_pulse,
                (within - lat) % ro.cycles_per_pulse,
                ro.cycles_per_pulse
            )
        } else {
            format!("cycle {cycle}: frame {fr}'s readout phase")
        }
    }
}

/// Runs `frames` frames: reset, then every cycle the detections of the pulse the pixels
/// sample (`detections[i]` is input i's — pixel i's, row-major over the pixels present, or
/// with G > 1 SPAD i's, row-major over their SPAD grid — one per pulse of the run; pulses
/// beyond present no detection).
pub fn run(
    model: &mut ArrayModel,
    detections: &[Vec<Option<u32>>],
    frames: u64,
) -> Result<ArrayRun, ArrayError> {
    run_with_reset(model, detections, frames, None)
}

/// [`run`] with one cycle of `rst` at cycle `reset_at` (≥ 2, inside the first frame's
/// accumulation: [`mid_frame_reset`]): every register with a reset clears, the sequencer
/// restarts, and the `frames` frames start at the next cycle. Pulses sampled before it take
/// the first detections; the frames after it take the next ones.
pub fn run_with_reset(
    model: &mut ArrayModel,
    detections: &[Vec<Option<u32>>],
    frames: u64,
    reset_at: Option<u64>,
) -> Result<ArrayRun, ArrayError> {
    let ro = *model.readout();
    if let Some(c) =
        reset_at.filter(|&c| c < RESET_CYCLES || c >= RESET_CYCLES + ro.accumulate_cycles())
    {
        return Err(ArrayError::Option {
            option: "reset-at".into(),
            value: c.to_string(),
            allowed: format!(
                "cycles {RESET_CYCLES}..{} (the first frame's accumulation)",
                RESET_CYCLES + ro.accumulate_cycles()
            ),
        });
    }
    let tile = model.present();
    let np = model.inputs();
    if detections.len() != np {
        return Err(ArrayError::Shape(format!(
            "{} inputs' detections for the {} × {} pixels present of {g} × {g} SPADs ({np})",
            detections.len(),
            tile.rows,
            tile.cols,
            g = model.superpixel()
        )));
    }
    // The last frame's readout ends N·C + D cycles after its start (double-buffered, that
    // is past the next frame's start when D > 1).
    let total = match frames {
        0 => frame_start_after(&ro, reset_at, 0),
        f => frame_start_after(&ro, reset_at, f - 1) + ro.accumulate_cycles() + ro.readout_cycles(),
    } + TAIL_CYCLES;
    let mut pins = Vec::with_capacity(total as usize);
    let mut pulse_cycles = Vec::new();
    let (mut valid, mut tdc) = (vec![false; np], vec![0u32; np]);
    for cycle in 0..total {
        let rst = cycle < RESET_CYCLES || Some(cycle) == reset_at;
        let pulse_o = model.outputs().pulse_o;
        let n = pulse_cycles.len();
        for i in 0..np {
            let d = if pulse_o {
                detections[i].get(n).copied().flatten()
            } else {
                None
            };
            (valid[i], tdc[i]) = (d.is_some(), d.unwrap_or(0));
        }
        if pulse_o {
            pulse_cycles.push(cycle);
        }
        pins.push(model.step(rst, &valid, &tdc));
    }
    let positions: Vec<usize> = (0..ro.pixels())
        .filter(|&q| {
            let (r, c) = ro.order(q);
            tile.contains(r, c)
        })
        .collect();
    let mut run = ArrayRun {
        readout: ro,
        superpixel: model.superpixel(),
        frames,
        pins,
        pulse_cycles,
        positions,
        words: Vec::new(),
        reset_at,
    };
    run.words = (0..frames)
        .map(|fr| {
            run.positions
                .iter()
                .map(|&q| {
                    (0..ro.words_per_pixel())
                        .map(|j| {
                            let beats: Vec<u64> = (0..ro.beats_per_word)
                                .map(|m| {
                                    let c = run.beat_cycle(fr, q, j, m) as usize;
                                    run.pins.get(c).map(|p| p.ro_data).unwrap_or(0)
                                })
                                .collect();
                            ro.word_of(&beats)
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    Ok(run)
}
