//! The batched Monte Carlo kernel: the same photon laws as the per-pulse reference
//! ([`crate::PhotonSource::fill_reference`]), drawn a block at a time in passes the
//! compiler vectorises.
//!
//! - **Random words**: [`LANES`] interleaved xoshiro256++ generators (struct of arrays, one
//!   step gives `LANES` words), one set per stream (jitter, signal Bernoulli, background).
//!   Pulse k of a block takes word k of each stream, whatever the request's length.
//! - **Jitter**: the ziggurat's branch-free fast pass over the block, the ≈ 0.7 % rejects
//!   finished exactly by the scalar slow path from a fourth, scalar stream
//!   ([`crate::ziggurat`]).
//! - **Depth**: a sine motion is evaluated as sin(θ_j + kΔ) = s_j cos kΔ + c_j sin kΔ over
//!   sub-blocks of [`crate::depths::SUB`] pulses from a table of (cos kΔ, sin kΔ) (no serial recurrence
//!   per pulse); other motions use the scene's own evaluation.
//! - **Laws**: signal with probability ρ_s at δ/c·2 + σ_I·z; background first arrival
//!   −ln(u)·W/ρ_b with u ∈ (0, 1] (52 bits), inside the window iff u > e^(−ρ_b); earliest in-window
//!   arrival wins; code = ⌊t / lsb⌋ (computed in code units, ≤ 1 ulp from the division).
//!   Every pulse draws its words whether or not it uses them: no per-pulse branches.

use rand::SeedableRng;
use rand::rngs::Xoshiro256PlusPlus;
use tofprobe_io::isa::Isa;

use crate::depths::Depths;
use crate::lanes::{FILL_BASELINE, Fill, LANES, Lanes, PASS, Streams, Words};
#[cfg(target_arch = "x86_64")]
use crate::lanes::{all_avx2, all_avx512, one_avx2, one_avx512};
use crate::ln::ln;
use crate::scene::Scene;
use crate::splitmix::SplitMix64;
use crate::ziggurat::{Tables, fast_pass, finish, tables};

/// One pulse of the Monte Carlo's output, in either form the kernels write: `Option<u32>`
/// (`None`: no detection) or the compact code (`u32`, [`NO_DETECTION`] for none, 4 bytes a
/// pulse: what the pixel's drivers read without conversion).
pub trait Slot: Copy + Default + Send + Sync + 'static {
    /// The pulse: a detection of `code` if `hit`, else none (branch-free).
    fn detection(hit: bool, code: u32) -> Self;
    /// The pulse as an `Option`.
    fn get(self) -> Option<u32>;
}

impl Slot for Option<u32> {
    #[inline(always)]
    fn detection(hit: bool, code: u32) -> Self {
        [None, Some(code)][usize::from(hit)]
    }
    #[inline(always)]
    fn get(self) -> Option<u32> {
        self
    }
}

impl Slot for u32 {
    #[inline(always)]
    fn detection(hit: bool, code: u32) -> Self {
        if hit { code } else { NO_DETECTION }
    }
    #[inline(always)]
    fn get(self) -> Option<u32> {
        (self != NO_DETECTION).then_some(self)
    }
}

/// The compact form's code of a pulse without a detection (TDC codes have at most 16
/// bits); the pixel's drivers read the same sentinel (`tofprobe_pixel::NO_DETECTION`).
pub const NO_DETECTION: u32 = u32::MAX;

/// The parameters of the kernel, in TDC code units (time / lsb).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Params {
    pub period_s: f64,
    /// Code units per mm of depth: 1 / (MM_PER_PS · lsb).
    pub code_per_mm: f64,
    /// Window start in code units.
    pub start: f64,
    /// Window length in code units.
    pub length: f64,
    /// σ_I in code units.
    pub sigma: f64,
    /// ρ_s as a threshold on 53-bit integers (≥ 2^53 when ρ_s = 1).
    pub signal_threshold: u64,
    pub signal_rate: f64,
    pub background_rate: f64,
    /// e^(−ρ_b).
    pub no_background: f64,
}

/// The block to generate: its streams' seed, its first pulse, and how many of its pulses.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Block {
    pub seed: u64,
    pub first_pulse: u64,
    pub n: usize,
}

/// Per-thread scratch of one block: the block's depths and one pass's buffers.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    depth: Vec<f64>,
    pass: Box<PassBuffers>,
}

