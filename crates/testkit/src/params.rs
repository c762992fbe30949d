//! Random valid pixel parameters for the tests, every knob of `PixelParams` drawn here once:
//! both modes, A > 1, K < C, odd and tight widths (so the registers wrap often), any zoom,
//! short frames, registers keeping G ≤ F fraction bits, either rounding, every register
//! file. A tiny deterministic generator ([`Rng`]) makes a case reproducible from its seed;
//! [`strategy`] wraps it for proptest.

use proptest::prelude::*;
use tofprobe_dsp::RomImage;
use tofprobe_pixel::{Mode, PixelParams, RegisterFile, Rounding};

/// splitmix64: small, fast, good enough for stimuli.
#[derive(Debug, Clone)]
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in 0..n (n ≥ 1).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
    /// True with probability `percent` %.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
    /// Uniform index in 0..n (0 when n is 0).
    pub fn index(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
    /// A uniformly chosen element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.index(v.len())]
    }
}

/// Random valid parameters (see the module documentation). The draws before the latest
/// knobs are unchanged, so a seed keeps its case when a knob is added (draw new knobs last).
pub fn random_params(rng: &mut Rng) -> PixelParams {
    let haar = rng.chance(35);
    let tdc_bits = 1 + rng.below(8) as u32;
    let zoom = rng.below(1 << tdc_bits) as u32;
    let (mode, bins, haar_scales, frame_pulses) = if haar {
        let l = 1 + rng.below(4) as u32;
        (Mode::Haar, 1, rng.below(u64::from(l)) as u32, 1u64 << l)
    } else {
        (
            Mode::Fourier,
            1 + rng.below(5) as usize,
            0,
            1 + rng.below(12),
        )
    };
    let mut p = PixelParams {
        mode,
        bins,
        haar_scales,
        adders: 1,
        cycles_per_pulse: 1,
        tdc_bits,
        zoom,
        shift: rng.below(7) as u32,
        frac_bits: rng.below(7) as u32,
        width: 1,
        frame_pulses,
        rom_depth: 1 + rng.below(7) as usize,
        prefilter_rounding: Rounding::Floor,
        register_frac_bits: None,
        register_file: RegisterFile::default(),
    };
    let ops = p.ops_per_pulse() as u64;
    p.adders = 1 + rng.below(ops) as usize;
    p.cycles_per_pulse = p.slots() + rng.below(3) as usize;
    // Registers keeping G ≤ F fraction bits (G = F half the time), before the width so
    // the tight widths are tight for the narrower operand too.
    if mode == Mode::Fourier && rng.chance(50) {
        p.register_frac_bits = Some(rng.below(u64::from(p.frac_bits) + 1) as u32);
    }
    p.width = p.operand_bits() + rng.below(10) as u32;
    // Knobs added later, drawn last.
    if mode == Mode::Fourier && rng.chance(30) {
        p.prefilter_rounding = Rounding::Nearest;
    }
    if rng.chance(30) {
        p.register_file = RegisterFile::ClockGated;
    }
    // Latches after that, only over flops: a case's other fields stay what they were.
    if rng.chance(30) && p.register_file == RegisterFile::Flops {
        p.register_file = RegisterFile::Latch;
    }
    p.validate()
        .expect("random parameters are valid by construction");
    p
}

/// A ROM of random bits for `p` (Fourier; Haar gets an unused one-entry ROM).
pub fn random_rom(rng: &mut Rng, p: &PixelParams) -> RomImage {
    RomImage::from_fn(p.rom_depth, p.registers(), |_, _| rng.chance(50))
}

/// A random detection: none, or a code that may exceed the T-bit pins (they truncate).
pub fn random_detection(rng: &mut Rng, p: &PixelParams) -> Option<u32> {
    if rng.chance(35) {
        None
    } else {
        Some(rng.below(1 << (p.tdc_bits + 1)) as u32)
    }
}

/// [`random_params`] as a proptest strategy (the case shrinks by its seed).
pub fn strategy() -> impl Strategy<Value = PixelParams> {
    any::<u64>().prop_map(|seed| random_params(&mut Rng(seed)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generator covers every knob's values within a few hundred draws.
    #[test]
    fn every_knob_is_drawn() {
        let mut rng = Rng(7);
        let ps: Vec<PixelParams> = (0..400).map(|_| random_params(&mut rng)).collect();
        assert!(ps.iter().any(|p| p.mode == Mode::Haar));
        assert!(ps.iter().any(|p| p.prefilter_rounding == Rounding::Nearest));
        assert!(
            ps.iter()
                .any(|p| p.register_file == RegisterFile::ClockGated)
        );
        assert!(ps.iter().any(|p| p.register_file == RegisterFile::Latch));
        assert!(ps.iter().any(|p| p.register_frac_bits.is_some()));
        assert!(
            ps.iter()
                .any(|p| p.adders > 1 && p.cycles_per_pulse > p.slots())
        );
    }
}
