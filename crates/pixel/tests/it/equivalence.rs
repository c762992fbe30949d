//! Equivalence of the two fidelities (issue point 3): over random configurations (both
//! modes, A > 1, K < C, odd W, any zoom), random detections, ROM bits and random pulse and
//! readout timing (including strobes the pixel must refuse), the cycle model's registers
//! equal the transaction model's after every pulse and every readout is identical.

use crate::common;

use common::{Rng, random_detection, random_params, random_rom};
use proptest::prelude::*;
use tofprobe_pixel::{
    CycleModel, Fault, Mode, PinsIn, PixelParams, Readout, ReadoutCollector, Sequencer,
    TransactionModel,
};

/// Steps idle cycles until the pixel is ready (a pulse would be accepted).
fn idle_until_ready(cm: &mut CycleModel, col: &mut ReadoutCollector) -> Option<Readout> {
    let mut got = None;
    let mut guard = 0;
    while !cm.outputs().ready {
        if let Some(r) = col.push(&cm.step(&PinsIn::default())) {
            got = Some(r);
        }
        guard += 1;
        assert!(guard < 10_000, "pixel never became ready");
    }
    got
}

fn check_state(cm: &CycleModel, tm: &TransactionModel, what: &str) {
    assert_eq!(cm.primed(), tm.primed(), "primed {what}");
    assert_eq!(cm.held(), tm.held(), "held {what}");
    if cm.params().mode == Mode::Fourier {
        assert_eq!(cm.prefilter_state(), tm.prefilter_state(), "x {what}");
    }
}

fn run_case(seed: u64) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let mut cm = CycleModel::new(&p).unwrap();
    let mut tm = TransactionModel::new(&p).unwrap();
    let mut col = ReadoutCollector::new(p.registers(), p.width);
    for _ in 0..2 {
        cm.step(&PinsIn {
            rst: true,
            ..PinsIn::default()
        });
    }
    let pulses = rng.below(3 * p.frame_pulses + 4);
    let mut addr = 0usize;
    let mut readouts = 0;
    for m in 0..pulses {
        // Sometimes strobe a pulse while the pipeline is busy: it must be refused.
        if !cm.outputs().ready && rng.chance(30) {
            let before = (cm.primed(), cm.held(), cm.prefilter_state(), cm.pcount());
            let o = cm.step(&PinsIn {
                pulse: true,
                valid: true,
                tdc: 1,
                ..PinsIn::default()
            });
            assert!(!o.ready && !cm.accepted_pulse());
            let after = (cm.primed(), cm.held(), cm.prefilter_state(), cm.pcount());
            assert_eq!(before, after, "a refused pulse changed the state");
            if col.push(&o).is_some() {
                unreachable!("no readout in progress");
            }
            tm.refuse();
        }
        for _ in 0..rng.below(3) {
            assert!(col.push(&cm.step(&PinsIn::default())).is_none());
        }
        // Sometimes read out first (Haar: always once the frame is full, else it refuses).
        let full = p.mode == Mode::Haar && tm.pulses_in_frame() == p.frame_pulses;
        if rng.chance(15) || (full && rng.chance(60)) {
            assert!(idle_until_ready(&mut cm, &mut col).is_none());
            // The accepting edge of the readout has all earlier pulses' slots done.
            let with_pulse = rng.chance(30);
            let o = cm.step(&PinsIn {
                readout: true,
                pulse: with_pulse,
                valid: true,
                tdc: 3,
                rom_word: rom.entry(0),
                ..PinsIn::default()
            });
            assert!(col.push(&o).is_none());
            if with_pulse {
                tm.refuse(); // readout wins, the pulse is refused and counted
            }
            // Strobe pulses while the words come out: all refused. The status word is on
            // the bus in the cycle after its edge E; a strobe at E is counted after the
            // status word was taken (refused ← 1), so it belongs to the next frame.
            let mut strobes = Vec::new();
            let got = loop {
                let strobe = !cm.outputs().ready && rng.chance(20);
                let o = cm.step(&PinsIn {
                    pulse: strobe,
                    valid: true,
                    tdc: 2,
                    ..PinsIn::default()
                });
                assert!(!cm.accepted_pulse());
                if let Some(r) = col.push(&o) {
                    assert!(!strobe, "the pixel is ready in the status word's cycle");
                    break r;
                }
                strobes.push(strobe);
            };
            let at_status_edge = strobes.pop().unwrap_or(false);
            for _ in strobes.iter().filter(|&&s| s) {
                tm.refuse();
            }
            let expected = tm.readout();
            if at_status_edge {
                tm.refuse();
            }
            assert_eq!(got, expected, "readout {readouts}");
            readouts += 1;
            addr = 0;
            check_state(&cm, &tm, "after readout");
        }
        assert!(idle_until_ready(&mut cm, &mut col).is_none());
        let det = random_detection(&mut rng, &p);
        let word = rom.entry(addr % p.rom_depth);
        let o = cm.step(&PinsIn {
            pulse: true,
            valid: det.is_some(),
            tdc: det.unwrap_or(0),
            rom_word: word,
            ..PinsIn::default()
        });
        assert!(o.ready);
        assert!(col.push(&o).is_none());
        // At the accepting edge the previous pulse's last slot has run: the registers hold
        // every earlier pulse, as the transaction model does before this pulse.
        assert_eq!(cm.registers(), tm.registers(), "registers before pulse {m}");
        let accepted = tm.pulse(det, word);
        assert_eq!(cm.accepted_pulse(), accepted, "acceptance of pulse {m}");
        if accepted {
            addr += 1;
        }
        check_state(&cm, &tm, &format!("after pulse {m}"));
        assert_eq!(cm.pcount(), tm.pulses_in_frame());
    }
    // Drain and read out the rest.
    assert!(idle_until_ready(&mut cm, &mut col).is_none());
    let o = cm.step(&PinsIn {
        readout: true,
        ..PinsIn::default()
    });
    assert!(col.push(&o).is_none());
    assert_eq!(
        cm.registers(),
        tm.registers(),
        "registers after the last pulse"
    );
    let got = loop {
        if let Some(r) = col.push(&cm.step(&PinsIn::default())) {
            break r;
        }
    };
    assert_eq!(got, tm.readout(), "final readout");
    assert!(cm.registers().iter().all(|&y| y == 0), "readout clears");
}

