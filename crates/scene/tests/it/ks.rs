//! Kolmogorov–Smirnov tests of the batched Monte Carlo (`PhotonSource::fill`) against the
//! closed-form laws of its TDC codes, and against the per-pulse reference kernel
//! (`fill_reference`) by the two-sample test: the jitter (a normal of σ_I around 2δ/c,
//! also under a sine motion), the first background arrival (exponential, truncated by
//! the window) and the mixed detection law with pile-up. Each law is checked on several
//! seeds, and a deliberately wrong law (σ_I × 1.1, ρ_b × 1.1, ρ_s × 1.1) must be rejected.
//!
//! The statistic is D = max_k |F̂(k) − F(k)| over the codes k, F(k) = P(code ≤ k) (a pulse
//! without detection counts above every code). For n samples the critical value at level
//! α = 0.001 is 1.95/√n (Kolmogorov's limit law; conservative for a discrete law): with
//! n = 200,000 it is 0.0044, while the wrong laws move F by ≥ 0.01.

use crate::common;

use common::{sensor, source};
use tofprobe_scene::{MotionConfig, PhotonSource, Scene, SceneConfig, SensorConfig};

const N: usize = 200_000;
const SEEDS: [u64; 3] = [1, 2, 0xDEAD_BEEF];

/// The one-sample critical value at α = 0.001.
fn critical(n: usize) -> f64 {
    1.95 / (n as f64).sqrt()
}

