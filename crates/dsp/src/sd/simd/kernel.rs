//! The inner loop of the full-band probe kernel ([`super::pairs`]): one anchor span of a
//! group of `L` lanes, in three copies of one body chosen at run time ([`super::Isa`]):
//! the x86-64 baseline (SSE2, [`Isa::Scalar`]), AVX2, and AVX-512 (with FMA; f64 lanes only: f32 lanes on
//! the AVX-512 path run the AVX2 copy, faster for them, see `LANES_F32_AVX512`).
//!
//! Lane layout: lanes 0 .. L/2 are the I streams of the group's bins, lanes L/2 .. L their
//! Q streams, so the rotation's partner of lane l is lane l ^ L/2: at every width that is
//! another register, never a shuffle within one.
//!
//! Determinism: every copy performs, per lane, the scalar reference's operations in its
//! order. The rewrites are exact ones (see the `pairs` module docs), and the AVX-512 copy
//! adds one more: where the others add ±b₂ (b₂ with its sign bit flipped by the
//! quantiser's decision) it computes fma(σ, b₂, v) with σ = ±1.0 (the same sign flip
//! applied to 1.0), and likewise acc ± x as fma(σ, x, acc). σ·b₂ is exact, so the fused
//! operation rounds the exact v ± b₂ once, exactly as the add does, signed zeros included:
//! the same bits, in two operations fewer per step (one instead of a sign flip and an
//! add, for every state and the accumulator). No other product is fused: `mul_add`
//! appears only with σ as a factor, and rustc never contracts a·b + c on its own. The
//! tests (crates/dsp/tests/it/fullband_isa.rs) run every copy this CPU supports against
//! the baseline copy and against the naive scalar reference.

// The lane loops index several same-length arrays in lockstep (`x[l]`, `x[l ^ h]`).
#![allow(clippy::needless_range_loop)]

use super::{Isa, Lane};

/// The loop state a span reads and leaves: states, rotators and accumulators.
pub(crate) struct Span<'a, T: Lane, const L: usize, const N: usize> {
    pub s: &'a mut [[T; L]; N],
    pub rot: &'a mut [T; L],
    pub acc: &'a mut [T; L],
}

/// The constants of a span: the rotation (cos d; −sin d on I lanes, +sin d on Q lanes)
/// and the CIFB coefficients (super-diagonal, input and feedback per state).
#[derive(Clone, Copy)]
pub(crate) struct Consts<'a, T: Lane, const L: usize, const N: usize> {
    pub cd: &'a [T; L],
    pub sdm: &'a [T; L],
    pub sup: &'a [T; N],
    pub b1: &'a [T; N],
    pub b2: &'a [T; N],
}

/// [`step_span`] on `path`: a wider copy where asked for and the CPU has its features
/// (checked here, so no caller can run it on a CPU without), else the baseline's. The
/// workspace's only unsafe code in this crate (see the root Cargo.toml): entering a
/// `#[target_feature]` function.
#[allow(unsafe_code)]
#[inline(always)]
pub(crate) fn step_on<
    T: Lane,
    const L: usize,
    const N: usize,
    const RES: bool,
    const TRACE: bool,
>(
    path: Isa,
    span: Span<'_, T, L, N>,
    k: Consts<'_, T, L, N>,
    aw: &[T],
    x: &[T],
    trace: &mut [u32],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if path == Isa::Avx512 && T::AVX512 && Isa::Avx512.available() {
            // SAFETY: the CPU has AVX-512 F and VL, AVX2 and FMA, checked on the line above.
            unsafe { step_span_avx512::<T, L, N, RES, TRACE>(span, k, aw, x, trace) };
            return;
        }
        let wide = path == Isa::Avx2 || path == Isa::Avx512;
        if wide && Isa::Avx2.available() {
            // SAFETY: the CPU has AVX2, checked on the line above.
            unsafe { step_span_avx2::<T, L, N, RES, TRACE>(span, k, aw, x, trace) };
            return;
        }
    }
    let _ = path;
    step_span::<T, L, N, RES, TRACE, false>(span, k, aw, x, trace)
}

/// [`step_span`] compiled for AVX2 (not FMA: products and sums round as on the baseline).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn step_span_avx2<T: Lane, const L: usize, const N: usize, const RES: bool, const TRACE: bool>(
    span: Span<'_, T, L, N>,
    k: Consts<'_, T, L, N>,
    aw: &[T],
    x: &[T],
    trace: &mut [u32],
) {
    step_span::<T, L, N, RES, TRACE, false>(span, k, aw, x, trace)
}

/// [`step_span`] compiled for AVX-512 (thirty-two vector registers: the group's states,
/// rotators, accumulators and coefficients all stay in registers) with the exact σ-FMA
/// (see the module docs).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
fn step_span_avx512<T: Lane, const L: usize, const N: usize, const RES: bool, const TRACE: bool>(
    span: Span<'_, T, L, N>,
    k: Consts<'_, T, L, N>,
    aw: &[T],
    x: &[T],
    trace: &mut [u32],
) {
    step_span::<T, L, N, RES, TRACE, true>(span, k, aw, x, trace)
}

