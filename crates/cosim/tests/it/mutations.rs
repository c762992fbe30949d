//! The co-simulation can fail: each deliberately broken RTL variant is caught, at exactly
//! the cycle where the same fault, injected through the hooks of the pixel crate's one
//! cycle model, first changes an observable (a register write or an output pin). That
//! cycle is computed by the model alone (`first_divergence`), independently of the
//! simulator. The pipeline's missing forward is a K = 1 hazard and runs on a K = 1 pixel
//! with a pulse at every edge.

use crate::common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::Fault;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::golden::{first_divergence, first_divergence_with};
use tofprobe_rtlgen::stimulus::{random_stimulus, sign_probe_rom};

/// Small enough to verilate quickly; W = operand + 1 so register 0 overflows W−1 bits
/// within the first frame; Z > 0 and S > 0 so d and the prefilter step go negative.
fn config() -> PixelParams {
    PixelParams {
        mode: Mode::Fourier,
        bins: 2,
        adders: 2,
        cycles_per_pulse: 3,
        tdc_bits: 4,
        zoom: 5,
        shift: 2,
        frac_bits: 2,
        width: 8,
        frame_pulses: 48,
        rom_depth: 16,
        ..PixelParams::default()
    }
}

/// K = 1 with a pulse at every edge (C = 1): each pulse's read ahead meets the previous
/// pulse's write of the same register, the pipeline hazard the forward resolves.
fn config_k1() -> PixelParams {
    PixelParams {
        bins: 1,
        adders: 2,
        cycles_per_pulse: 1,
        ..config()
    }
}

/// The configuration each fault is tested on: the pipeline's missing forward shows only
/// when K = 1 with back-to-back pulses; every other fault on the K = 2 pixel. `g`: the
/// registers' fraction bits (`None`: all F), W one bit above their operand as in
/// [`config`].
fn config_for(fault: Fault, g: Option<u32>) -> PixelParams {
    let mut p = match fault {
        Fault::MissingForward => config_k1(),
        _ => config(),
    };
    p.register_frac_bits = g;
    p.width = p.operand_bits() + 1;
    p
}

#[test]
fn every_fault_is_caught_at_its_first_cycle() {
    faults_caught(&Fault::ALL, None, "");
}

/// The faults of the operand's path with registers keeping G = 0 of the F = 2 fraction
/// bits (the operand a slice of x, W one bit above it): the prefilter's logical shift and
/// the hold change x, the narrow register wraps the narrower sums; each still shows at the
/// cycle the model predicts. (The sign, schedule and forward faults do not see G.)
#[test]
fn operand_faults_are_caught_at_their_first_cycle_with_g_below_f() {
    faults_caught(
        &[
            Fault::LogicalShift,
            Fault::HoldInvalid,
            Fault::NarrowRegister,
        ],
        Some(0),
        "-g0",
    );
}

fn faults_caught(faults: &[Fault], g: Option<u32>, tag: &str) {
    if !tools_or_skip(&["verilator"], "every_fault_is_caught_at_its_first_cycle") {
        return;
    }
    let seed = 7;
    let frames = 2;
    // The clean RTL passes on the same stimulus (so a failure below is the fault's).
    let k1 = faults.contains(&Fault::MissingForward);
    let clean = [
        ("clean", config_for(Fault::SignFlip, g)),
        ("clean-k1", config_for(Fault::MissingForward, g)),
    ];
    for (name, p) in clean.into_iter().filter(|(n, _)| k1 || *n == "clean") {
        p.validate().expect("valid configuration");
        let mut o = CosimOptions::new(work_dir(&format!("mutation-{name}{tag}")));
        o.frames = frames;
        o.seed = seed;
        let clean = cosim(&p, &o).expect("clean co-simulation runs");
        assert!(clean.pass, "{name}: clean RTL must pass: {:?}", clean.first);
    }
    assert_eq!(config_k1().slots(), 1);
    for &fault in faults {
        let p = config_for(fault, g);
        let stim = random_stimulus(&p, frames * p.frame_pulses, seed);
        let rom = sign_probe_rom(&p);
        let (cycle, pulse) = first_divergence(&p, &stim, &rom, frames, fault)
            .expect("the model accepts the configuration")
            .unwrap_or_else(|| panic!("{fault:?} never shows on this stimulus"));
        let mut o = CosimOptions::new(work_dir(&format!("mutation-{}{tag}", fault.name())));
        o.frames = frames;
        o.seed = seed;
        o.mutation = Some(fault);
        o.vcd_on_mismatch = false;
        let r = cosim(&p, &o).expect("mutated co-simulation runs");
        assert!(!r.pass, "{fault:?} was not caught");
        let m = r
            .first
            .unwrap_or_else(|| panic!("{fault:?}: no first mismatch reported"));
        assert_eq!(
            m.cycle, cycle,
            "{fault:?}: reported {m:?}, the model says cycle {cycle}"
        );
        assert_eq!(m.pulse, pulse, "{fault:?}: pulse index");
        eprintln!(
            "{fault:?}: caught at cycle {} (pulse {}): {} expected {} actual {}",
            m.cycle, m.pulse, m.signal, m.expected, m.actual
        );
    }
}