/// erfc(x), Numerical Recipes' Chebyshev fit (fractional error < 1.2e-7 everywhere, far
/// below the KS resolution of ~1e-3).
fn erfc(x: f64) -> f64 {
    // Horner's rule over the coefficients after the constant term, lowest power first (a
    // loop, not the nested expression: rustfmt takes seconds to lay that out).
    const TAIL: [f64; 9] = [
        1.000_023_68,
        0.374_091_96,
        0.096_784_18,
        -0.186_288_06,
        0.278_868_07,
        -1.135_203_98,
        1.488_515_87,
        -0.822_152_23,
        0.170_872_77,
    ];
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = TAIL.iter().rev().fold(0.0, |acc, c| c + t * acc);
    let r = t * (-z * z - 1.265_512_23 + t * poly).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// The standard normal CDF.
fn phi(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// D between the codes and the law `cdf(k)` = P(code ≤ k), k < `codes`.
fn ks(out: &[Option<u32>], codes: u32, cdf: impl Fn(u32) -> f64) -> f64 {
    let mut hist = vec![0u64; codes as usize];
    for c in out.iter().flatten() {
        hist[*c as usize] += 1;
    }
    let mut acc = 0u64;
    let mut d = 0.0f64;
    for (k, h) in hist.iter().enumerate() {
        acc += h;
        d = d.max((acc as f64 / out.len() as f64 - cdf(k as u32)).abs());
    }
    d
}

fn draw(src: &PhotonSource, n: usize) -> Vec<Option<u32>> {
    let mut out = vec![None; n];
    src.fill(0, &mut out);
    out
}

/// A sensor with a fine TDC (1 ps codes) so the codes resolve the laws.
fn fine(jitter_ps: f64, rho_s: f64, rho_b: f64) -> SensorConfig {
    SensorConfig {
        tdc_lsb_ps: 1.0,
        ..sensor(jitter_ps, rho_s, rho_b)
    }
}

/// P(0 ≤ μ + σz < t) for the window starting at 0.
fn signal_before(t: f64, mu: f64, sigma: f64) -> f64 {
    phi((t - mu) / sigma) - phi(-mu / sigma)
}

/// Jitter on a static scene: code k holds arrivals in [k, k + 1) ps, the signal at
/// 30 mm = 200 ps with σ_I = 50 ps; σ_I × 1.1 is rejected on every seed.
#[test]
fn jitter_is_the_normal_of_sigma_i() {
    let (mu, sigma) = (200.0, 50.0);
    for seed in SEEDS {
        let src = PhotonSource::new(&fine(sigma, 1.0, 0.0), &common::static_scene(30.0), seed)
            .expect("valid");
        let out = draw(&src, N);
        let law = |s: f64| move |k: u32| signal_before(f64::from(k) + 1.0, mu, s);
        let d = ks(&out, src.tdc_codes(), law(sigma));
        assert!(d < critical(N), "seed {seed}: D = {d} ≥ {}", critical(N));
        let wrong = ks(&out, src.tdc_codes(), law(1.1 * sigma));
        assert!(
            wrong > 3.0 * critical(N),
            "seed {seed}: σ×1.1 not rejected, D = {wrong}"
        );
    }
}

/// Jitter under a 20 mm sine (±133 ps, 2.7 σ_I) at 4.5 kHz: the codes follow the mixture
/// over the pulses of the normals around each pulse's δ(t_n), F(k) = mean_n P(code ≤ k |
/// δ(t_n)), with the window's cut of the tails included. Checks the batched depth
/// evaluation; σ_I × 1.1 is rejected.
#[test]
fn jitter_under_a_sine_is_the_mixture_of_normals() {
    let n = 100_000;
    let (amp, f, sigma) = (20.0, 4500.0, 50.0);
    let scene = Scene::new(&SceneConfig {
        depth_mm: 30.0,
        motions: vec![MotionConfig::Sine {
            amplitude_mm: amp,
            frequency_hz: f,
            phase_deg: 30.0,
        }],
    })
    .expect("valid");
    // 5 ps codes (80 in the window): the mixture is evaluated per code and pulse.
    let sensor = sensor(sigma, 1.0, 0.0);
    let mus: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / sensor.laser_rate_hz;
            let d = 30.0 + amp * (std::f64::consts::TAU * (f * t + 30.0 / 360.0)).sin();
            d / tofprobe_scene::MM_PER_PS
        })
        .collect();
    let mixture = |s: f64| {
        let cdf: Vec<f64> = (0..80)
            .map(|k| {
                let t = 5.0 * (f64::from(k) + 1.0);
                mus.iter().map(|&mu| signal_before(t, mu, s)).sum::<f64>() / n as f64
            })
            .collect();
        move |k: u32| cdf[k as usize]
    };
    let (right, wrong) = (mixture(sigma), mixture(1.1 * sigma));
    // The two laws' own distance is 0.0129 (2.1 critical values): the sample's distance to
    // the wrong law stays under one critical value only if the sample strays from its own
    // law by more than 0.0129 − 0.0062 = 0.0067 toward it (√n·D = 2.1), probability
    // ≈ 2·e^(−2·2.1²) ≈ 2.5·10^−4 per seed. (A threshold of two critical values, 0.0123,
    // sat inside the sampling noise of the gap itself.)
    let gap = (0..80u32)
        .map(|k| (right(k) - wrong(k)).abs())
        .fold(0.0, f64::max);
    assert!(gap > 2.0 * critical(n), "the laws' gap {gap}");
    for seed in SEEDS {
        let src = PhotonSource::new(&sensor, &scene, seed).expect("valid");
        let out = draw(&src, n);
        let d = ks(&out, 80, &right);
        assert!(d < critical(n), "seed {seed}: D = {d} ≥ {}", critical(n));
        let w = ks(&out, 80, &wrong);
        assert!(w > critical(n), "seed {seed}: σ×1.1 not rejected, D = {w}");
    }
}

/// Background alone: the first of Poisson(ρ_b) arrivals uniform over the window W is
/// before t with probability 1 − e^(−ρ_b t/W); no arrival (no detection) has e^(−ρ_b).
/// ρ_b × 1.1 is rejected.
#[test]
fn background_first_arrival_is_the_truncated_exponential() {
    let w = 400.0;
    for (rho_b, seed) in [(0.3, SEEDS[0]), (0.3, SEEDS[1]), (2.0, SEEDS[2])] {
        let src = PhotonSource::new(&fine(50.0, 0.0, rho_b), &common::static_scene(30.0), seed)
            .expect("valid");
        let out = draw(&src, N);
        let law = |rb: f64| move |k: u32| 1.0 - (-rb * (f64::from(k) + 1.0) / w).exp();
        let d = ks(&out, src.tdc_codes(), law(rho_b));
        assert!(d < critical(N), "ρ_b {rho_b} seed {seed}: D = {d}");
        let wrong = ks(&out, src.tdc_codes(), law(1.1 * rho_b));
        assert!(
            wrong > 2.0 * critical(N),
            "ρ_b×1.1 not rejected: D = {wrong}"
        );
        // The arrival count: detections are Binomial(N, 1 − e^(−ρ_b)), 5 standard errors.
        let p = 1.0 - (-rho_b).exp();
        let got = out.iter().flatten().count() as f64 / N as f64;
        let se = (p * (1.0 - p) / N as f64).sqrt();
        assert!(
            (got - p).abs() < 5.0 * se,
            "detections {got}, expected {p} ± {se}"
        );
    }
}

