//! The default configuration, short frames, both modes: Verilator and Icarus agree with
//! the reference model bit for bit.

use crate::common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::{Mode, PixelParams};

#[test]
fn default_fourier_and_haar_pass_in_verilator() {
    if !tools_or_skip(&["verilator"], "default_fourier_and_haar_pass_in_verilator") {
        return;
    }
    for mode in [Mode::Fourier, Mode::Haar] {
        let p = short_default(mode);
        let mut o = CosimOptions::new(work_dir(&format!("default-{mode:?}")));
        o.frames = 3;
        let r = cosim(&p, &o).expect("co-simulation runs");
        assert!(r.pass, "{mode:?}: {:?}", r.first);
        // The run really covered the sequence: 2 reset cycles + frames·(N·C + R + 2) + 1
        // trailing cycle.
        let c = 2 + 3 * (128 * 16 + p.registers() as u64 + 2) + 1;
        assert_eq!(r.outcome.cycles, c);
        assert_eq!(r.outcome.frames, 3);
    }
}

/// `--rtl DIR`: the committed short-frame default RTL co-simulates clean, and a second run
/// reuses the cached Verilator build instead of re-verilating.
#[test]
fn committed_rtl_dir_passes_and_the_build_is_reused() {
    if !tools_or_skip(
        &["verilator"],
        "committed_rtl_dir_passes_and_the_build_is_reused",
    ) {
        return;
    }
    let rtl =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl");
    // The default's periodic ΣΔ ROM (L = 20,000) of which a 64-pulse frame reads the start.
    let p = PixelParams {
        frame_pulses: 64,
        rom_depth: 20_000,
        ..PixelParams::default()
    };
    // The committed RTL records T, F and W resolved from the embedded default scene.
    let p = PixelParams {
        tdc_bits: 7,
        frac_bits: 8,
        width: 39,
        ..p
    };
    let mut o = CosimOptions::new(work_dir("rtl-dir"));
    o.rtl_dir = Some(rtl);
    o.frames = 2;
    let first = cosim(&p, &o).expect("runs");
    assert!(first.pass, "{:?}", first.first);
    let second = cosim(&p, &o).expect("runs again");
    assert!(second.pass);
    assert!(second.build.reused, "the second run re-verilated");
    assert_eq!(first.build.exe, second.build.exe);
}
