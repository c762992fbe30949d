//! The plain-Verilog testbench under Icarus: the default configuration (short frames, both
//! modes) passes, and a sign-flipped accumulate fails at the cycle the model predicts.

use crate::common;
use common::*;
use std::path::Path;
use tofprobe_cosim::{icarus, render_into};
use tofprobe_pixel::Fault;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::golden::first_divergence;
use tofprobe_rtlgen::stimulus::{random_stimulus, sign_probe_rom};
use tofprobe_rtlgen::vectors::golden_run;
use tofprobe_rtlgen::vectors::{VectorOptions, write_vectors};
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, module_names};

fn run(
    p: &PixelParams,
    dir: &Path,
    fault: Option<Fault>,
    frames: u64,
) -> tofprobe_cosim::RunOutcome {
    let rtl = dir.join("rtl");
    render_into(p, &rtl, fault).expect("renders");
    let stim = random_stimulus(p, frames * p.frame_pulses, 3);
    let rom = sign_probe_rom(p);
    let o = VectorOptions {
        frames,
        seed: 3,
        ..VectorOptions::default()
    };
    // The judge: the pixel crate's cycle model.
    let (g, w) = golden_run(p, &stim, &rom, &o).expect("pixel model accepts");
    let vec = dir.join("vectors");
    write_vectors(&vec, p, &stim, &rom, &g, w, &o).expect("writes vectors");
    let rtl = std::fs::canonicalize(rtl).expect("rtl dir");
    let vec = std::fs::canonicalize(vec).expect("vec dir");
    icarus::run(
        &rtl,
        &vec,
        &module_names(DEFAULT_MODULE_PREFIX).2,
        &dir.join("icarus"),
    )
    .expect("icarus runs")
}

#[test]
fn default_passes_under_icarus() {
    if !tools_or_skip(&["iverilog", "vvp"], "default_passes_under_icarus") {
        return;
    }
    for mode in [Mode::Fourier, Mode::Haar] {
        let mut p = short_default(mode);
        p.frame_pulses = 64;
        p.rom_depth = 64;
        let out = run(&p, &work_dir(&format!("icarus-{mode:?}")), None, 2);
        assert_eq!(out.mismatches, 0, "{mode:?}: {:?}", out.first);
        assert_eq!(out.frames, 2);
        assert_eq!(out.cycles, 2 + 2 * (64 * 16 + p.registers() as u64 + 2) + 1);
    }
}

#[test]
fn icarus_catches_a_sign_flip_at_its_first_cycle() {
    if !tools_or_skip(
        &["iverilog", "vvp"],
        "icarus_catches_a_sign_flip_at_its_first_cycle",
    ) {
        return;
    }
    let mut p = short_default(Mode::Fourier);
    p.frame_pulses = 32;
    p.rom_depth = 32;
    let stim = random_stimulus(&p, p.frame_pulses, 3);
    let (cycle, pulse) = first_divergence(&p, &stim, &sign_probe_rom(&p), 1, Fault::SignFlip)
        .expect("the model accepts the configuration")
        .expect("shows");
    let out = run(&p, &work_dir("icarus-signflip"), Some(Fault::SignFlip), 1);
    let m = out.first.expect("a mismatch is reported");
    assert_eq!((m.cycle, m.pulse), (cycle, pulse), "{m:?}");
}
