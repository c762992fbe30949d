//! SplitMix64 (Steele, Lea & Flood 2014): the one small, seedable generator of the workspace.
//! It seeds the Monte Carlo's per-block streams ([`crate::PhotonSource`]) and generates the
//! RTL test stimulus (tofprobe-rtlgen), whose manifest lets anyone re-derive it from the
//! seed: identical on every platform, no dependency.

/// The golden-ratio increment of the SplitMix64 state.
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// The SplitMix64 output of state `z` before its increment: a bijective 64-bit mix.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(GAMMA);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The SplitMix64 generator: `next_u64` advances the state by the golden-ratio increment
/// and returns its mix.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let out = mix(self.0);
        self.0 = self.0.wrapping_add(GAMMA);
        out
    }

    /// Uniform in 0..n (n ≥ 1; the modulo's bias, below 2^-40 for the small n drawn, is
    /// irrelevant to stimuli and parameters).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// True with probability `percent` %.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }

    /// The state: `SplitMix64::new(g.state())` continues `g`'s stream.
    pub fn state(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs for seed 0 of the reference C implementation
    /// (prng.di.unimi.it/splitmix64.c), the published test values.
    #[test]
    fn matches_the_reference_sequence() {
        let mut g = SplitMix64::new(0);
        let got: Vec<u64> = (0..3).map(|_| g.next_u64()).collect();
        assert_eq!(
            got,
            [
                0xe220_a839_7b1d_cdaf,
                0x6e78_9e6a_a1b9_65f4,
                0x06c4_5d18_8009_454f
            ]
        );
        assert_eq!(mix(0), 0xe220_a839_7b1d_cdaf);
    }
}