/// The buffers of one pass of [`PASS`] pulses (≈ 66 bytes a pulse, 33 kB: about L1), each
/// a whole pass long; a block's last, shorter pass uses their first pulses.
#[derive(Debug)]
struct PassBuffers {
    z: [f64; PASS],
    /// The jitter, signal and background streams' words.
    words: Words,
    signal_words: Words,
    background_words: Words,
    flags: [u64; PASS],
    /// Each pulse's ziggurat layer edges.
    edges: [[f64; 2]; PASS],
    rejects: Vec<u32>,
    /// The earliest in-window arrival of each pulse, code units (∞ when none).
    best: [f64; PASS],
    bg: Gather,
}

/// The background's gathered pulses ([`background`]): flags, then the indices and values
/// of the pulses with a photon in the window.
#[derive(Debug)]
struct Gather {
    flags: [u8; PASS],
    index: [u32; PASS],
    value: [f64; PASS],
}

impl Default for Gather {
    fn default() -> Self {
        Gather {
            flags: [0; PASS],
            index: [0; PASS],
            value: [0.0; PASS],
        }
    }
}

impl Default for PassBuffers {
    fn default() -> Self {
        PassBuffers {
            z: [0.0; PASS],
            words: [0; PASS],
            signal_words: [0; PASS],
            background_words: [0; PASS],
            flags: [0; PASS],
            edges: [[0.0; 2]; PASS],
            rejects: Vec::new(),
            best: [0.0; PASS],
            bg: Gather::default(),
        }
    }
}

