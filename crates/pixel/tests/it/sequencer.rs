//! The reference sequencer's iterator counts its way through the sequence (no division per
//! cycle); it must present exactly the pins of `Sequencer::pins(cycle)`, which computes
//! each cycle's phase from its index, over random configurations (both modes, any C, N, L,
//! R), several frames and the golden vectors' extra status cycle.

use crate::common;

use common::{Rng, random_detection, random_params, random_rom};
use tofprobe_pixel::{PinsIn, Sequencer};

#[test]
fn the_iterator_presents_the_pins_of_every_cycle() {
    let mut rng = Rng(2028);
    for case in 0..200 {
        let mut p = random_params(&mut rng);
        if p.mode == tofprobe_pixel::Mode::Fourier {
            p.rom_depth = 1 + rng.below(20) as usize;
        }
        let rom = random_rom(&mut rng, &p);
        let frames = 1 + rng.below(3) as usize;
        let stimuli: Vec<Option<u32>> = (0..frames * p.frame_pulses as usize)
            .map(|_| random_detection(&mut rng, &p))
            .collect();
        let mut seq = Sequencer::new(&p, &stimuli, Some(&rom)).unwrap();
        if rng.chance(50) {
            seq = seq.with_status_cycle();
        }
        let reference: Vec<PinsIn> = (0..seq.total_cycles()).map(|c| seq.pins(c)).collect();
        let counted: Vec<PinsIn> = seq.clone().collect();
        assert_eq!(counted, reference, "case {case}: {p:?}");
        // The sequence has pulses, readouts and a reset: not a trivially equal stream.
        let pulses = counted.iter().filter(|x| x.pulse).count();
        let extra = usize::from(seq.total_cycles() > 2 + (frames as u64) * seq.frame_cycles());
        assert_eq!(pulses, stimuli.len() + extra, "case {case}");
        assert_eq!(counted.iter().filter(|x| x.readout).count(), frames);
        assert_eq!(counted.iter().filter(|x| x.rst).count(), 2);
    }
}

/// The counted ROM address wraps at L: in a frame longer than the ROM, pulse 4 of a
/// 3-entry ROM reads entry 1 (a count that did not wrap would read past the ROM).
#[test]
fn the_counted_rom_address_wraps_at_l() {
    let p = tofprobe_pixel::PixelParams::fourier_default(30, 7, 3);
    let mut rng = Rng(1);
    let rom = random_rom(&mut rng, &p);
    let stimuli = vec![Some(5); 7];
    let seq = Sequencer::new(&p, &stimuli, Some(&rom)).unwrap();
    // Pulse 4 of the frame reads address 4 mod 3 = 1, not entry 4.
    let cycle = 2 + 4 * p.cycles_per_pulse as u64;
    let counted = seq.clone().nth(cycle as usize).unwrap();
    assert!(counted.pulse);
    assert_eq!(counted.rom_word, rom.entry(1));
    assert_eq!(counted, seq.pins(cycle));
}

/// Pulse strobes come in index order in both sequencers: cycle c presents a pulse exactly
/// when `pulse_index(c)` is some k, and k counts the strobes before it. The golden run
/// (tofprobe-rtlgen) counts strobes instead of asking `pulse_index` per cycle.
#[test]
fn pulse_strobes_are_presented_in_index_order() {
    let mut rng = Rng(2029);
    for case in 0..60 {
        let p = random_params(&mut rng);
        let rom = random_rom(&mut rng, &p);
        let directed = rng.chance(50);
        let program = directed.then(|| {
            let o = tofprobe_pixel::DirectedOptions {
                long_frame: 1 + rng.below(3),
                ..Default::default()
            };
            tofprobe_pixel::directed_program(&p, &o).unwrap()
        });
        let frames = 1 + rng.below(2);
        let pulses = match &program {
            Some(prog) => frames * prog.loop_pulses(),
            None => frames * p.frame_pulses,
        };
        let stimuli: Vec<Option<u32>> = (0..pulses)
            .map(|_| random_detection(&mut rng, &p))
            .collect();
        let seq = match program {
            Some(prog) => Sequencer::directed(&p, prog, &stimuli, Some(&rom), frames).unwrap(),
            None => Sequencer::new(&p, &stimuli, Some(&rom)).unwrap(),
        }
        .with_status_cycle();
        let mut strobes = 0u64;
        for (c, pins) in (0u64..).zip(seq.clone()) {
            let index = seq.pulse_index(c);
            assert_eq!(index.is_some(), pins.pulse, "case {case} cycle {c}");
            if let Some(k) = index {
                assert_eq!(k, strobes, "case {case} cycle {c} (directed {directed})");
                strobes += 1;
            }
        }
        // Every pulse of the stimuli, plus the status cycle's strobe.
        assert_eq!(strobes, pulses + 1, "case {case}");
    }
}
