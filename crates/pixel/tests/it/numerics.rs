//! Numerics of the data path (issue point 4): the wrap property, the shift prefilter's dead
//! band and bias at F = 0 against the default F (measured), arithmetic-shift semantics on
//! negative values, and no silent saturation.

use crate::common;

use common::Rng;
use proptest::prelude::*;
use tofprobe_pixel::fixed::{prefilter_step, sign_extend, to_raw, wrap};
use tofprobe_pixel::{DEFAULT_FRAC_BITS, Mode, PixelParams, TransactionModel};

/// Drives the prefilter with a constant held depth from a start state until it stops
/// moving; returns the final x in codes.
fn settle(x0: i64, held: i64, f: u32, s: u32) -> f64 {
    let mut x = x0;
    for _ in 0..100_000 {
        let next = prefilter_step(x, held, f, s);
        if next == x {
            break;
        }
        x = next;
    }
    x as f64 / f64::from(1u32 << f)
}

/// Dead band: after an upward step the floor shift stops as soon as the difference is
/// below 2^S LSBs of x, i.e. (2^S − 1)·2^−F codes short of the target; a downward step
/// reaches the target exactly. At F = 0 and S = 5 an upward step of up to 31 codes is lost
/// entirely; at the default F = 8 the residue is 31/256 = 0.121 code.
#[test]
fn prefilter_dead_band_f0_versus_default() {
    let s = 5;
    for (f, band) in [(0u32, 31.0), (DEFAULT_FRAC_BITS, 31.0 / 256.0)] {
        // Up by 40 codes from 10: stops exactly `band` codes below 50.
        let up = settle(10 << f, 50, f, s);
        assert_eq!(50.0 - up, band, "upward residue at F = {f}");
        // Down by 40 codes: exact.
        assert_eq!(settle(50 << f, 10, f, s), 10.0, "downward at F = {f}");
        // A step smaller than the band is lost entirely at F = 0.
        if f == 0 {
            assert_eq!(
                settle(20, 51, f, s),
                20.0,
                "31-code step swallowed at F = 0"
            );
        }
    }
}

/// Bias on a noisy constant depth (held = 40 + uniform{−3..3} codes, 2·10^5 pulses).
/// At F = 0 (and up to F = 2) the 31-code dead band exceeds the noise: x slides down to the
/// lowest input it sees and stays there — a bias of exactly −3 codes, the noise's lower
/// edge, whatever the true mean. Once the dead band is below the noise, E[floor(d/2^S)] =
/// E[d]/2^S − E[frac] puts x (2^S − 1)/2 LSBs below the mean input: −15.5·2^−F codes,
/// −0.061 code at the default F = 8 (measured −0.052). Measured over F (this seed):
/// F=3 −1.93, F=4 −0.96, F=5 −0.47, F=6 −0.23, F=7 −0.11, F=8 −0.052, F=10 −0.007.
/// Tolerance: the mean of x over n = 2·10^5 samples correlated over τ ≈ 2^S = 32 pulses has
/// a standard error ≈ σ_x·sqrt(2τ/n); with σ_x ≈ 0.4 code after the filter that is ≈ 0.007
/// code, so ±0.03 code is more than 4 standard errors.
#[test]
fn prefilter_bias_f0_versus_default() {
    let s = 5;
    let measure = |f: u32| {
        let mut rng = Rng(11);
        let mut x = 40i64 << f;
        let mut sum = 0.0;
        let n = 200_000;
        for i in 0..n + 1000 {
            let held = 40 + rng.below(7) as i64 - 3;
            x = prefilter_step(x, held, f, s);
            if i >= 1000 {
                sum += x as f64 / f64::from(1u32 << f) - 40.0;
            }
        }
        sum / n as f64
    };
    assert_eq!(measure(0), -3.0, "F = 0 locks onto the lowest input");
    let f = DEFAULT_FRAC_BITS;
    let bias = measure(f);
    let expected = -15.5 / f64::from(1u32 << f);
    assert!(
        (bias - expected).abs() < 0.03,
        "F = {f}: measured bias {bias:.4} codes, expected {expected:.4}"
    );
    assert!(
        bias.abs() < 0.1,
        "the default F removes the bias to < 0.1 code"
    );
}

/// `>>` on i64 is an arithmetic (floor) shift in Rust, as `>>>` on a signed reg in Verilog:
/// −1 >>> 5 = −1 (not 0), −33 >>> 5 = −2, 31 >>> 5 = 0. The prefilter relies on it: a
/// negative difference always moves x by at least one LSB.
#[test]
fn arithmetic_shift_floors_negative_values() {
    assert_eq!(-1i64 >> 5, -1);
    assert_eq!(-32i64 >> 5, -1);
    assert_eq!(-33i64 >> 5, -2);
    assert_eq!(31i64 >> 5, 0);
    // x = 0, held = −1 code at F = 0: diff = −1 → step −1, not 0.
    assert_eq!(prefilter_step(0, -1, 0, 5), -1);
    // The same magnitude upward is a dead-band step of 0.
    assert_eq!(prefilter_step(0, 1, 0, 5), 0);
    // Negative zoomed depths through the whole pixel: held = 3 − 10 = −7 codes.
    let mut p = PixelParams::fourier_default(20, 8, 1);
    p.bins = 1;
    p.frac_bits = 2;
    p.zoom = 10;
    let mut tm = TransactionModel::new(&p).unwrap();
    tm.pulse(Some(3), &[0b01]); // primes: x = −7·4 = −28
    assert_eq!((tm.held(), tm.prefilter_state()), (-7, -28));
    tm.pulse(Some(9), &[0b01]); // x = −28 + ((−28 − −28) >> 5) = −28; I += −28, Q −= −28
    assert_eq!(tm.registers(), &[-28, 28]);
    tm.pulse(None, &[0b01]); // held −1·4 = −4: diff = 24 → 24 >> 5 = 0 (dead band)
    assert_eq!(tm.prefilter_state(), -28);
    tm.pulse(None, &[0b01]);
    assert_eq!(tm.registers(), &[-84, 84]);
}