#[cfg(test)]
mod mask_tests {
    /// The multiply's mask against the flag-by-flag one, on every length and random flags
    /// (a wrong constant, 0x8040…0201, fails here).
    #[test]
    fn flag_mask_is_the_flags_bit_by_bit() {
        let mut g = crate::SplitMix64::new(3);
        for len in 0..=64 {
            for _ in 0..50 {
                let r = g.next_u64();
                let flags: Vec<u8> = (0..len).map(|k| ((r >> k) & 1) as u8).collect();
                let naive = flags
                    .iter()
                    .enumerate()
                    .fold(0u64, |m, (k, &f)| m | (u64::from(f) << k));
                assert_eq!(super::flag_mask(&flags), naive, "{flags:?}");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MotionConfig, SceneConfig, SensorConfig};

    /// Every copy the CPU runs (AVX-512, AVX2) and the scalar copy
    /// give the same codes, detections and background wins, bit for bit, on a moving
    /// scene at mixed rates (a reordered or fused operation would move some codes).
    #[test]
    fn every_copy_of_the_kernel_is_bit_identical() {
        let scene = Scene::new(&SceneConfig {
            depth_mm: 30.0,
            motions: vec![MotionConfig::Sine {
                amplitude_mm: 5.0,
                frequency_hz: 4500.0,
                phase_deg: 10.0,
            }],
        })
        .expect("valid");
        let sensor = SensorConfig {
            laser_rate_hz: 10e6,
            jitter_ps: 50.0,
            tdc_lsb_ps: 5.0,
            window_start_ps: 0.0,
            window_length_ps: 400.0,
            signal_rate: 0.7,
            background_rate: 0.4,
        };
        let lsb = sensor.tdc_lsb_ps;
        let p = Params {
            period_s: 1e-7,
            code_per_mm: 1.0 / (crate::MM_PER_PS * lsb),
            start: 0.0,
            length: 400.0 / lsb,
            sigma: 50.0 / lsb,
            signal_threshold: (0.7 * (1u64 << 53) as f64) as u64,
            signal_rate: 0.7,
            background_rate: 0.4,
            no_background: (-0.4f64).exp(),
        };
        let depths = Depths::new(&scene, p.period_s);
        for block in 0..8u64 {
            let (mut a, mut b) = (vec![None; 4096], vec![None; 4096]);
            let (mut sa, mut sb) = (Scratch::default(), Scratch::default());
            let blk = Block {
                seed: block,
                first_pulse: block * 4096,
                n: 4096,
            };
            let cb = generate_on(
                Isa::Scalar,
                &p,
                &scene,
                &depths,
                blk,
                &mut sb,
                (0, 79, &mut b),
            );
            for isa in Isa::vector_paths_to_test() {
                let (mut c, mut sc) = (vec![None; 4096], Scratch::default());
                let cc = generate_on(isa, &p, &scene, &depths, blk, &mut sc, (0, 79, &mut c));
                assert_eq!((cc, &c), (cb, &b), "{} copy, block {block}", isa.name());
            }
            let ca = generate(&p, &scene, &depths, blk, &mut sa, (0, 79, &mut a));
            assert_eq!((ca, &a), (cb, &b), "the current ISA's copy, block {block}");
            assert!(ca.0 > 3000 && ca.1 > 500, "block {block}: {ca:?}");
        }
    }
}

/// Generates pulses 0 .. n of a block (n ≤ the block length), in passes of [`PASS`] pulses,
/// and writes pulses `offset .. offset + out.len()` of them as codes into `out` (returns
/// its detections and background wins), on the workspace's ISA
/// ([`tofprobe_io::isa::Isa::current`]).
pub(crate) fn generate<O: Slot>(
    p: &Params,
    scene: &Scene,
    depths: &Depths,
    block: Block,
    sc: &mut Scratch,
    out: (usize, u32, &mut [O]),
) -> (u64, u64) {
    generate_on(Isa::current(), p, scene, depths, block, sc, out)
}

/// [`generate`] on `isa`: the AVX-512 or AVX2 copy of the kernel where asked for and the
/// CPU has it (the same IEEE operations, no fused multiply-adds: bit-identical to the
/// scalar copy), the scalar copy otherwise.
pub(crate) fn generate_on<O: Slot>(
    isa: Isa,
    p: &Params,
    scene: &Scene,
    depths: &Depths,
    block: Block,
    sc: &mut Scratch,
    (offset, last, out): (usize, u32, &mut [O]),
) -> (u64, u64) {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && isa.available() {
        // SAFETY: the CPU has AVX-512 F, VL and DQ (`available`, checked above), the one
        // requirement of `generate_avx512`.
        #[allow(unsafe_code)]
        unsafe {
            return generate_avx512(p, scene, depths, block, sc, (offset, last, out));
        }
    }
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx2 && isa.available() {
        // SAFETY: the CPU has AVX2 (checked on the line above), the one requirement of
        // `generate_avx2`; the workspace's second allowed unsafe call (see Cargo.toml).
        #[allow(unsafe_code)]
        unsafe {
            return generate_avx2(p, scene, depths, block, sc, (offset, last, out));
        }
    }
    let _ = isa;
    generate_body(
        p,
        scene,
        depths,
        block,
        sc,
        (offset, last, out),
        FILL_BASELINE,
    )
}

/// [`generate_body`] compiled for AVX-512 (64-bit rotates and integer-to-float
/// conversions in vectors).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq")]
fn generate_avx512<O: Slot>(
    p: &Params,
    scene: &Scene,
    depths: &Depths,
    block: Block,
    sc: &mut Scratch,
    (offset, last, out): (usize, u32, &mut [O]),
) -> (u64, u64) {
    generate_body(
        p,
        scene,
        depths,
        block,
        sc,
        (offset, last, out),
        Fill {
            one: one_avx512,
            all: all_avx512,
        },
    )
}

/// [`generate_body`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn generate_avx2<O: Slot>(
    p: &Params,
    scene: &Scene,
    depths: &Depths,
    block: Block,
    sc: &mut Scratch,
    (offset, last, out): (usize, u32, &mut [O]),
) -> (u64, u64) {
    generate_body(
        p,
        scene,
        depths,
        block,
        sc,
        (offset, last, out),
        Fill {
            one: one_avx2,
            all: all_avx2,
        },
    )
}

#[inline(always)]
fn generate_body<O: Slot>(
    p: &Params,
    scene: &Scene,
    depths: &Depths,
    block: Block,
    sc: &mut Scratch,
    (offset, last, out): (usize, u32, &mut [O]),
    fill: Fill,
) -> (u64, u64) {
    let Block {
        seed: block_seed,
        first_pulse,
        n,
    } = block;
    let padded = n.div_ceil(LANES) * LANES;
    sc.depth.resize(padded, 0.0);
    depths.fill(scene, first_pulse, p.period_s, &mut sc.depth[..n]);
    let b = &mut sc.pass;
    let mut seeder = SplitMix64::new(block_seed);
    let mut g = Streams {
        jitter: Lanes::new(&mut seeder),
        signal: Lanes::new(&mut seeder),
        background: Lanes::new(&mut seeder),
    };
    let mut slow = Xoshiro256PlusPlus::seed_from_u64(seeder.next_u64());
    let mut counts = (0, 0);
    // The block in passes of PASS pulses, each pass's buffers in L1: pulse k still takes
    // word k of each stream and the rejects are finished in pulse order, so the stream is
    // the one a single pass over the whole block draws.
    for first in (0..padded).step_by(PASS) {
        let m = (padded - first).min(PASS);
        // Pulses first + lo .. first + hi of this pass are the request's.
        let lo = offset.saturating_sub(first).min(m);
        let hi = n.saturating_sub(first).min(m).max(lo);
        let o = (first + lo).saturating_sub(offset);
        let c = pass(
            p,
            (&mut g, &mut slow, fill),
            b,
            &sc.depth[first..first + m],
            (lo, hi),
            (last, &mut out[o..o + hi - lo]),
        );
        counts.0 += c.0;
        counts.1 += c.1;
    }
    counts
}

/// One pass of `depth.len()` pulses (a multiple of [`LANES`]): every stream advanced by
/// that many words, the rejects finished, and pulses `lo .. hi` of the pass written to `out`
/// (returns their detections and background wins).
#[inline(always)]
fn pass<O: Slot>(
    p: &Params,
    (g, slow, fill): (&mut Streams, &mut Xoshiro256PlusPlus, Fill),
    b: &mut PassBuffers,
    depth: &[f64],
    (lo, hi): (usize, usize),
    (last, out): (u32, &mut [O]),
) -> (u64, u64) {
    let m = depth.len();
    let t: &Tables = tables();
    let bern = p.signal_rate < 1.0;
    let bg = p.background_rate > 0.0;
    // Whole passes of words are drawn (the fills' fixed length), also for a block's last,
    // shorter pass: its generators are not used after it.
    if bern || bg {
        std::hint::black_box(fill.all)(
            g,
            &mut b.words,
            &mut b.signal_words,
            &mut b.background_words,
        );
    } else {
        std::hint::black_box(fill.one)(&mut g.jitter, &mut b.words);
    }
    let (words, z) = (&b.words[..m], &mut b.z[..m]);
    let (sw, bw) = (&b.signal_words[..m], &b.background_words[..m]);
    fast_pass(
        t,
        words,
        z,
        (&mut b.flags[..m], &mut b.edges[..m]),
        &mut b.rejects,
    );
    for &k in &b.rejects {
        z[k as usize] = finish(t, words[k as usize], slow);
    }
    if lo == hi {
        // A pass before the request's start: its streams advanced, nothing is computed.
        return (0, 0);
    }
    // Signal: t = δ·code_per_mm + σ z − start, kept when inside [0, length) and (ρ_s < 1)
    // the pulse has its signal photon. Each loop writes a buffer it does not read: a
    // select between a new value and the old one of the same cell becomes a masked store
    // (`vmaskmovpd`), which is microcoded and slow on AMD's AVX2 cores (it was a third of
    // the AVX2 kernel at (ρ_s, ρ_b) = (0.3, 0.3)).
    let (cpm, sigma, start, len) = (p.code_per_mm, p.sigma, p.start, p.length);
    let best = &mut b.best[..m];
    if bern {
        // Both sides < 2^53: the signed compare (the one AVX2 has) is exact.
        let thr = p.signal_threshold.min(1 << 53) as i64;
        for (((b, &d), &z), &w) in best.iter_mut().zip(depth).zip(z.iter()).zip(sw.iter()) {
            let x = d * cpm + sigma * z - start;
            let keep = x >= 0.0 && x < len && ((w >> 11) as i64) < thr;
            *b = if keep { x } else { f64::INFINITY };
        }
    } else {
        for ((b, &d), &z) in best.iter_mut().zip(depth).zip(z.iter()) {
            let x = d * cpm + sigma * z - start;
            *b = if x >= 0.0 && x < len {
                x
            } else {
                f64::INFINITY
            };
        }
    }
    let mut wins = 0;
    if bg {
        wins = background(p, &bw[lo..hi], &mut best[lo..hi], &mut b.bg);
    }
    let detections = codes(&best[lo..hi], last, out);
    (detections, wins)
}

/// The background's first arrivals of pulses `bw.len()` (their words `bw`): each pulse's
/// arrival in `best` becomes the background's where that is in the window and earlier
/// (returns how many were). Only the ≈ 1 − e^(−ρ_b) of pulses with a background photon in
/// the window need the logarithm: they are gathered (a vector compare, then the set bits
/// of its mask visited), their −ln(u)·W/ρ_b computed densely in vectors, and scattered
/// back; every pulse's value is the one the direct loop computes, in half its time at
/// ρ_b = 0.3 (the direct loop's logarithm of every pulse was half of the AVX2 kernel).
#[inline(always)]
fn background(p: &Params, bw: &[u64], best: &mut [f64], g: &mut Gather) -> u64 {
    // u ∈ (0, 1] on the 2^−52 grid, by the exponent trick (no integer-to-float
    // conversion, which AVX2 lacks for 64-bit lanes).
    let uniform = |w: u64| 2.0 - f64::from_bits((w >> 12) | 0x3FF0_0000_0000_0000);
    let scale = p.length / p.background_rate;
    let nb = p.no_background;
    let n = bw.len();
    for (f, &w) in g.flags[..n].iter_mut().zip(bw) {
        *f = u8::from(uniform(w) > nb);
    }
    let mut k = 0;
    for (j, w) in g.flags[..n].chunks(64).enumerate() {
        let mut mask = flag_mask(w);
        while mask != 0 {
            let i = 64 * j + mask.trailing_zeros() as usize;
            (g.index[k], g.value[k]) = (i as u32, uniform(bw[i]));
            k += 1;
            mask &= mask - 1;
        }
    }
    for v in &mut g.value[..k] {
        *v = -ln(*v) * scale;
    }
    let mut wins = 0;
    for (&i, &tb) in g.index[..k].iter().zip(&g.value[..k]) {
        let b = &mut best[i as usize];
        let win = tb < *b;
        wins += u64::from(win);
        *b = if win { tb } else { *b };
    }
    wins
}

/// Bit k set iff `flags[k]` is 1 (flags 0 or 1, at most 64): eight flags at a time, by
/// one multiply that gathers the low bit of each byte of a word into its top byte (the
/// bytes' bits land at distinct places and never carry). A fold of 64 shifted flags was a
/// zero-extension, compare and mask per flag on AVX2, a branch-free compaction (index
/// written, count advanced by the flag) a serial add per pulse: each ≈ 12 % of the kernel.
#[inline(always)]
fn flag_mask(flags: &[u8]) -> u64 {
    debug_assert!(flags.len() <= 64 && flags.iter().all(|&f| f <= 1));
    let pack = |b: [u8; 8]| u64::from_le_bytes(b).wrapping_mul(0x0102_0408_1020_4080) >> 56;
    let mut mask = 0u64;
    let mut words = flags.chunks_exact(8);
    for (i, c) in (&mut words).enumerate() {
        mask |= pack(c.try_into().expect("8 flags")) << (8 * i);
    }
    let rest = words.remainder();
    if !rest.is_empty() {
        let mut b = [0u8; 8];
        for (d, &f) in b.iter_mut().zip(rest) {
            *d = f;
        }
        mask |= pack(b) << (flags.len() - rest.len());
    }
    mask
}

/// Writes `best` as TDC codes into `out` (no detection outside the window); returns the
/// detections.
#[inline(always)]
fn codes<O: Slot>(best: &[f64], last: u32, out: &mut [O]) -> u64 {
    let mut detections = 0u64;
    let last_f = f64::from(last);
    // 2^52: a float in [0, 2^32) truncated and added to it holds its integer value in the
    // low mantissa bits (a vector conversion where `as u32`'s saturating one is not).
    const MAGIC: f64 = 4_503_599_627_370_496.0;
    for (o, &b) in out.iter_mut().zip(best) {
        // b ∈ [0, length) when hit, ∞ otherwise; the clamp is a float min (an integer min
        // compiles to a branch that a 50 % detection rate would mispredict).
        let hit = b < f64::INFINITY;
        let c = (b.min(last_f).trunc() + MAGIC).to_bits() as u32;
        *o = O::detection(hit, c);
        detections += u64::from(hit);
    }
    detections
}
