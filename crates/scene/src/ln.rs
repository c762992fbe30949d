//! A branch-free natural logarithm for the batched Monte Carlo's background arrivals
//! (crates/scene/src/batch.rs): the platform's `ln` is a call per value, this one is
//! straight-line code a pass over a block vectorises.

/// ln(u) for u ∈ [2^−53, 1] (normal, positive), branch-free so a batch vectorises: the
/// fdlibm algorithm (e_log.c: u = 2^k·m with m ∈ [√½, √2), s = (m − 1)/(m + 1), a degree-14
/// polynomial in s), error < 1 ulp as fdlibm's. The constants as fdlibm publishes them.
#[allow(clippy::excessive_precision)]
#[inline(always)]
pub(crate) fn ln(u: f64) -> f64 {
    const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
    const LG1: f64 = 6.666_666_666_666_735_130e-1;
    const LG2: f64 = 3.999_999_999_940_941_908e-1;
    const LG3: f64 = 2.857_142_874_366_239_149e-1;
    const LG4: f64 = 2.222_219_843_214_978_396e-1;
    const LG5: f64 = 1.818_357_216_161_805_012e-1;
    const LG6: f64 = 1.531_383_769_920_937_332e-1;
    const LG7: f64 = 1.479_819_860_511_658_591e-1;
    let bits = u.to_bits();
    // The biased exponent as a float by the 2^52 trick (exact: it is < 2^11), not an
    // integer-to-float conversion, which AVX2 lacks for 64-bit lanes (scalar there).
    const TWO52: f64 = 4_503_599_627_370_496.0;
    let e = f64::from_bits((bits >> 52) | TWO52.to_bits()) - (TWO52 + 1023.0);
    let m = f64::from_bits((bits & 0x000F_FFFF_FFFF_FFFF) | 0x3FF0_0000_0000_0000);
    let big = m > std::f64::consts::SQRT_2;
    let m = if big { 0.5 * m } else { m };
    let k = if big { e + 1.0 } else { e };
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG2 + w * (LG4 + w * LG6));
    let t2 = z * (LG1 + w * (LG3 + w * (LG5 + w * LG7)));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    k * LN2_HI - ((hfsq - (s * (hfsq + r) + k * LN2_LO)) - f)
}

#[cfg(test)]
mod tests {
    /// The branch-free ln against the platform's over (0, 1]: within 2 ulps everywhere
    /// tried (a wrong fdlibm coefficient shows at ~1e-10).
    #[test]
    fn ln_matches_std() {
        let mut g = crate::SplitMix64::new(7);
        let mut worst = 0.0f64;
        for i in 0..200_000 {
            let u = if i < 64 {
                0.5f64.powi(i) * 0.999
            } else {
                ((g.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
            };
            let (a, b) = (super::ln(u), u.ln());
            if b != 0.0 {
                worst = worst.max(((a - b) / b).abs());
            } else {
                assert_eq!(a, 0.0);
            }
        }
        assert!(
            worst <= 2.0 * f64::EPSILON,
            "worst relative error {worst:e}"
        );
    }
}