fn sequencer_case(seed: u64) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let frames = 1 + rng.below(3) as usize;
    let n = p.frame_pulses as usize;
    let stimuli: Vec<Option<u32>> = (0..frames * n)
        .map(|_| random_detection(&mut rng, &p))
        .collect();
    let seq = Sequencer::new(&p, &stimuli, Some(&rom)).unwrap();
    assert_eq!(seq.len() as u64, seq.total_cycles());
    let mut cm = CycleModel::new(&p).unwrap();
    let mut col = ReadoutCollector::new(p.registers(), p.width);
    let mut got = Vec::new();
    let mut accepted = 0;
    for pins in seq {
        if let Some(r) = col.push(&cm.step(&pins)) {
            got.push(r);
        }
        accepted += u64::from(cm.accepted_pulse());
    }
    // The last status word is on the bus during the cycle after the sequence's last edge.
    if let Some(r) = col.push(&cm.outputs()) {
        got.push(r);
    }
    let mut tm = TransactionModel::new(&p).unwrap();
    let expected = tm.run_frames(&stimuli, Some(&rom)).unwrap();
    assert_eq!(
        accepted,
        (frames * n) as u64,
        "every sequenced pulse is accepted"
    );
    assert!(got.iter().all(|r| r.refused == 0));
    assert_eq!(got, expected);
}

/// `run` (regrouped partial sums) is bit-identical to `pulse` one at a time, across calls
/// that start mid-ROM, with R above 64 (several ROM words per entry) and narrow W.
fn batch_case(seed: u64) {
    let mut rng = Rng(seed);
    let mut p = random_params(&mut rng);
    p.mode = Mode::Fourier;
    p.bins = 1 + rng.below(80) as usize;
    p.adders = p.registers();
    p.cycles_per_pulse = 1;
    p.frame_pulses = 1000;
    p.width = p.width.max(p.operand_bits());
    let rom = random_rom(&mut rng, &p);
    let stimuli: Vec<Option<u32>> = (0..200).map(|_| random_detection(&mut rng, &p)).collect();
    let mut one = TransactionModel::new(&p).unwrap();
    let mut batch = TransactionModel::new(&p).unwrap();
    let mut start = 0usize;
    while start < stimuli.len() {
        let len = (1 + rng.below(60) as usize).min(stimuli.len() - start);
        batch
            .run(&stimuli[start..start + len], Some(&rom), start as u64)
            .unwrap();
        for (i, &d) in stimuli[start..start + len].iter().enumerate() {
            one.pulse(d, rom.entry((start + i) % p.rom_depth));
        }
        assert_eq!(batch.registers(), one.registers());
        assert_eq!(batch.prefilter_state(), one.prefilter_state());
        start += len;
    }
}

