//! The imputation against independent references: a matrix-form Kalman filter written
//! here from the textbook equations, Kalata's steady-state relations, the hold's closed
//! forms as the α-β form's special case, and simulated spectra.

use super::response::{mean_response, noise_factor, steady_state_gains};
use super::*;
use crate::closed_form::{hold_noise_factor, hold_response_sq};
use crate::preprocess::{FrontEnd, FrontEndOutput};

type M = [[f64; 2]; 2];

fn mm(a: &M, b: &M) -> M {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}
fn tr(a: &M) -> M {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}
fn add(a: &M, b: &M) -> M {
    [
        [a[0][0] + b[0][0], a[0][1] + b[0][1]],
        [a[1][0] + b[1][0], a[1][1] + b[1][1]],
    ]
}

/// The textbook filter in matrix form (F, Q, H, R as matrices; Joseph update), primed and
/// gated as the module says. Returns the output per pulse (0 before priming).
fn naive_kalman(k: &KalmanParams, input: &[Option<f64>]) -> Vec<f64> {
    let f: M = [[1.0, 1.0], [0.0, 1.0]];
    let g = [0.5, 1.0];
    let s2 = k.process_noise * k.process_noise;
    let q: M = [
        [g[0] * g[0] * s2, g[0] * g[1] * s2],
        [g[1] * g[0] * s2, g[1] * g[1] * s2],
    ];
    let r = k.measurement_noise * k.measurement_noise;
    let mut x = [0.0, 0.0];
    let mut p: M = [[r, 0.0], [0.0, r]];
    let mut primed = false;
    let mut out = Vec::new();
    for &z in input {
        if !primed {
            if let Some(z) = z {
                primed = true;
                x = [z, 0.0];
            }
            out.push(if primed { x[0] } else { 0.0 });
            continue;
        }
        x = [
            f[0][0] * x[0] + f[0][1] * x[1],
            f[1][0] * x[0] + f[1][1] * x[1],
        ];
        p = add(&mm(&mm(&f, &p), &tr(&f)), &q);
        if let Some(z) = z {
            let s = p[0][0] + r;
            let nu = z - x[0];
            if nu.abs() <= k.gate_sd * s.sqrt() {
                let kg = [p[0][0] / s, p[1][0] / s];
                x = [x[0] + kg[0] * nu, x[1] + kg[1] * nu];
                let ikh: M = [[1.0 - kg[0], 0.0], [-kg[1], 1.0]];
                let krk: M = [
                    [kg[0] * kg[0] * r, kg[0] * kg[1] * r],
                    [kg[1] * kg[0] * r, kg[1] * kg[1] * r],
                ];
                p = add(&mm(&mm(&ikh, &p), &tr(&ikh)), &krk);
            }
        }
        out.push(x[0]);
    }
    out
}

/// A deterministic detection stream: a ρ = 0 prefix, then detections with probability
/// `rho` at a slow sine plus uniform noise, and outliers (every 97th detection +40 mm).
fn stream(n: usize, prefix: usize, rho: f64, scale: f64) -> Vec<Option<f64>> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut u = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|i| {
            let hit = u() < rho;
            let noise = (u() - 0.5) * 12.0;
            if i < prefix || !hit {
                return None;
            }
            let out = if i % 97 == 0 { 40.0 } else { 0.0 };
            Some(scale * (30.0 + (i as f64 * 1e-3).sin() + noise + out))
        })
        .collect()
}

/// The front end's Kalman equals the matrix-form reference to 1e-12 relative (the same
/// operations regrouped: a few ulps per pulse, no growth as P converges), with a ρ = 0
/// prefix of 10^4 pulses and at huge and tiny scales; no NaN anywhere.
#[test]
fn kalman_matches_the_matrix_form_reference() {
    for &scale in &[1.0, 1e9, 1e-9] {
        let k = KalmanParams {
            process_noise: 1e-4 * scale,
            measurement_noise: 3.0 * scale,
            gate_sd: 3.0,
        };
        let input = stream(60_000, 10_000, 0.1, scale);
        let want = naive_kalman(&k, &input);
        let mut fe =
            FrontEnd::with_imputation(0.0, FrontEndOutput::Held, Imputation::Kalman(k)).unwrap();
        let got: Vec<f64> = input.iter().map(|&d| fe.step(d)).collect();
        assert!(got[..10_000].iter().all(|&v| v == 0.0));
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(g.is_finite(), "pulse {i}: {g}");
            assert!(
                (g - w).abs() <= 1e-12 * w.abs().max(scale),
                "pulse {i}: {g} vs {w}"
            );
        }
    }
}