/// One anchor span of the interleaved loop (see the `pairs` module docs for why each
/// rewrite of the reference's arithmetic is exact; `FMA`: the σ-FMA of the module docs).
/// Conditions are compile-time, so each lane loop is straight-line SIMD.
#[inline(always)]
fn step_span<
    T: Lane,
    const L: usize,
    const N: usize,
    const RES: bool,
    const TRACE: bool,
    const FMA: bool,
>(
    span: Span<'_, T, L, N>,
    k: Consts<'_, T, L, N>,
    aw: &[T],
    x: &[T],
    trace: &mut [u32],
) {
    const { assert!(L.is_power_of_two() && L >= 2 && L <= 32) };
    let h = L / 2;
    let mut st = *span.s;
    let mut r = *span.rot;
    let mut ac = *span.acc;
    let b2b = k.b2.map(T::bits);
    let one = T::of(1.0).bits();
    for (t, (&a, &xv)) in aw.iter().zip(x).enumerate() {
        let mut u = [T::default(); L];
        for l in 0..L {
            u[l] = a * r[l];
        }
        let mut nr = [T::default(); L];
        for l in 0..L {
            nr[l] = r[l] * k.cd[l] + r[l ^ h] * k.sdm[l];
        }
        r = nr;
        // Sign of y = u + x[N−1]: set ⇔ the quantiser outputs −1.
        let mut sm = [T::Bits::default(); L];
        for l in 0..L {
            sm[l] = (u[l] + st[N - 1][l]).bits() & T::SIGN;
        }
        if TRACE {
            let mut w = 0u32;
            for (l, m) in sm.iter().enumerate() {
                w |= u32::from(*m == T::Bits::default()) << l;
            }
            trace[t] = w;
        }
        // σ = ±1.0, the quantiser's output (FMA copy only).
        let mut sg = [T::default(); L];
        if FMA {
            for l in 0..L {
                sg[l] = T::from_bits(one ^ sm[l]);
            }
        }
        let mut ns = [[T::default(); L]; N];
        for row in 0..N {
            for l in 0..L {
                let mut v = if row > 0 {
                    st[row - 1][l] + st[row][l]
                } else {
                    st[row][l]
                };
                if RES && row + 1 < N {
                    // Adding 0·x where a row has no resonator is exact (states are never −0).
                    v = v + k.sup[row] * st[row + 1][l];
                }
                v = v + k.b1[row] * u[l];
                ns[row][l] = if FMA {
                    sg[l].mul_add(k.b2[row], v)
                } else {
                    v + T::from_bits(b2b[row] ^ sm[l])
                };
            }
        }
        if FMA {
            for l in 0..L {
                ac[l] = sg[l].mul_add(xv, ac[l]);
            }
        } else {
            let xb = xv.bits();
            for l in 0..L {
                ac[l] = ac[l] + T::from_bits(xb ^ sm[l]);
            }
        }
        st = ns;
    }
    *span.s = st;
    *span.rot = r;
    *span.acc = ac;
}

#[cfg(test)]
mod tests {
    /// The σ-FMA's premise: fma(σ, b, v) with σ = ±1.0 rounds the exact v ± b once, as
    /// v + (±b) does, so the bits are the add's: for 10^5 pairs across twelve decades of
    /// magnitude and both signs, exact cancellations (both +0) and subnormal results. The
    /// check can fail: a real contraction fma(c, u, v), whose product c·u rounds, parts
    /// from c·u + v wherever c·u and v are within a few decades of each other (≈ 8% of
    /// these pairs, 7,926 of 10^5; far apart, the rounding of c·u vanishes in the sum).
    #[test]
    fn sigma_fma_is_the_add_and_a_real_contraction_is_not() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut value = || {
            let r = next();
            let m = (r >> 11) as f64 / (1u64 << 53) as f64;
            let sign = if r & 1 == 1 { -1.0 } else { 1.0 };
            sign * m * 10f64.powi((r >> 3) as i32 % 12 - 6)
        };
        let mut contracted_differs = 0;
        for _ in 0..100_000 {
            let (b, v, c) = (value(), value(), value());
            for sigma in [1.0f64, -1.0] {
                let fused = sigma.mul_add(b, v);
                let added = v + f64::from_bits(b.to_bits() ^ (sigma.to_bits() & (1 << 63)));
                assert_eq!(fused.to_bits(), added.to_bits(), "σ {sigma} b {b} v {v}");
                let narrow = (sigma as f32).mul_add(b as f32, v as f32);
                assert_eq!(
                    narrow.to_bits(),
                    (v as f32 + sigma as f32 * b as f32).to_bits()
                );
            }
            contracted_differs += usize::from(c.mul_add(b, v) != c * b + v);
        }
        for (b, v) in [
            (0.3, -0.3),
            (-0.7, 0.7),
            (f64::MIN_POSITIVE, -f64::MIN_POSITIVE / 2.0),
        ] {
            for sigma in [1.0f64, -1.0] {
                let added = v + sigma * b;
                assert_eq!(sigma.mul_add(b, v).to_bits(), added.to_bits(), "{b} {v}");
            }
        }
        assert_eq!(
            (1.0f64).mul_add(0.3, -0.3).to_bits(),
            0.0f64.to_bits(),
            "+0, not −0"
        );
        assert!(contracted_differs > 5_000, "{contracted_differs}");
    }
}
