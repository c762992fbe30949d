//! The default configuration, short frames, both modes: Verilator and Icarus agree with
//! the reference model bit for bit.

mod common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_rtlgen::params::Mode;

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
