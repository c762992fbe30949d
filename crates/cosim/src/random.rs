//! Random valid configurations for `tofprobe cosim --random N --seed S` and the CI's eight:
//! both modes and every knob of the pixel (B or U, A, C, T, Z, S, F, W, N, L, the prefilter's
//! rounding, the registers' fraction bits G, the register file's kind) drawn by the one
//! generator, `tofprobe_pixel::random` (its `Ranges::VERILATOR`), the register
//! width either drawn or `auto` (sized by `tofprobe_pixel::sizing::required_width` for the
//! whole TDC range and the sign probe ROM actually replayed), and sometimes sized for a
//! frame 16× shorter than the one simulated, so the wrapping accumulators really wrap.
//! Kept small (R ≤ 15, N ≤ 64) because every configuration is a Verilator build.

use tofprobe_pixel::PixelParams;
use tofprobe_pixel::random::{Ranges, random_params};
use tofprobe_pixel::sizing::required_width;
use tofprobe_rtlgen::golden::rom_image;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_scene::SplitMix64;

/// How the width of a drawn configuration was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WidthChoice {
    /// Drawn between one operand and operand + 11 bits.
    Drawn,
    /// `width = "auto"`: sized for the simulated frame.
    Auto,
    /// Sized for a frame 16× shorter than the one simulated: the registers wrap.
    AutoShortFrame,
}

/// One drawn configuration and the stimulus seed to run it with.
#[derive(Debug, Clone)]
pub struct RandomCase {
    pub params: PixelParams,
    pub seed: u64,
    pub width: WidthChoice,
}

/// The `i`-th case of the stream of `seed` (the same on every machine): the parameters
/// from the one generator with [`Ranges::VERILATOR`], then the width's choice and the
/// stimulus seed.
pub fn random_case(seed: u64, i: u64) -> RandomCase {
    let mut rng = SplitMix64::new(seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let mut p = random_params(&mut rng, &Ranges::VERILATOR);
    let width = match rng.below(3) {
        0 => WidthChoice::Drawn,
        1 => WidthChoice::Auto,
        _ => WidthChoice::AutoShortFrame,
    };
    if width != WidthChoice::Drawn {
        // Sized for G = F (a width that holds one operand and leaves registers keeping
        // G < F fraction bits F − G bits of headroom).
        let mut sized = p.clone();
        sized.register_frac_bits = None;
        if width == WidthChoice::AutoShortFrame {
            sized.frame_pulses = (p.frame_pulses / 16).max(1);
        }
        let rom = rom_image(&sized, &sign_probe_rom(&sized));
        p.width = required_width(&sized, 0, (1u32 << p.tdc_bits) - 1, rom.as_ref()).min(63);
    }
    let seed = rng.below(10_000) + 1;
    RandomCase {
        params: p,
        seed,
        width,
    }
}
