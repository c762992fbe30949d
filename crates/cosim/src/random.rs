//! Random valid configurations for `tofprobe cosim --random N --seed S` and the CI's eight:
//! both modes and every knob of the pixel (B or U, A, C, T, Z, S, F, W, N, L, the prefilter's
//! rounding, the registers' fraction bits G, the register file's kind), the register
//! width either drawn or `auto` (sized by `tofprobe_pixel::sizing::required_width` for the
//! whole TDC range and the sign probe ROM actually replayed), and sometimes sized for a
//! frame 16× shorter than the one simulated, so the wrapping accumulators really wrap.
//! Kept small (R ≤ 15, N ≤ 64) because every configuration is a Verilator build.

use tofprobe_pixel::sizing::required_width;
use tofprobe_pixel::{Mode, PixelParams, RegisterFile, Rounding};
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

fn pick(rng: &mut SplitMix64, lo: u64, hi_incl: u64) -> u64 {
    lo + rng.next_u64() % (hi_incl - lo + 1)
}

/// The `i`-th case of the stream of `seed` (the same on every machine).
pub fn random_case(seed: u64, i: u64) -> RandomCase {
    let mut rng = SplitMix64::new(seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let haar = rng.next_u64() & 1 == 1;
    let t = pick(&mut rng, 1, 9) as u32;
    let ln = pick(&mut rng, 4, 6) as u32;
    let mut p = PixelParams {
        mode: if haar { Mode::Haar } else { Mode::Fourier },
        bins: pick(&mut rng, 1, 7) as usize,
        haar_scales: pick(&mut rng, 0, 2) as u32,
        adders: 1,
        cycles_per_pulse: 1,
        tdc_bits: t,
        zoom: pick(&mut rng, 0, (1u64 << t) - 1) as u32,
        shift: pick(&mut rng, 0, 8) as u32,
        frac_bits: pick(&mut rng, 0, 5) as u32,
        width: 8,
        frame_pulses: 1 << ln,
        rom_depth: pick(&mut rng, 1, 48) as usize,
        prefilter_rounding: Rounding::Floor,
        register_frac_bits: None,
        register_file: Default::default(),
    };
    p.adders = (pick(&mut rng, 1, 4) as usize).min(p.ops_per_pulse());
    p.cycles_per_pulse = p.slots() + pick(&mut rng, 0, 2) as usize;
    let width = match rng.next_u64() % 3 {
        0 => WidthChoice::Drawn,
        1 => WidthChoice::Auto,
        _ => WidthChoice::AutoShortFrame,
    };
    p.width = match width {
        WidthChoice::Drawn => (p.operand_bits() + pick(&mut rng, 0, 11) as u32).min(63),
        WidthChoice::Auto | WidthChoice::AutoShortFrame => {
            let mut sized = p.clone();
            if width == WidthChoice::AutoShortFrame {
                sized.frame_pulses = (p.frame_pulses / 16).max(1);
            }
            let rom = rom_image(&sized, &sign_probe_rom(&sized));
            required_width(&sized, 0, (1u32 << t) - 1, rom.as_ref()).min(63)
        }
    };
    let seed = rng.next_u64() % 10_000 + 1;
    // Drawn last, so every other field of a case is what it was before the knob existed.
    if p.mode == Mode::Fourier && rng.next_u64() & 1 == 1 {
        p.prefilter_rounding = Rounding::Nearest;
    }
    // G after that, for the same reason: the registers keep G of the F fraction bits
    // (0..=F, G = F left out). The width stays the one drawn or sized for G = F, which
    // still holds one operand and leaves the registers F − G bits of headroom.
    if p.mode == Mode::Fourier && p.frac_bits > 0 {
        let g = pick(&mut rng, 0, u64::from(p.frac_bits)) as u32;
        p.register_frac_bits = (g < p.frac_bits).then_some(g);
    }
    // The register file's kind is drawn after every other field (keep it last when a knob
    // is added), so the cases drawn before it existed keep their other fields.
    if rng.next_u64() & 1 == 1 {
        p.register_file = RegisterFile::ClockGated;
    }
    // Latches, drawn after that (and only over flops), so a case drawn before they existed
    // keeps every field, its kind included, or turns from flops into latches.
    if rng.next_u64() & 1 == 1 && p.register_file == RegisterFile::Flops {
        p.register_file = RegisterFile::Latch;
    }
    RandomCase {
        params: p,
        seed,
        width,
    }
}