/// At ρ = 1 the filter's gain converges to Kalata's steady state (1e-9: the gain settles
/// geometrically, 10^5 pulses are ≫ 1/α for these λ), and the closed form obeys the α-β
/// relations β²/(1 − α) = λ² and β = 2(2 − α) − 4·sqrt(1 − α) (1e-12 relative).
#[test]
fn steady_state_gain_is_kalatas() {
    for &lambda in &[1e-3, 0.1, 1.0, 10.0] {
        let (alpha, beta) = steady_state_gains(lambda);
        assert!((beta * beta / (1.0 - alpha) / (lambda * lambda) - 1.0).abs() < 1e-12);
        let rel = 2.0 * (2.0 - alpha) - 4.0 * (1.0 - alpha).sqrt();
        assert!(
            (rel - beta).abs() < 1e-12 * beta.max(1e-300),
            "{rel} vs {beta}"
        );
        let k = KalmanParams {
            process_noise: lambda,
            measurement_noise: 1.0,
            gate_sd: f64::INFINITY,
        };
        let mut im = Imputer::new(Imputation::Kalman(k));
        for _ in 0..100_000 {
            im.step(Some(0.0));
        }
        // The gain the next update uses: predicted P's first column over S.
        let (_, [dd, dv, vv]) = im.state();
        let q = lambda * lambda;
        let (pdd, pdv) = (dd + 2.0 * dv + vv + 0.25 * q, dv + vv + 0.5 * q);
        let s = pdd + 1.0;
        assert!(
            (pdd / s - alpha).abs() < 1e-9,
            "λ {lambda}: α {} vs {alpha}",
            pdd / s
        );
        assert!(
            (pdv / s - beta).abs() < 1e-9,
            "λ {lambda}: β {} vs {beta}",
            pdv / s
        );
    }
    // Tiny λ keeps its precision: α ≈ sqrt(2λ), β ≈ λ.
    let (a, b) = steady_state_gains(1e-14);
    assert!((a / (2e-14f64).sqrt() - 1.0).abs() < 1e-6 && (b / 1e-14 - 1.0).abs() < 1e-6);
}

/// The α-β closed forms at α = 1, β = 0 are the hold's (1e-12: the same quantity by two
/// exact routes in f64).
#[test]
fn fixed_gain_forms_reduce_to_the_hold() {
    for &(rho, f) in &[(0.03, 4.5e-4), (0.3, 1e-3), (0.9, 0.2)] {
        let w = 2.0 * std::f64::consts::PI * f;
        let h = mean_response(1.0, 0.0, rho, w).unwrap().norm_sqr();
        assert!((h / hold_response_sq(rho, w) - 1.0).abs() < 1e-12);
        let nf = noise_factor(1.0, 0.0, rho, w).unwrap();
        assert!((nf / hold_noise_factor(rho, w) - 1.0).abs() < 1e-12, "{nf}");
    }
    assert!(mean_response(0.0, 0.0, 0.5, 0.1).is_err());
    assert!(noise_factor(0.5, 0.1, 0.0, 0.1).is_err());
}

