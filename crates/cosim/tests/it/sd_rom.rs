//! The ΣΔ probe ROM of crates/dsp (what `tofprobe flow` renders) goes into the RTL and
//! co-simulates clean: the image read back from the rendered RTL is the generated one, bit
//! for bit, and Verilator agrees with the reference model replaying it.

use crate::common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_dsp::sd::{ProbeConfig, ProbeDesign, ProbeRom};
use tofprobe_pixel::PixelParams;

#[test]
fn sigma_delta_rom_is_rendered_and_cosimulates() {
    if !tools_or_skip(
        &["verilator"],
        "sigma_delta_rom_is_rendered_and_cosimulates",
    ) {
        return;
    }
    // Windowed, L = N = 2048: the ΣΔ band f_s/(2·OSR) holds bins 1..31; three bins.
    let n = 2048u64;
    let design = ProbeDesign::new(&ProbeConfig::default(), 3.0 / n as f64).expect("design");
    let rom = ProbeRom::generate(&design, 10e6, n, &[3, 11, 29]).expect("rom");
    let p = PixelParams {
        bins: 3,
        frame_pulses: n,
        rom_depth: rom.depth(),
        tdc_bits: 7,
        frac_bits: 8,
        width: 39,
        ..PixelParams::default()
    };
    let words = rom.image.words().to_vec();
    // Not the sign probe: the test would otherwise not show the ΣΔ image is used.
    assert_ne!(words, tofprobe_rtlgen::stimulus::sign_probe_rom(&p));
    let mut o = CosimOptions::new(work_dir("sd-rom"));
    o.frames = 1;
    o.rom = Some(words.clone());
    let r = cosim(&p, &o).expect("co-simulation runs");
    assert!(r.pass, "{:?}", r.first);
    assert_eq!(r.rom, words, "the RTL's $readmemh image is the ΣΔ ROM");
    assert_eq!(r.outcome.frames, 1);
}
