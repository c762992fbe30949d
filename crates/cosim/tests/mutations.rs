//! The co-simulation can fail: each deliberately broken RTL variant is caught, at exactly
//! the cycle where the same fault, injected through the hooks of the pixel crate's one
//! cycle model, first changes an observable (a register write or an output pin). That
//! cycle is computed by the model alone (`first_divergence`), independently of the
//! simulator. The pipeline's missing forward is a K = 1 hazard and runs on a K = 1 pixel
//! with a pulse at every edge.

mod common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::Fault;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::golden::first_divergence;
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
/// when K = 1 with back-to-back pulses; every other fault on the K = 2 pixel.
fn config_for(fault: Fault) -> PixelParams {
    match fault {
        Fault::MissingForward => config_k1(),
        _ => config(),
    }
}

#[test]
fn every_fault_is_caught_at_its_first_cycle() {
    if !tools_or_skip(&["verilator"], "every_fault_is_caught_at_its_first_cycle") {
        return;
    }
    let seed = 7;
    let frames = 2;
    // The clean RTL passes on the same stimulus (so a failure below is the fault's).
    for (name, p) in [("clean", config()), ("clean-k1", config_k1())] {
        p.validate().expect("valid configuration");
        let mut o = CosimOptions::new(work_dir(&format!("mutation-{name}")));
        o.frames = frames;
        o.seed = seed;
        let clean = cosim(&p, &o).expect("clean co-simulation runs");
        assert!(clean.pass, "{name}: clean RTL must pass: {:?}", clean.first);
    }
    assert_eq!(config_k1().slots(), 1);
    for fault in Fault::ALL {
        let p = config_for(fault);
        let stim = random_stimulus(&p, frames * p.frame_pulses, seed);
        let rom = sign_probe_rom(&p);
        let (cycle, pulse) = first_divergence(&p, &stim, &rom, frames, fault)
            .expect("the model accepts the configuration")
            .unwrap_or_else(|| panic!("{fault:?} never shows on this stimulus"));
        let mut o = CosimOptions::new(work_dir(&format!("mutation-{}", fault.name())));
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
