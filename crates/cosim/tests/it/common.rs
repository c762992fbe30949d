//! Shared helpers of the co-simulation tests.
#![allow(dead_code)]

use std::path::PathBuf;
use tofprobe_pixel::{Mode, PixelParams};

/// True when the tools exist; otherwise prints a loud SKIP line (CI installs them via
/// scripts/test.sh, so there the tests always run).
pub fn tools_or_skip(tools: &[&'static str], test: &str) -> bool {
    tofprobe_testkit::tools::have(tools, test)
}

/// A fresh work directory under the cargo target dir.
pub fn work_dir(name: &str) -> PathBuf {
    let base = std::env::var_os("CARGO_TARGET_TMPDIR")
        .map(PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    let d = base.join("cosim-tests").join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The default configuration with a short frame (CI-sized).
pub fn short_default(mode: Mode) -> PixelParams {
    PixelParams {
        mode,
        frame_pulses: 128,
        rom_depth: 128,
        ..PixelParams::default()
    }
}

/// K = 3 (Fourier: R = 6 over 2 adders; Haar: U = 2, 3 scales over 1 adder), C = 4, and
/// W = 8: 2^W − 1 = 255 refusals saturate the counter, a frame of 16 pulses of 4-bit codes
/// fits, and a 4× longer one wraps.
pub fn directed_config(mode: Mode) -> PixelParams {
    PixelParams {
        mode,
        bins: 3,
        haar_scales: 2,
        adders: if mode == Mode::Fourier { 2 } else { 1 },
        cycles_per_pulse: 4,
        tdc_bits: 4,
        zoom: 5,
        shift: 2,
        frac_bits: 2,
        width: 8,
        frame_pulses: 16,
        rom_depth: 16,
        prefilter_rounding: Default::default(),
        register_frac_bits: None,
        register_file: Default::default(),
    }
}