/// The α-β form's simulated periodogram matches its closed forms: white noise σ = 1 at
/// ρ = 0.2, mean |Y|² over 4096 bins of a 2^16-pulse rectangular DFT, 4 seeds: relative
/// sd 1/sqrt(16384) ≈ 0.8 %, so 4 % is 5 sd; and a noise-free sine's amplitude equals
/// |H_mean| (2 %: the random-coefficient leakage at the tone is ≈ sqrt(ρ(1 − ρ)/N) ≈ 0.2 %
/// of A per seed).
#[test]
fn fixed_gain_simulation_matches_closed_forms() {
    let g = AlphaBeta {
        alpha: 1.0 / 8.0,
        beta: 1.0 / 512.0,
        gate_mm: f64::INFINITY,
    };
    let (n, rho) = (1usize << 16, 0.2);
    let (lo, hi) = (1000usize, 5096usize);
    let mut sum = 0.0;
    for seed in 0..4u64 {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut u = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut fe =
            FrontEnd::with_imputation(0.0, FrontEndOutput::Held, Imputation::AlphaBeta(g)).unwrap();
        // Uniform noise of sd 1: (u − ½)·sqrt(12).
        let y: Vec<f64> = (0..2 * n)
            .map(|_| {
                let hit = u() < rho;
                let w = (u() - 0.5) * 12f64.sqrt();
                fe.step(hit.then_some(w))
            })
            .collect();
        let spec = crate::dft::amplitude_spectrum(&y[n..], crate::Window::Rectangular).unwrap();
        // amplitude_spectrum is 2|X|/N: E|Y|² = 4 S(ω)/N.
        sum += spec[lo..hi]
            .iter()
            .map(|a| a * a * n as f64 / 4.0)
            .sum::<f64>();
    }
    let measured = sum / (4.0 * (hi - lo) as f64);
    let want = (lo..hi)
        .map(|k| {
            noise_factor(
                g.alpha,
                g.beta,
                rho,
                2.0 * std::f64::consts::PI * k as f64 / n as f64,
            )
            .unwrap()
        })
        .sum::<f64>()
        / (hi - lo) as f64;
    assert!((measured / want - 1.0).abs() < 0.04, "{measured} vs {want}");
    // A noise-free sine on bin 200.
    let k0 = 200usize;
    let w0 = 2.0 * std::f64::consts::PI * k0 as f64 / n as f64;
    let mut fe =
        FrontEnd::with_imputation(0.0, FrontEndOutput::Held, Imputation::AlphaBeta(g)).unwrap();
    let mut s: u64 = 12345;
    let y: Vec<f64> = (0..2 * n)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let hit = ((s >> 11) as f64 / (1u64 << 53) as f64) < rho;
            fe.step(hit.then_some((w0 * i as f64).sin()))
        })
        .collect();
    let spec = crate::dft::amplitude_spectrum(&y[n..], crate::Window::Rectangular).unwrap();
    let h = mean_response(g.alpha, g.beta, rho, w0).unwrap().norm();
    assert!((spec[k0] / h - 1.0).abs() < 0.02, "{} vs {h}", spec[k0]);
}

/// Bad parameters are refused, naming the field.
#[test]
fn bad_parameters_rejected() {
    let bad = |i: Imputation| FrontEnd::with_imputation(0.0, FrontEndOutput::Held, i).unwrap_err();
    let k = KalmanParams::from_scene(7.5, 0.1, 2.8e-3);
    let e = bad(Imputation::Kalman(KalmanParams {
        measurement_noise: 0.0,
        ..k
    }));
    assert!(e.to_string().contains("measurement_noise"), "{e}");
    let e = bad(Imputation::Kalman(KalmanParams {
        process_noise: f64::NAN,
        ..k
    }));
    assert!(e.to_string().contains("process_noise"), "{e}");
    let g = AlphaBeta::from_kalman(&k, 0.1).unwrap();
    assert!(
        bad(Imputation::AlphaBeta(AlphaBeta { alpha: 0.0, ..g }))
            .to_string()
            .contains("alpha")
    );
    assert!(AlphaBeta::from_kalman(&k, 0.0).is_err());
    let still = KalmanParams {
        process_noise: 0.0,
        ..k
    };
    let e = AlphaBeta::from_kalman(&still, 0.1).unwrap_err();
    assert!(e.to_string().contains("alpha"), "{e}");
    // The physics defaults give power-of-two gains and a finite gate.
    assert_eq!(g.alpha.log2().fract(), 0.0);
    assert_eq!(g.beta.log2().fract(), 0.0);
    assert!(g.gate_mm.is_finite() && g.gate_mm > 3.0 * 7.5);
}
