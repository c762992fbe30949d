//! The registers' operand with G ≤ F fraction bits (`register_frac_bits`, issue 16 point
//! 1b): the datapath adds op = x >>> (F − G), the floor of x / 2^(F−G), judged against a
//! naive floating-point floor on every pulse of a random stream (negative x included), and
//! the mean of that floor's residue against its closed form on a jittered depth. The
//! register widths this saves are checked through the binary
//! (crates/cli/tests/register_frac_bits.rs).

use crate::common;

use common::Rng;
use tofprobe_pixel::{Datapath, PixelParams};

/// The default Fourier pixel (T = 7, F = 8, S = 5) with zoom 40, so d = tdc − 40 spans
/// −40..=87 and x can take both signs, and registers keeping `g` fraction bits.
fn params(g: u32) -> PixelParams {
    let mut p = PixelParams::fourier_default(40, 1 << 20, 1);
    p.zoom = 40;
    p.register_frac_bits = Some(g);
    p.validate().expect("valid parameters");
    p
}

/// Every primed pulse's operand equals floor(x / 2^(F−G)) computed in f64 (exact: |x| <
/// 2^16) for every G in 0..=F, and fits the T+1+G operand bits; x itself keeps T+1+F.
#[test]
fn operand_is_the_floor_of_x() {
    let mut rng = Rng(0x6b17_5eed);
    for g in 0..=8u32 {
        let p = params(g);
        let k = 8 - g;
        let (ob, xb) = (p.operand_bits(), p.prefilter_bits());
        assert_eq!((ob, xb), (8 + g, 16));
        let mut dp = Datapath::new(&p);
        let (mut checked, mut negative_inexact) = (0, 0);
        for _ in 0..20_000 {
            let valid = rng.chance(80);
            // d = tdc − 40 over −40..=40: the filtered x is negative about half the time.
            let tdc = rng.below(81) as u32;
            let Some(op) = dp.fourier_pulse(valid, tdc, None) else {
                continue;
            };
            let x = dp.prefilter_state();
            let naive = (x as f64 / f64::from(1u32 << k)).floor() as i64;
            assert_eq!(op, naive, "G = {g}: x = {x}");
            assert!(
                (-(1i64 << (ob - 1))..1i64 << (ob - 1)).contains(&op),
                "G = {g}: op = {op} beyond {ob} bits"
            );
            assert!((-(1i64 << (xb - 1))..1i64 << (xb - 1)).contains(&x));
            checked += 1;
            // Where floor and truncation toward zero differ: a `/` in place of the shift
            // would fail here.
            if x < 0 && x % (1 << k) != 0 {
                negative_inexact += 1;
            }
        }
        assert!(checked > 15_000, "G = {g}: {checked} operands");
        if k > 0 {
            assert!(negative_inexact > 1000, "G = {g}: {negative_inexact}");
        }
    }
}

/// The floor drops x's low F − G bits, whose value, uniform over 0..2^(F−G) on a noisy
/// input, has the mean (1 − 2^−(F−G))/2 LSB_G: the operand sits that much below x
/// (−0.375 LSB_G at G = F − 2, −0.498 at G = 0, exactly 0 at G = F). Measured on a depth
/// jittered uniformly over ±20 codes around the zoom (x of both signs), 2^20 pulses.
/// Tolerance 0.015 LSB_G: the residue's sd is ≤ 1/sqrt(12) = 0.29 LSB_G; even if
/// consecutive residues were correlated over the prefilter's whole time constant τ = 2^S =
/// 32 pulses the standard error is 0.29·sqrt(2τ/n) = 0.0023, so 0.015 is > 6 of them. The
/// same statistic of truncation toward zero (x / 2^(F−G) in integer division) sits near 0
/// on this zero-mean x and fails it (checked).
#[test]
fn operand_bias_matches_the_closed_form() {
    let n = 1usize << 20;
    for g in [0u32, 2, 4, 6, 8] {
        let p = params(g);
        let k = 8 - g;
        let scale = f64::from(1u32 << k);
        let mut dp = Datapath::new(&p);
        let mut rng = Rng(0xb1a5 + u64::from(g));
        let (mut floor_sum, mut trunc_sum, mut count) = (0.0, 0.0, 0usize);
        for _ in 0..n {
            let tdc = 20 + rng.below(41) as u32;
            let Some(op) = dp.fourier_pulse(true, tdc, None) else {
                continue;
            };
            let x = dp.prefilter_state();
            floor_sum += op as f64 - x as f64 / scale;
            trunc_sum += (x / (1 << k)) as f64 - x as f64 / scale;
            count += 1;
        }
        let closed = -(1.0 - 1.0 / scale) / 2.0;
        let floor_bias = floor_sum / count as f64;
        let trunc_bias = trunc_sum / count as f64;
        assert!(
            (floor_bias - closed).abs() < 0.015,
            "G = {g}: measured {floor_bias:.4} LSB_G, closed form {closed:.4}"
        );
        if k >= 2 {
            assert!(
                (trunc_bias - closed).abs() > 0.1,
                "G = {g}: truncation {trunc_bias:.4} would pass"
            );
        }
        eprintln!(
            "G = {g}: bias {floor_bias:+.4} LSB_G (closed form {closed:+.4}), truncation {trunc_bias:+.4}"
        );
    }
}