proptest! {
    // Each case is a few hundred cycles: 256 cases take about a second in debug.
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn cycle_model_equals_transaction_model(seed in any::<u64>()) {
        run_case(seed);
    }

    #[test]
    fn reference_sequencer_readouts_equal_transaction_frames(seed in any::<u64>()) {
        sequencer_case(seed);
    }

    #[test]
    fn batch_run_equals_pulse_by_pulse(seed in any::<u64>()) {
        batch_case(seed);
    }
}

/// The default configuration under the reference sequencer: every pulse accepted, one per
/// C = 16 cycles, and a frame costs N·C + R + 2 cycles.
#[test]
fn default_schedule_accepts_every_pulse() {
    let p = PixelParams::fourier_default(40, 20, 20);
    assert_eq!((p.registers(), p.slots()), (32, 16));
    let mut rng = Rng(7);
    let rom = random_rom(&mut rng, &p);
    let stimuli: Vec<Option<u32>> = (0..40).map(|i| Some(i % 80)).collect();
    let seq = Sequencer::new(&p, &stimuli, Some(&rom)).unwrap();
    assert_eq!(seq.total_cycles(), 2 + 2 * (20 * 16 + 32 + 2));
    let mut cm = CycleModel::new(&p).unwrap();
    let mut writes = 0;
    let mut accepted = 0;
    for pins in seq {
        cm.step(&pins);
        writes += cm.writes().len();
        accepted += usize::from(cm.accepted_pulse());
    }
    assert_eq!(accepted, 40);
    // The priming pulse (first of the record) contributes nothing; the other 39 write all
    // 32 registers; two readouts clear 32 registers each.
    assert_eq!(writes, 39 * 32 + 2 * 32);
    assert_eq!(cm.refused(), 0);
}

/// One frame of back-to-back pulses (a pulse at every edge, C = K = 1) on the cycle model
/// carrying `fault`; returns the first pulse whose registers differ from the transaction
/// model's, `None` if the frame and its readout agree.
fn back_to_back_first_difference(p: &PixelParams, fault: Option<Fault>) -> Option<u64> {
    let mut rng = Rng(11);
    let rom = random_rom(&mut rng, p);
    let mut cm = CycleModel::with_fault(p, fault).unwrap();
    let mut tm = TransactionModel::new(p).unwrap();
    for n in 0..p.frame_pulses {
        assert!(cm.outputs().ready, "K = 1 takes a pulse at every edge");
        let det = random_detection(&mut rng, p);
        let word = rom.entry(n as usize % p.rom_depth);
        cm.step(&PinsIn {
            pulse: true,
            valid: det.is_some(),
            tdc: det.unwrap_or(0),
            rom_word: word,
            ..PinsIn::default()
        });
        assert!(cm.accepted_pulse());
        if cm.registers() != tm.registers() {
            return Some(n);
        }
        tm.pulse(det, word);
    }
    cm.step(&PinsIn {
        readout: true,
        ..PinsIn::default()
    });
    (cm.registers() != tm.registers()).then_some(p.frame_pulses)
}

/// The pipeline's hazard (contract "Pipeline"): with K = 1 the read ahead of each pulse's
/// slot 0 meets the previous pulse's write of the same register at the same edge (Fourier
/// P ≤ A: every register; Haar: scale 0 always, scale u while v stays). With the forward
/// the cycle model equals the transaction model on back-to-back pulses; the model without
/// it (`MissingForward`) differs, so the check can fail.
#[test]
fn k1_back_to_back_pulses_need_the_forward() {
    let fourier = PixelParams {
        mode: Mode::Fourier,
        bins: 2,
        adders: 4,
        cycles_per_pulse: 1,
        tdc_bits: 4,
        zoom: 3,
        shift: 1,
        frac_bits: 2,
        width: 9,
        frame_pulses: 40,
        rom_depth: 8,
        ..PixelParams::default()
    };
    let haar = PixelParams {
        mode: Mode::Haar,
        bins: 1,
        haar_scales: 2,
        adders: 3,
        frame_pulses: 16,
        rom_depth: 1,
        ..fourier.clone()
    };
    for p in [fourier, haar] {
        p.validate().unwrap();
        assert_eq!((p.slots(), p.cycles_per_pulse), (1, 1), "{:?}", p.mode);
        assert_eq!(
            back_to_back_first_difference(&p, None),
            None,
            "{:?}",
            p.mode
        );
        assert!(
            back_to_back_first_difference(&p, Some(Fault::MissingForward)).is_some(),
            "{:?}: the missing forward must show",
            p.mode
        );
    }
}