/// The long-frame path: with digests only (4 pulses per window), a fault is still pinned to
/// its first cycle by re-running the first differing window with its full trace.
#[test]
fn digest_mismatch_is_refined_to_the_first_cycle() {
    if !tools_or_skip(
        &["verilator"],
        "digest_mismatch_is_refined_to_the_first_cycle",
    ) {
        return;
    }
    let p = config();
    let (seed, frames) = (7, 2);
    let stim = random_stimulus(&p, frames * p.frame_pulses, seed);
    let fault = Fault::LogicalShift;
    let (cycle, pulse) = first_divergence(&p, &stim, &sign_probe_rom(&p), frames, fault)
        .expect("the model accepts the configuration")
        .expect("shows");
    let mut o = CosimOptions::new(work_dir("mutation-digest"));
    o.frames = frames;
    o.seed = seed;
    o.mutation = Some(fault);
    o.vcd_on_mismatch = false;
    o.digest_only = true;
    o.digest_pulses = 4;
    let r = cosim(&p, &o).expect("runs");
    assert!(!r.pass);
    let d = r.outcome.digest.expect("a digest window differs");
    assert_eq!(
        d.first_pulse,
        pulse / 4 * 4,
        "window of the first divergence"
    );
    let m = r.first.expect("refined to a cycle");
    assert_eq!((m.cycle, m.pulse), (cycle, pulse), "{m:?}");
}

/// The refusal path's faults (status word, refused counter, Haar frame limit): the
/// reference sequencer refuses no pulse, so they show only under the directed sequencer
/// (docs/pixel-contract.md, "The directed sequencer"). Each is caught, in every mode it
/// applies to, at exactly the cycle (and pulse) the model carrying it predicts, with the
/// expected and actual values of that mismatch. The score is asserted: 5/5.
#[test]
fn refusal_faults_are_caught_at_their_first_cycle_by_the_directed_schedule() {
    if !tools_or_skip(
        &["verilator"],
        "refusal_faults_are_caught_at_their_first_cycle_by_the_directed_schedule",
    ) {
        return;
    }
    let (seed, frames) = (5, 1);
    let directed = tofprobe_pixel::DirectedOptions::default();
    let (mut caught, mut total) = (0, 0);
    for mode in [Mode::Fourier, Mode::Haar] {
        let p = directed_config(mode);
        for fault in Fault::REFUSAL {
            if mode == Mode::Fourier && fault == Fault::HaarFrameLimit {
                continue;
            }
            total += 1;
            let prog = tofprobe_pixel::directed_program(&p, &directed).expect("program");
            let mut stim = random_stimulus(&p, frames * prog.loop_pulses(), seed);
            prog.miss_frame_leads(&mut stim);
            let rom = sign_probe_rom(&p);
            let (cycle, pulse) =
                first_divergence_with(&p, &stim, &rom, frames, Some(&directed), fault)
                    .expect("the model accepts the configuration")
                    .unwrap_or_else(|| panic!("{mode:?} {fault:?} never shows on the schedule"));
            // Under the reference sequencer the same fault never shows (why it survived).
            let ref_stim = random_stimulus(&p, 2 * p.frame_pulses, seed);
            assert_eq!(
                first_divergence(&p, &ref_stim, &rom, 2, fault).expect("model"),
                None,
                "{mode:?} {fault:?} shows under the reference sequencer"
            );
            let mut o = CosimOptions::new(work_dir(&format!("refusal-{mode:?}-{}", fault.name())));
            o.frames = frames;
            o.seed = seed;
            o.mutation = Some(fault);
            o.vcd_on_mismatch = false;
            o.directed = Some(directed);
            let r = cosim(&p, &o).expect("mutated co-simulation runs");
            assert!(!r.pass, "{mode:?} {fault:?} was not caught");
            let m = r
                .first
                .unwrap_or_else(|| panic!("{mode:?} {fault:?}: no first mismatch reported"));
            assert_eq!(
                (m.cycle, m.pulse),
                (cycle, pulse),
                "{mode:?} {fault:?}: reported {m:?}, the model says cycle {cycle}"
            );
            caught += 1;
            eprintln!(
                "{mode:?} {fault:?}: caught at cycle {} (pulse {}): {} expected {} actual {}",
                m.cycle, m.pulse, m.signal, m.expected, m.actual
            );
        }
    }
    eprintln!("refusal faults caught at their predicted cycle: {caught}/{total}");
    assert_eq!((caught, total), (5, 5));
}

