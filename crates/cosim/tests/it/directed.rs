//! The directed sequencer (docs/pixel-contract.md, "The directed sequencer") co-simulates
//! bit-exactly under Verilator and Icarus, in both modes, on a small-W pixel whose refused
//! counter saturates within the first loop; its status words are the contract's closed
//! forms; a long frame wraps the registers while the counter saturates.

use crate::common;
use common::*;
use tofprobe_cosim::{CosimOptions, Simulator, cosim};
use tofprobe_pixel::{DirectedOptions, Mode, PixelParams, TransactionModel};

/// The status words of one loop, closed forms of the schedule (crates/pixel/src/directed.rs):
/// frame 0 counts the pulse refused with the readout and the R refused while the words come
/// out (R + 1; the one at the status edge goes to frame 1); frame 1 saturates (2^W − 1);
/// frame 2 refuses nothing in Fourier mode, and in Haar mode the long frame's pulses beyond
/// N ((long − 1)·N).
fn status_words(p: &PixelParams, long: u64) -> [u64; 3] {
    let r = p.registers() as u64;
    let frame2 = match p.mode {
        Mode::Fourier => 0,
        Mode::Haar => (long - 1) * p.frame_pulses,
    };
    [r + 1, p.refused_max(), frame2]
}

#[test]
fn directed_schedule_cosimulates_bit_exactly() {
    if !tools_or_skip(
        &["verilator", "iverilog", "vvp"],
        "directed_schedule_cosimulates_bit_exactly",
    ) {
        return;
    }
    for mode in [Mode::Fourier, Mode::Haar] {
        let p = directed_config(mode);
        p.validate().expect("valid configuration");
        assert_eq!(p.slots(), 3, "{mode:?}: K");
        for sim in [Simulator::Verilator, Simulator::Icarus] {
            let mut o = CosimOptions::new(work_dir(&format!("directed-{mode:?}-{}", sim.name())));
            o.frames = 2;
            o.seed = 5;
            o.simulator = sim;
            o.vcd_on_mismatch = false;
            o.directed = Some(DirectedOptions::default());
            let r = cosim(&p, &o).expect("directed co-simulation runs");
            assert!(r.pass, "{mode:?} {}: {:?}", sim.name(), r.first);
            assert_eq!(r.outcome.frames, 6, "three frames per loop, two loops");
            let want = status_words(&p, 1);
            let got: Vec<u64> = r.readouts.iter().map(|f| f[p.registers()]).collect();
            assert_eq!(got, [want, want].concat(), "{mode:?}: status words");
            // Frames start with misses: the first two pulse strobes after reset.
            assert_eq!(r.stimulus[..2], [None, None]);
            eprintln!(
                "{mode:?} {}: {} cycles, {} pulse strobes, status words {got:?}: pass",
                sim.name(),
                r.cycles,
                r.pulses
            );
        }
    }
}

/// A clean directed RTL is refused when the run drives the reference sequencer, and the
/// other way round: the vectors of one cannot judge the other.
#[test]
fn rtl_of_the_other_sequencer_is_refused() {
    let p = directed_config(Mode::Haar);
    let dir = work_dir("directed-other");
    tofprobe_cosim::driver::render_driven(
        &p,
        &[],
        &dir.join("rtl"),
        None,
        Some(DirectedOptions::default()),
    )
    .expect("renders");
    let mut o = CosimOptions::new(dir.join("run"));
    o.rtl_dir = Some(dir.join("rtl"));
    let e = cosim(&p, &o)
        .expect_err("reference run on directed RTL")
        .to_string();
    assert!(
        e.contains("sequencer") && e.contains("directed (long_frame = 1)"),
        "{e}"
    );
    o.directed = Some(DirectedOptions {
        long_frame: 2,
        ..DirectedOptions::default()
    });
    let e = cosim(&p, &o).expect_err("long_frame differs").to_string();
    assert!(e.contains("long_frame = 2"), "{e}");
}

/// Wrap against saturate: with a frame 4× longer than N, the Fourier registers (W = 8,
/// sized for N) wrap while frame 1's refused counter saturates; RTL and model agree, and
/// every readout is the unwrapped sum of a 62-bit twin (fed the pulses the pixel accepted)
/// taken mod 2^W.
#[test]
fn long_frame_wraps_while_the_refused_counter_saturates() {
    if !tools_or_skip(
        &["verilator"],
        "long_frame_wraps_while_the_refused_counter_saturates",
    ) {
        return;
    }
    let p = directed_config(Mode::Fourier);
    let long = 4;
    let mut o = CosimOptions::new(work_dir("directed-long"));
    o.frames = 1;
    o.seed = 5;
    o.vcd_on_mismatch = false;
    o.directed = Some(DirectedOptions {
        long_frame: long,
        ..DirectedOptions::default()
    });
    let r = cosim(&p, &o).expect("runs");
    assert!(r.pass, "{:?}", r.first);
    let got: Vec<u64> = r.readouts.iter().map(|f| f[p.registers()]).collect();
    assert_eq!(got, status_words(&p, long), "status words");
    // The twin: the same sequence through the cycle model, its accepted pulses fed to a
    // 62-bit transaction model, read out where the pixel's status word comes out.
    let prog = tofprobe_pixel::directed_program(&p, o.directed.as_ref().unwrap()).unwrap();
    let image = tofprobe_rtlgen::golden::rom_image(&p, &r.rom);
    let seq = tofprobe_pixel::Sequencer::directed(&p, prog, &r.stimulus, image.as_ref(), 1)
        .unwrap()
        .with_status_cycle();
    let wide = PixelParams {
        width: 62,
        ..p.clone()
    };
    let mut twin = TransactionModel::new(&wide).unwrap();
    let mut model = tofprobe_pixel::CycleModel::new(&p).unwrap();
    let mut twin_readouts = Vec::new();
    for c in 0..seq.total_cycles() {
        let pins = seq.pins(c);
        if pins.rst {
            // The reset in the middle of frame 0 restarts the twin too.
            twin = TransactionModel::new(&wide).unwrap();
        }
        let out = model.step(&pins);
        if out.rd_valid && out.rd_index as usize == p.registers() {
            twin_readouts.push(twin.readout().words);
        }
        if model.accepted_pulse() {
            twin.pulse(pins.valid.then_some(pins.tdc), pins.rom_word);
        }
    }
    assert_eq!(twin_readouts.len(), r.readouts.len());
    let mask = (1u64 << p.width) - 1;
    let mut wrapped = 0;
    for (f, (wide_words, words)) in twin_readouts.iter().zip(&r.readouts).enumerate() {
        for (reg, &v) in wide_words.iter().enumerate() {
            assert_eq!(words[reg], (v as u64) & mask, "frame {f} register {reg}");
            if v >= 1 << (p.width - 1) || v < -(1 << (p.width - 1)) {
                wrapped += 1;
            }
        }
    }
    eprintln!("long frame ({long}·N): {wrapped} register words wrapped; status words {got:?}");
    assert!(wrapped > 0, "no register left W bits: no wrap-around shown");
}