/// Signal and background with pile-up, (ρ_s, ρ_b) = (0.3, 0.3): the earliest of a signal
/// photon (probability ρ_s, normal around 200 ps) and the first background arrival, so
/// P(code ≤ k) = 1 − (1 − ρ_s P(0 ≤ signal < t))·e^(−ρ_b t/W) at t = k + 1 ps. ρ_s × 1.1
/// is rejected.
#[test]
fn mixed_detection_law_with_pileup() {
    let (mu, sigma, w, rho_b) = (200.0, 50.0, 400.0, 0.3);
    let law = |rs: f64| {
        move |k: u32| {
            let t = f64::from(k) + 1.0;
            1.0 - (1.0 - rs * signal_before(t, mu, sigma)) * (-rho_b * t / w).exp()
        }
    };
    for seed in SEEDS {
        let src = PhotonSource::new(&fine(sigma, 0.3, rho_b), &common::static_scene(30.0), seed)
            .expect("valid");
        let out = draw(&src, N);
        let d = ks(&out, src.tdc_codes(), law(0.3));
        assert!(d < critical(N), "seed {seed}: D = {d}");
        let wrong = ks(&out, src.tdc_codes(), law(0.33));
        assert!(
            wrong > 2.0 * critical(N),
            "ρ_s×1.1 not rejected: D = {wrong}"
        );
    }
}

/// The per-pulse reference kernel judges the batched one: the two-sample KS statistic
/// between `fill` and `fill_reference` (independent streams of one source) stays under
/// its α = 0.001 critical value 1.95·√(2/n) at both benchmark rates on a moving scene,
/// and so do the detection and background-win counts (5 standard errors of the
/// difference of two binomials).
#[test]
fn batched_kernel_matches_the_reference_kernel() {
    let n = N;
    for (rho_s, rho_b) in [(1.0, 0.0), (0.3, 0.3)] {
        let src = PhotonSource::new(&sensor(50.0, rho_s, rho_b), &common::busy_scene(), 5)
            .expect("valid");
        let mut a = vec![None; n];
        let mut b = vec![None; n];
        let ca = src.fill_counted(0, &mut a);
        let cb = src.fill_counted_reference(0, &mut b);
        let codes = src.tdc_codes() as usize;
        let hist = |v: &[Option<u32>]| {
            let mut h = vec![0i64; codes];
            for c in v.iter().flatten() {
                h[*c as usize] += 1;
            }
            h
        };
        let (ha, hb) = (hist(&a), hist(&b));
        let (mut acc, mut d) = (0i64, 0i64);
        for k in 0..codes {
            acc += ha[k] - hb[k];
            d = d.max(acc.abs());
        }
        let d = d as f64 / n as f64;
        let crit = 1.95 * (2.0 / n as f64).sqrt();
        assert!(d < crit, "({rho_s}, {rho_b}): two-sample D = {d} ≥ {crit}");
        for (x, y, what) in [
            (ca.detections, cb.detections, "detections"),
            (ca.background_wins, cb.background_wins, "background wins"),
        ] {
            let p = (x + y) as f64 / (2 * n) as f64;
            let se = (2.0 * p * (1.0 - p) / n as f64).sqrt().max(1.0 / n as f64);
            let diff = (x as f64 - y as f64).abs() / n as f64;
            assert!(diff < 5.0 * se, "({rho_s}, {rho_b}) {what}: {x} vs {y}");
        }
    }
    // Two different laws are told apart by the same test: ρ_s 1 against 0.9.
    let one = source(30.0, 50.0, 1.0, 0.0, 5);
    let other = source(30.0, 50.0, 0.9, 0.0, 5);
    let (mut a, mut b) = (vec![None; n], vec![None; n]);
    let (x, y) = (
        one.fill_counted(0, &mut a),
        other.fill_counted_reference(0, &mut b),
    );
    assert!(x.detections - y.detections > (n / 20) as u64);
}
