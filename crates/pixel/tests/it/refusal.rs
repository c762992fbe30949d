//! The cycle model alone: pulses strobed while the pixel cannot take them are counted and
//! change nothing else (issue point 2), and the accumulate schedule is the contract's table
//! (operation j = slot·A + a on register j at edge t + 1 + slot).

use crate::common;

use common::{Rng, random_detection, random_params, random_rom};
use proptest::prelude::*;
use tofprobe_pixel::fixed::to_raw;
use tofprobe_pixel::schedule::haar_target;
use tofprobe_pixel::{CycleModel, Mode, PinsIn, PixelParams};

/// Two pixels in lockstep: `a` also gets strobes at cycles where it is not ready (and,
/// Haar, pulses beyond a full frame), `b` idles there. Every state element must stay equal
/// and `a` must have counted exactly the extra strobes.
fn refusal_case(seed: u64) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let mut a = CycleModel::new(&p).unwrap();
    let mut b = CycleModel::new(&p).unwrap();
    let mut extra = 0u64;
    let mut addr = 0usize;
    for _ in 0..300 {
        let ready = a.outputs().ready;
        assert_eq!(ready, b.outputs().ready);
        let full = p.mode == Mode::Haar && a.pcount() == p.frame_pulses;
        let det = random_detection(&mut rng, &p);
        let pins = PinsIn {
            pulse: true,
            valid: det.is_some(),
            tdc: det.unwrap_or(0),
            rom_word: rom.entry(addr % p.rom_depth),
            ..PinsIn::default()
        };
        if !ready || full {
            // Only `a` sees a strobe it must refuse.
            if rng.chance(60) {
                a.step(&pins);
                extra += 1;
            } else {
                a.step(&PinsIn::default());
            }
            b.step(&PinsIn::default());
            assert!(!a.accepted_pulse());
        } else if rng.chance(50) {
            a.step(&pins);
            b.step(&pins);
            assert!(a.accepted_pulse() && b.accepted_pulse());
            addr += 1;
        } else {
            a.step(&PinsIn::default());
            b.step(&PinsIn::default());
        }
        assert_eq!(a.registers(), b.registers());
        assert_eq!(
            (a.primed(), a.held(), a.prefilter_state(), a.pcount()),
            (b.primed(), b.held(), b.prefilter_state(), b.pcount())
        );
        assert_eq!(a.writes(), b.writes());
        assert_eq!(a.refused(), extra.min(p.refused_max()), "refused count");
        assert_eq!(b.refused(), 0);
    }
}

/// Accept one pulse and check which registers each of the next K edges writes.
fn schedule_case(seed: u64) {
    let mut rng = Rng(seed);
    let p = random_params(&mut rng);
    let rom = random_rom(&mut rng, &p);
    let mut cm = CycleModel::new(&p).unwrap();
    // Prime with a first valid pulse (Fourier: it contributes nothing), wait it out.
    let prime = PinsIn {
        pulse: true,
        valid: true,
        tdc: 1,
        rom_word: rom.entry(0),
        ..PinsIn::default()
    };
    cm.step(&prime);
    let prime_writes = (0..p.slots())
        .map(|_| {
            cm.step(&PinsIn::default());
            cm.writes().len()
        })
        .sum::<usize>();
    let expected_prime = if p.mode == Mode::Haar {
        p.ops_per_pulse()
    } else {
        0
    };
    assert_eq!(prime_writes, expected_prime, "priming pulse writes");
    let det = random_detection(&mut rng, &p);
    let word = rom.entry(1 % p.rom_depth);
    cm.step(&PinsIn {
        pulse: true,
        valid: det.is_some(),
        tdc: det.unwrap_or(0),
        rom_word: word,
        ..PinsIn::default()
    });
    assert!(cm.accepted_pulse());
    let n_lat = cm.pcount() - 1;
    for slot in 0..p.slots() {
        let before = cm.registers().to_vec();
        assert!(!cm.outputs().ready || slot == p.slots() - 1);
        cm.step(&PinsIn::default());
        let regs: Vec<usize> = cm.writes().iter().map(|w| w.register as usize).collect();
        let expected: Vec<usize> = (slot * p.adders
            ..((slot + 1) * p.adders).min(p.ops_per_pulse()))
            .map(|j| match p.mode {
                Mode::Fourier => j,
                Mode::Haar => haar_target(n_lat, j as u32, p.log2_frame()).0,
            })
            .collect();
        assert_eq!(regs, expected, "slot {slot}");
        for w in cm.writes() {
            let r = w.register as usize;
            assert_eq!(w.value, to_raw(cm.registers()[r], p.width));
            assert_ne!(before[r], i64::MIN, "sanity");
        }
    }
    assert!(cm.outputs().ready, "free after K slots");
    assert!(
        cm.writes()
            .iter()
            .all(|w| (w.register as usize) < p.registers())
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]
    #[test]
    fn refused_pulses_are_counted_and_change_nothing(seed in any::<u64>()) {
        refusal_case(seed);
    }

    #[test]
    fn accumulate_schedule_is_the_contract_table(seed in any::<u64>()) {
        schedule_case(seed);
    }
}

/// The refused counter saturates at 2^W − 1 instead of wrapping (a count the user relies on
/// never silently restarts), and the status word reports it and clears it.
#[test]
fn refused_counter_saturates_and_is_reported() {
    let mut p = PixelParams::fourier_default(5, 4, 4);
    p.bins = 20;
    p.tdc_bits = 2;
    p.frac_bits = 0;
    p.adders = 1;
    p.cycles_per_pulse = 40;
    assert_eq!((p.operand_bits(), p.slots()), (3, 40));
    let strobe = PinsIn {
        pulse: true,
        ..PinsIn::default()
    };
    // One accepted pulse keeps the pipeline busy for K − 1 = 39 edges: 39 refusals.
    let mut cm = CycleModel::new(&p).unwrap();
    cm.step(&strobe);
    assert!(cm.accepted_pulse());
    for i in 0..39 {
        assert!(!cm.outputs().ready, "edge {i}");
        cm.step(&strobe);
    }
    assert_eq!(cm.refused(), 31, "39 refusals saturate at 2^5 − 1");
    assert!(cm.outputs().ready);

    // Status word: R = 40 words after the readout edge, then the status at the next edge.
    // Strobes during the words count; the one at the status edge goes to the next frame.
    let mut cm = CycleModel::new(&p).unwrap();
    cm.step(&PinsIn {
        readout: true,
        ..PinsIn::default()
    });
    for _ in 0..40 {
        cm.step(&strobe);
    }
    assert_eq!(cm.refused(), 31);
    cm.step(&strobe); // the status edge
    let status = cm.outputs();
    assert_eq!(
        (status.rd_valid, status.rd_index, status.rd_data),
        (true, 40, 31)
    );
    assert_eq!(
        cm.refused(),
        1,
        "the strobe at the status edge starts the next count"
    );
    assert!(status.ready);
}
