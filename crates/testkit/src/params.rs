//! Random valid pixel parameters for the tests: `tofprobe_pixel::random`'s one generator
//! with the tests' ranges (every knob of `PixelParams` is drawn there, once), on the
//! workspace's one SplitMix64 (`tofprobe_scene`). [`Rng`] holds the generator's state, so a
//! case is reproducible from its seed (`Rng(seed)`); [`strategy`] wraps it for proptest.

use proptest::prelude::*;
use tofprobe_dsp::RomImage;
use tofprobe_pixel::PixelParams;
use tofprobe_pixel::random::Ranges;
use tofprobe_scene::SplitMix64;

/// The tests' generator: `tofprobe_scene::SplitMix64` seeded with (and holding) `.0`.
#[derive(Debug, Clone)]
pub struct Rng(pub u64);

impl Rng {
    /// Runs `f` on the SplitMix64 at this state, keeping where it stopped.
    fn with<T>(&mut self, f: impl FnOnce(&mut SplitMix64) -> T) -> T {
        let mut g = SplitMix64::new(self.0);
        let out = f(&mut g);
        self.0 = g.state();
        out
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.with(SplitMix64::next_u64)
    }
    /// Uniform in 0..n (n ≥ 1).
    pub fn below(&mut self, n: u64) -> u64 {
        self.with(|g| g.below(n))
    }
    /// True with probability `percent` %.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.with(|g| g.chance(percent))
    }
    /// Uniform index in 0..n (0 when n is 0).
    pub fn index(&mut self, n: usize) -> usize {
        self.below(n.max(1) as u64) as usize
    }
    /// A uniformly chosen element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.index(v.len())]
    }
}

/// Random valid parameters ([`Ranges::TESTS`]; see `tofprobe_pixel::random`).
pub fn random_params(rng: &mut Rng) -> PixelParams {
    rng.with(|g| tofprobe_pixel::random::random_params(g, &Ranges::TESTS))
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

    /// `Rng` is SplitMix64's stream: the published first outputs for seed 0
    /// (prng.di.unimi.it/splitmix64.c), and a seed's parameters are those of the one
    /// generator on that stream.
    #[test]
    fn the_stream_is_splitmix64s_and_the_parameters_the_one_generators() {
        let mut r = Rng(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        let mut g = SplitMix64::new(99);
        let want = tofprobe_pixel::random::random_params(&mut g, &Ranges::TESTS);
        let mut r = Rng(99);
        assert_eq!(random_params(&mut r), want);
        assert_eq!(r.0, g.state());
    }
}
