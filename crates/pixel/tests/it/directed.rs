//! The directed sequencer on the cycle model alone, over random valid configurations: it
//! takes every path of the contract's accept rule that the reference sequencer never takes
//! (a pulse refused into a busy pipeline, during a readout, at the status edge, beyond a
//! full Haar frame, together with a taken readout; a readout ignored while reading, and
//! while the pipeline is busy when K ≥ 3; the refused counter held at saturation when
//! 2^W − 1 ≤ 4095), and its status words are the contract's closed forms
//! (docs/pixel-contract.md, "The directed sequencer").

use crate::common;

use common::{Rng, random_detection, random_params, random_rom};
use tofprobe_pixel::{
    CycleModel, DirectedOptions, Fault, Mode, PixelParams, Sequencer, directed_program,
};

/// Paths seen, counted per edge from the pins and the model's state before it.
#[derive(Debug, Default)]
struct Paths {
    refused_busy: u64,
    refused_reading: u64,
    refused_full: u64,
    refused_with_readout: u64,
    refused_at_status_edge: u64,
    readout_ignored_reading: u64,
    readout_ignored_busy: u64,
    held_saturated: u64,
}

/// The closed-form status words of one loop (frames 0, 1, 2), capped by saturation.
fn closed_form(p: &PixelParams, long: u64) -> [Option<u64>; 3] {
    let max = p.refused_max();
    let r = p.registers() as u64;
    let k = p.slots() as u64;
    let frame1 = match (p.mode, max <= 4095) {
        // Fourier with K = 1 refuses only the pulse at frame 0's status edge.
        (Mode::Fourier, _) if k == 1 => Some(1),
        (_, true) => Some(max),
        // A wide counter is not saturated by the capped burst; its count is not a closed
        // form worth writing here.
        (_, false) => None,
    };
    let frame2 = match p.mode {
        Mode::Fourier => 0,
        Mode::Haar => (long - 1) * p.frame_pulses,
    };
    [Some((r + 1).min(max)), frame1, Some(frame2.min(max))]
}

fn run(seed: u64, long: u64) -> (PixelParams, Paths) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let o = DirectedOptions {
        long_frame: long,
        ..DirectedOptions::default()
    };
    let prog = directed_program(&p, &o).expect("a program for every valid configuration");
    let loops = 2;
    let mut stim: Vec<Option<u32>> = (0..loops * prog.loop_pulses())
        .map(|_| random_detection(&mut rng, &p))
        .collect();
    prog.miss_frame_leads(&mut stim);
    let seq = Sequencer::directed(&p, prog, &stim, Some(&rom), loops)
        .expect("sequence")
        .with_status_cycle();
    let mut m = CycleModel::new(&p).expect("model");
    let mut paths = Paths::default();
    let mut status = Vec::new();
    let (r, max) = (p.registers() as u64, p.refused_max());
    // The edge that ends the readout in progress (its status edge), tracked from the
    // contract: a readout taken at edge t reads out at t+1..t+R and ends at t+R+1.
    let mut reading_until: Option<u64> = None;
    for c in 0..seq.total_cycles() {
        let pins = seq.pins(c);
        let ready = m.outputs().ready;
        let reading = reading_until.is_some_and(|e| c <= e);
        let status_edge = reading_until == Some(c);
        let full = p.mode == Mode::Haar && m.pcount() == p.frame_pulses;
        let before = m.refused();
        let out = m.step(&pins);
        if out.rd_valid && u64::from(out.rd_index) == r {
            status.push(out.rd_data);
        }
        if pins.rst {
            continue;
        }
        assert_eq!(
            ready,
            !reading && ready,
            "seed {seed} cycle {c}: ready while reading"
        );
        if pins.pulse && !m.accepted_pulse() {
            if status_edge {
                assert_eq!(
                    m.refused(),
                    1,
                    "seed {seed} cycle {c}: refusal at the status edge"
                );
                paths.refused_at_status_edge += 1;
            } else if before == max {
                assert_eq!(m.refused(), max, "seed {seed} cycle {c}: saturated");
                paths.held_saturated += 1;
            } else {
                assert_eq!(m.refused(), before + 1, "seed {seed} cycle {c}: counted");
            }
            match (pins.readout && ready, ready, full, reading) {
                (true, ..) => paths.refused_with_readout += 1,
                (false, true, true, _) => paths.refused_full += 1,
                (false, false, _, true) => paths.refused_reading += 1,
                (false, false, _, false) => paths.refused_busy += 1,
                (false, true, false, _) => panic!("seed {seed} cycle {c}: a free pulse refused"),
            }
        }
        if pins.readout && !ready {
            if reading {
                paths.readout_ignored_reading += 1;
            } else {
                paths.readout_ignored_busy += 1;
            }
        }
        if pins.readout && ready {
            reading_until = Some(c + r + 1);
        }
    }
    let want = closed_form(&p, long);
    assert_eq!(
        status.len(),
        3 * loops as usize,
        "seed {seed}: frames {p:?}"
    );
    for (i, &s) in status.iter().enumerate() {
        if let Some(w) = want[i % 3] {
            assert_eq!(s, w, "seed {seed}: status word of frame {i}, {p:?}");
        }
    }
    (p, paths)
}

