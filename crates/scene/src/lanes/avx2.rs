//! The AVX2 copy's fills written with explicit vector operations. AVX2 has no 64-bit
//! rotate, and LLVM's cost model then leaves the eight lanes' xoshiro256++ step scalar (the
//! fills were 43 % of the AVX2 kernel at (ρ_s, ρ_b) = (0.3, 0.3)); here each state word is
//! two 256-bit vectors of four lanes and a rotate is two shifts and an or. The same
//! integer operations as [`super::step`], so the same words bit for bit
//! (`batch::tests::every_copy_of_the_kernel_is_bit_identical` runs this copy).

use std::arch::x86_64::{
    __m256i, _mm256_add_epi64, _mm256_extract_epi64, _mm256_or_si256, _mm256_set_epi64x,
    _mm256_slli_epi64, _mm256_srli_epi64, _mm256_xor_si256,
};

use super::{LANES, Lanes, Streams, Words};

// Two vectors of four lanes a state word.
const _: () = assert!(LANES == 8);

/// A lane set's state: word j, lanes 0–3 and 4–7.
type State = [[__m256i; 2]; 4];

/// Four words as a vector (one load once LLVM merges the four).
#[target_feature(enable = "avx2")]
fn load(a: &[u64]) -> __m256i {
    _mm256_set_epi64x(a[3] as i64, a[2] as i64, a[1] as i64, a[0] as i64)
}

/// A vector's four words into `a` (one store once LLVM merges the four).
#[target_feature(enable = "avx2")]
fn store(v: __m256i, a: &mut [u64]) {
    a[0] = _mm256_extract_epi64::<0>(v) as u64;
    a[1] = _mm256_extract_epi64::<1>(v) as u64;
    a[2] = _mm256_extract_epi64::<2>(v) as u64;
    a[3] = _mm256_extract_epi64::<3>(v) as u64;
}

#[target_feature(enable = "avx2")]
fn state(l: &Lanes) -> State {
    std::array::from_fn(|w| [load(&l.s[w][..4]), load(&l.s[w][4..])])
}

#[target_feature(enable = "avx2")]
fn put(s: &State, l: &mut Lanes) {
    for (w, v) in s.iter().enumerate() {
        store(v[0], &mut l.s[w][..4]);
        store(v[1], &mut l.s[w][4..]);
    }
}

/// x rotated left by `L` (`R` = 64 − `L`).
#[target_feature(enable = "avx2")]
fn rotl<const L: i32, const R: i32>(x: __m256i) -> __m256i {
    _mm256_or_si256(_mm256_slli_epi64::<L>(x), _mm256_srli_epi64::<R>(x))
}

/// One step of all eight lanes, their outputs into `out` (eight words).
#[target_feature(enable = "avx2")]
fn step(s: &mut State, out: &mut [u64]) {
    for h in 0..2 {
        let (s0, s1, s2, s3) = (s[0][h], s[1][h], s[2][h], s[3][h]);
        let r = _mm256_add_epi64(rotl::<23, 41>(_mm256_add_epi64(s0, s3)), s0);
        store(r, &mut out[4 * h..4 * h + 4]);
        let t = _mm256_slli_epi64::<17>(s1);
        let s2 = _mm256_xor_si256(s2, s0);
        let s3 = _mm256_xor_si256(s3, s1);
        s[1][h] = _mm256_xor_si256(s1, s2);
        s[0][h] = _mm256_xor_si256(s0, s3);
        s[2][h] = _mm256_xor_si256(s2, t);
        s[3][h] = rotl::<45, 19>(s3);
    }
}

/// The jitter stream alone ([`super::Fill::one`]).
#[target_feature(enable = "avx2")]
pub(super) fn one(l: &mut Lanes, j: &mut Words) {
    let mut s = state(l);
    for c in j.chunks_exact_mut(LANES) {
        step(&mut s, c);
    }
    put(&s, l);
}

/// The three streams ([`super::Fill::all`]), one after the other: a lane set's state is
/// eight 256-bit registers, so three stepped in one loop (24) would not fit AVX2's sixteen
/// and spilled every step.
#[target_feature(enable = "avx2")]
pub(super) fn all(g: &mut Streams, j: &mut Words, s: &mut Words, b: &mut Words) {
    one(&mut g.jitter, j);
    one(&mut g.signal, s);
    one(&mut g.background, b);
}