/// No silent saturation: the registers wrap exactly (two's complement), they never clamp.
/// 2^(W−1) − 1 + 1 wraps to −2^(W−1) at every width.
#[test]
fn registers_wrap_never_saturate() {
    for w in 2..=63u32 {
        let max = (1i64 << (w - 1)) - 1;
        assert_eq!(wrap(max + 1, w), -(1i64 << (w - 1)), "W = {w}");
        assert_eq!(sign_extend(to_raw(-1, w), w), -1);
    }
    // Through the model: W = 5 (range −16..15), operand 7 added three times = 21 → −11.
    let mut p = PixelParams::fourier_default(5, 8, 1);
    p.bins = 1;
    p.tdc_bits = 3;
    p.frac_bits = 0;
    p.shift = 0;
    let mut tm = TransactionModel::new(&p).unwrap();
    for _ in 0..4 {
        tm.pulse(Some(7), &[0b11]);
    }
    assert_eq!(tm.registers(), &[21 - 32, 21 - 32]);
}

/// The Haar mode ignores F and S: its operand is the held depth itself.
#[test]
fn haar_operand_is_the_held_depth() {
    let mut p = PixelParams::fourier_default(12, 4, 1);
    p.mode = Mode::Haar;
    p.haar_scales = 1;
    p.frac_bits = 16; // ignored in Haar mode: W only needs T + 1 = 8 bits
    p.width = 8;
    p.validate().unwrap();
    let mut tm = TransactionModel::new(&p).unwrap();
    for c in [5, 6, 7, 9] {
        tm.pulse(Some(c), &[]);
    }
    // Scale 0: 5 + 6 − 7 − 9 = −5; scale 1: v = 0: 5 − 6 = −1; v = 1: 7 − 9 = −2.
    assert_eq!(tm.registers(), &[-5, -1, -2]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    /// Wrap property: whatever the partial sums did, the wrapped final value equals the
    /// true final value whenever the latter fits in W bits. Operands up to 2^20 and 64
    /// terms make the partial sums leave a W ≤ 24-bit range often while the final value is
    /// forced back into range by a last correcting term.
    #[test]
    fn final_value_exact_when_it_fits(
        w in 3u32..24,
        ops in proptest::collection::vec(-(1i64 << 20)..(1i64 << 20), 1..64),
        target in any::<i32>(),
    ) {
        let lim = 1i64 << (w - 1);
        let goal = i64::from(target).rem_euclid(2 * lim) - lim; // a value that fits
        let partial: i64 = ops.iter().sum();
        let mut reg = 0i64;
        for &o in &ops {
            reg = wrap(reg + o, w);
        }
        reg = wrap(reg + (goal - partial), w);
        prop_assert_eq!(reg, goal);
    }
}

/// Issue 16, prefilter rounding, before and after: the stationary bias of x against the
/// mean held depth, on a jittered static scene (held = 40 codes ± 3, uniform, so the
/// residues of the shift are uniform). The closed forms: floor truncates a mean of
/// (2^S − 1)/2^(S+1) LSB per step and the filter's DC gain 2^S multiplies it, so x settles
/// (2^S − 1)/2 LSB = 15.5/256 = −0.0605 code low; nearest (round half up) leaves 1/2^(S+1)
/// LSB per step, +1/2 LSB = +0.00195 code. 10^6 steps: the mean's sd is ≈ 1e-4 code (the
/// filter's output noise ≈ 0.3 code over ≈ 10^6/64 independent samples), so ±0.002 code
/// holds both with margin and fails a swap of the two roundings by 30×.
#[test]
fn nearest_rounding_removes_the_prefilter_bias() {
    use tofprobe_pixel::Rounding;
    use tofprobe_pixel::fixed::prefilter_step_rounded;
    let (f, s) = (DEFAULT_FRAC_BITS, 5);
    let bias = |rounding: Rounding| {
        let mut rng = Rng(7);
        let mut x: i64 = 40 << f;
        let (mut sum_x, mut sum_held, mut count) = (0f64, 0f64, 0f64);
        for n in 0..1_000_000u32 {
            let held = 37 + rng.below(7) as i64;
            x = prefilter_step_rounded(x, held, f, s, rounding);
            if n >= 10_000 {
                sum_x += x as f64 / f64::from(1u32 << f);
                sum_held += held as f64;
                count += 1.0;
            }
        }
        (sum_x - sum_held) / count
    };
    let lsb = 1.0 / f64::from(1u32 << f);
    let floor = bias(Rounding::Floor);
    let nearest = bias(Rounding::Nearest);
    let floor_closed = -f64::from((1u32 << s) - 1) / 2.0 * lsb;
    let nearest_closed = 0.5 * lsb;
    println!(
        "prefilter bias (codes): floor {floor:+.4} (closed form {floor_closed:+.4}), nearest {nearest:+.5} (closed form {nearest_closed:+.5})"
    );
    assert!((floor - floor_closed).abs() < 2e-3, "floor {floor}");
    assert!((nearest - nearest_closed).abs() < 2e-3, "nearest {nearest}");
    assert!(
        floor.abs() > 25.0 * nearest.abs(),
        "floor {floor} nearest {nearest}"
    );
    // S = 0 is exact either way: no rounding constant.
    assert_eq!(
        prefilter_step_rounded(3, 5, 2, 0, Rounding::Nearest),
        prefilter_step(3, 5, 2, 0)
    );
}
