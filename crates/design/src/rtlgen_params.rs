//! The one conversion from the pixel's parameters to the RTL generator's. The generator
//! keeps its own parameter type for now; when it takes `tofprobe_pixel::PixelParams`
//! itself, this file and its callers' `rtlgen_params(…)` calls are deleted.

use tofprobe_rtlgen::params::{Mode, PixelParams as RtlgenParams};

/// The generator's parameters for the pixel `p` (same fields, same meaning; module
/// prefix `tofprobe`).
pub fn rtlgen_params(p: &tofprobe_pixel::PixelParams) -> RtlgenParams {
    RtlgenParams {
        mode: match p.mode {
            tofprobe_pixel::Mode::Fourier => Mode::Fourier,
            tofprobe_pixel::Mode::Haar => Mode::Haar,
        },
        bins: p.bins,
        haar_scales: p.haar_scales,
        adders: p.adders,
        cycles_per_pulse: p.cycles_per_pulse,
        tdc_bits: p.tdc_bits,
        zoom: p.zoom,
        shift: p.shift,
        frac_bits: p.frac_bits,
        width: p.width,
        frame_pulses: p.frame_pulses,
        rom_depth: p.rom_depth,
        module_prefix: "tofprobe".to_string(),
    }
}