/// The faults the cycle model has no hook for, under Icarus (a fast compile per mutant, and
/// every state element reset forgets is an X there), in both modes, with a directed
/// stimulus whose frames start with missed pulses (the priming rule): each is caught, with
/// its first mismatch reported (the refusal path's faults are modelled: see
/// `refusal_faults_are_caught_at_their_first_cycle_by_the_directed_schedule`; the
/// stimulus faults, `Fault::STIMULUS`, are caught in stimulus.rs).
#[test]
fn unmodelled_faults_are_caught_under_icarus() {
    if !tools_or_skip(
        &["iverilog", "vvp"],
        "unmodelled_faults_are_caught_under_icarus",
    ) {
        return;
    }
    let mut caught = 0;
    let mut total = 0;
    for mode in [Mode::Fourier, Mode::Haar] {
        let p = PixelParams {
            mode,
            haar_scales: 2,
            frame_pulses: 16,
            ..config()
        };
        p.validate().expect("valid configuration");
        let run = |fault: Option<Fault>| {
            let name = fault.map(Fault::name).unwrap_or("clean");
            let mut o = CosimOptions::new(work_dir(&format!("icarus-mut-{mode:?}-{name}")));
            o.frames = 2;
            o.seed = 7;
            o.lead_misses = 3;
            o.mutation = fault;
            o.simulator = tofprobe_cosim::Simulator::Icarus;
            cosim(&p, &o).expect("icarus co-simulation runs")
        };
        let clean = run(None);
        assert!(clean.pass, "{mode:?} clean: {:?}", clean.first);
        assert_eq!(clean.stimulus[..3], [None, None, None]);
        // The stimulus faults need the directed sequencer's mid-frame reset and words that
        // leave W bits: crates/cosim/tests/it/stimulus.rs.
        for fault in Fault::UNMODELLED
            .into_iter()
            .filter(|f| !Fault::STIMULUS.contains(f))
        {
            total += 1;
            let r = run(Some(fault));
            assert!(!r.pass, "{mode:?} {fault:?} was not caught");
            let m = r
                .first
                .unwrap_or_else(|| panic!("{fault:?}: no first mismatch"));
            caught += 1;
            eprintln!(
                "{mode:?} {fault:?}: caught at cycle {} (pulse {}): {} expected {} actual {}",
                m.cycle, m.pulse, m.signal, m.expected, m.actual
            );
        }
    }
    eprintln!("unmodelled faults caught: {caught}/{total}");
    assert_eq!((caught, total), (8, 8));
}

/// A forgotten reset passes with registers that start at zero; with randomised initial
/// values (`--x-initial unique`, `+verilator+rand+reset+2`) the seeds of CI catch it, and
/// the clean RTL passes under the same seeds.
#[test]
fn forgotten_reset_is_caught_with_random_initial_values() {
    if !tools_or_skip(
        &["verilator"],
        "forgotten_reset_is_caught_with_random_initial_values",
    ) {
        return;
    }
    let p = config();
    let seeds = [1u64, 2, 3, 4];
    let mut caught = Vec::new();
    for fault in [None, Some(Fault::ResetPrimed)] {
        for &x_seed in &seeds {
            let name = fault.map(Fault::name).unwrap_or("clean");
            let mut o = CosimOptions::new(work_dir(&format!("xreset-{name}-{x_seed}")));
            o.frames = 1;
            o.seed = 7;
            o.x_seed = x_seed;
            o.mutation = fault;
            o.vcd_on_mismatch = false;
            let r = cosim(&p, &o).expect("runs");
            assert_eq!(r.x_seed, x_seed);
            match fault {
                None => assert!(r.pass, "clean RTL, x-seed {x_seed}: {:?}", r.first),
                Some(_) if !r.pass => caught.push(x_seed),
                Some(_) => {}
            }
        }
    }
    eprintln!("forgotten reset caught at x-seeds {caught:?} of {seeds:?}");
    assert!(!caught.is_empty(), "no CI seed catches the forgotten reset");
}

/// Frames longer than the width was sized for: W = 8 holds one operand plus one bit, so
/// the accumulators wrap; RTL and model agree, and the readout is the unwrapped sum of a
/// 62-bit twin taken mod 2^W (the contract's "exact whenever the final value fits").
#[test]
fn wrap_around_beyond_the_sized_width_cosimulates() {
    if !tools_or_skip(
        &["verilator"],
        "wrap_around_beyond_the_sized_width_cosimulates",
    ) {
        return;
    }
    let p = config();
    let mut o = CosimOptions::new(work_dir("wrap"));
    o.frames = 1;
    o.seed = 7;
    let r = cosim(&p, &o).expect("runs");
    assert!(r.pass, "{:?}", r.first);
    let wide = PixelParams {
        width: 62,
        ..p.clone()
    };
    let mut m = tofprobe_pixel::TransactionModel::new(&wide).expect("wide twin");
    let words = p.registers().div_ceil(64);
    for (i, d) in r.stimulus.iter().enumerate() {
        let a = (i % p.rom_depth) * words;
        m.pulse(*d, &r.rom[a..a + words]);
    }
    let wide_words = m.readout().words;
    let mask = (1u64 << p.width) - 1;
    let mut wrapped = 0;
    for (reg, &v) in wide_words.iter().enumerate() {
        assert_eq!(r.readouts[0][reg], (v as u64) & mask, "register {reg}");
        if v >= 1 << (p.width - 1) || v < -(1 << (p.width - 1)) {
            wrapped += 1;
        }
    }
    assert!(
        wrapped > 0,
        "no register left W bits: the test shows no wrap-around"
    );
}