#[test]
fn directed_schedule_takes_every_refusal_path_with_closed_form_status_words() {
    let mut totals = Paths::default();
    let mut saturating = 0;
    for seed in 0..300u64 {
        let long = 1 + seed % 3;
        let (p, paths) = run(seed, long);
        assert!(paths.refused_with_readout >= 2, "seed {seed}: {paths:?}");
        assert!(paths.refused_at_status_edge >= 2, "seed {seed}: {paths:?}");
        assert!(paths.readout_ignored_reading >= 2, "seed {seed}: {paths:?}");
        if p.slots() >= 2 {
            assert!(paths.refused_busy > 0, "seed {seed}: {paths:?}");
        }
        // A Haar frame longer than N refuses its last pulse: the pipeline is idle then.
        if p.slots() >= 3 && (p.mode == Mode::Fourier || long == 1) {
            assert!(paths.readout_ignored_busy > 0, "seed {seed}: {paths:?}");
        }
        if p.mode == Mode::Haar {
            assert!(paths.refused_full > 0, "seed {seed}: {paths:?}");
        }
        if p.refused_max() <= 4095 && (p.mode == Mode::Haar || p.slots() >= 2) {
            assert!(paths.held_saturated > 0, "seed {seed}: {paths:?}");
            saturating += 1;
        }
        totals.refused_with_readout += paths.refused_with_readout;
        totals.refused_at_status_edge += paths.refused_at_status_edge;
        totals.readout_ignored_reading += paths.readout_ignored_reading;
        totals.refused_busy += paths.refused_busy;
        totals.refused_reading += paths.refused_reading;
        totals.refused_full += paths.refused_full;
        totals.readout_ignored_busy += paths.readout_ignored_busy;
        totals.held_saturated += paths.held_saturated;
    }
    eprintln!("300 configurations, {saturating} saturating: {totals:?}");
    assert!(
        saturating > 30,
        "too few saturating configurations: {saturating}"
    );
    assert!(totals.refused_reading > 0 && totals.readout_ignored_busy > 0);
}

/// The status words of two loops under the cycle model carrying `fault`.
fn status_under(seed: u64, fault: Option<Fault>) -> (PixelParams, Vec<u64>) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let prog = directed_program(&p, &DirectedOptions::default()).expect("program");
    let stim: Vec<Option<u32>> = (0..2 * prog.loop_pulses())
        .map(|_| random_detection(&mut rng, &p))
        .collect();
    let seq = Sequencer::directed(&p, prog, &stim, Some(&rom), 2)
        .expect("sequence")
        .with_status_cycle();
    let mut m = CycleModel::with_fault(&p, fault).expect("model");
    let r = p.registers() as u32;
    let words = seq
        .map(|pins| m.step(&pins))
        .filter(|o| o.rd_valid && o.rd_index == r)
        .map(|o| o.rd_data)
        .collect();
    (p, words)
}

/// The closed forms can fail: a counter that does not count, or a status word that does
/// not carry it, misses frame 0's R + 1 on every configuration.
#[test]
fn broken_refusal_paths_miss_the_closed_forms() {
    for fault in [Fault::RefusedCounter, Fault::StatusWord] {
        for seed in 0..50u64 {
            let (p, good) = status_under(seed, None);
            let (_, bad) = status_under(seed, Some(fault));
            assert_eq!(Some(good[0]), closed_form(&p, 1)[0], "seed {seed}");
            assert_ne!(
                bad[0], good[0],
                "{fault:?} seed {seed}: frame 0's status word"
            );
        }
    }
}
