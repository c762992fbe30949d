//! The batched Monte Carlo's random words: [`LANES`] interleaved xoshiro256++ generators
//! per stream (struct of arrays, one step gives `LANES` words), the block's three streams,
//! and the per-ISA fill functions the kernel's copies call (crates/scene/src/batch.rs).

use crate::splitmix::SplitMix64;

#[cfg(target_arch = "x86_64")]
mod avx2;

/// Interleaved generators per stream: eight, one 512-bit vector per state word (with four,
/// LLVM packed two state words into one 512-bit register and the shuffles between them
/// lengthened every step's dependency chain: 3.2× slower a word on AVX-512).
pub(crate) const LANES: usize = 8;

/// Words per fill: one pass of the kernel (crates/scene/src/batch.rs). A fixed length, so
/// the fills' loops have a known trip count: with a slice of unknown length LLVM left the
/// eight lanes' step scalar (8.5× slower a word).
pub(crate) const PASS: usize = 512;

/// One fill's words of one stream.
pub(crate) type Words = [u64; PASS];

/// `LANES` xoshiro256++ generators side by side (state word j of lane l is `s[j][l]`).
#[derive(Debug, Clone)]
pub(crate) struct Lanes {
    s: [[u64; LANES]; 4],
}

impl Lanes {
    pub(crate) fn new(seeder: &mut SplitMix64) -> Lanes {
        let mut s = [[0u64; LANES]; 4];
        for l in 0..LANES {
            for w in &mut s {
                w[l] = seeder.next_u64();
            }
        }
        Lanes { s }
    }

    /// Fills `out` with the stream's next words.
    #[inline(always)]
    fn fill(&mut self, out: &mut Words) {
        let mut s = self.s;
        for chunk in out.chunks_exact_mut(LANES) {
            chunk.copy_from_slice(&step(&mut s));
        }
        self.s = s;
    }
}

/// One xoshiro256++ step of every lane: the lanes' outputs (whole-array operations, which
/// the compiler keeps in one vector register each).
#[inline(always)]
fn step(s: &mut [[u64; LANES]; 4]) -> [u64; LANES] {
    let [s0, s1, s2, s3] = *s;
    let out = std::array::from_fn(|l| rotl(s0[l].wrapping_add(s3[l]), 23).wrapping_add(s0[l]));
    let t: [u64; LANES] = std::array::from_fn(|l| s1[l] << 17);
    let s2: [u64; LANES] = std::array::from_fn(|l| s2[l] ^ s0[l]);
    let s3: [u64; LANES] = std::array::from_fn(|l| s3[l] ^ s1[l]);
    let s1: [u64; LANES] = std::array::from_fn(|l| s1[l] ^ s2[l]);
    let s0: [u64; LANES] = std::array::from_fn(|l| s0[l] ^ s3[l]);
    let s2: [u64; LANES] = std::array::from_fn(|l| s2[l] ^ t[l]);
    let s3: [u64; LANES] = std::array::from_fn(|l| rotl(s3[l], 45));
    *s = [s0, s1, s2, s3];
    out
}

/// x rotated left by k (one `vprolq` with AVX-512, two shifts and an or elsewhere).
#[inline(always)]
fn rotl(x: u64, k: u32) -> u64 {
    x.rotate_left(k)
}

/// A block's generators: the three lane sets (the scalar stream of the ziggurat's slow
/// path is apart, its address passed to the slow path: these stay in registers).
pub(crate) struct Streams {
    pub jitter: Lanes,
    pub signal: Lanes,
    pub background: Lanes,
}

impl Streams {
    /// Fills `j`, `s` and `b` with the jitter, signal and background streams' next words.
    /// The three lane sets step in one loop:
    /// each set's step depends on its last, so one set alone waits on that chain's
    /// latency, three interleaved overlap it.
    #[inline(always)]
    fn fill_all(&mut self, j: &mut Words, s: &mut Words, b: &mut Words) {
        let (mut sj, mut ss, mut sb) = (self.jitter.s, self.signal.s, self.background.s);
        for ((x, y), z) in j
            .chunks_exact_mut(LANES)
            .zip(s.chunks_exact_mut(LANES))
            .zip(b.chunks_exact_mut(LANES))
        {
            x.copy_from_slice(&step(&mut sj));
            y.copy_from_slice(&step(&mut ss));
            z.copy_from_slice(&step(&mut sb));
        }
        (self.jitter.s, self.signal.s, self.background.s) = (sj, ss, sb);
    }
}
/// How a copy of the kernel fills a pass's words from a lane set: a function of its own,
/// never inlined, so the compiler vectorises the lanes' step there whatever the
/// register pressure of the pass around it (inlined, it fell back to scalar code at some
/// call sites).
#[derive(Clone, Copy)]
pub(crate) struct Fill {
    /// The jitter stream alone ([`Lanes::fill`]).
    pub one: fn(&mut Lanes, &mut Words),
    /// The three streams ([`Streams::fill_all`]).
    pub all: fn(&mut Streams, &mut Words, &mut Words, &mut Words),
}

/// The AVX-512 copy's fills: built in that copy (a target-feature function is a
/// safe function pointer only where its features are enabled).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq")]
#[inline(never)]
pub(crate) fn one_avx512(l: &mut Lanes, j: &mut Words) {
    l.fill(j);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq")]
#[inline(never)]
pub(crate) fn all_avx512(g: &mut Streams, j: &mut Words, s: &mut Words, b: &mut Words) {
    g.fill_all(j, s, b);
}

/// The AVX2 copy's fills: built in that copy (a target-feature function is a
/// safe function pointer only where its features are enabled), by the explicit vector
/// step of [`avx2`] (LLVM leaves [`step`] scalar without a 64-bit vector rotate).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
pub(crate) fn one_avx2(l: &mut Lanes, j: &mut Words) {
    avx2::one(l, j);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
pub(crate) fn all_avx2(g: &mut Streams, j: &mut Words, s: &mut Words, b: &mut Words) {
    avx2::all(g, j, s, b);
}

/// The baseline copy's fills.
pub(crate) const FILL_BASELINE: Fill = Fill {
    one: one_baseline,
    all: all_baseline,
};

#[inline(never)]
pub(crate) fn one_baseline(l: &mut Lanes, j: &mut Words) {
    l.fill(j);
}

#[inline(never)]
pub(crate) fn all_baseline(g: &mut Streams, j: &mut Words, s: &mut Words, b: &mut Words) {
    g.fill_all(j, s, b);
}
