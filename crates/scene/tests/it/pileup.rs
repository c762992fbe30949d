//! Pile-up and missed pulses against their closed forms (paper Sec. 6.1).

use crate::common;

use common::source;
use tofprobe_scene::FillCounts;

/// Runs `n` pulses and returns the counts.
fn counts(src: &tofprobe_scene::PhotonSource, n: usize) -> FillCounts {
    let mut out = vec![None; n];
    src.fill_counted(0, &mut out)
}

/// Signal survival under pile-up: ρ_s* = ρ_s·e^(−ρ_b·t_s/W), i.e. e^(−ρ_b/2) mid-window.
/// The signal sits at 30 mm = 200 ps, mid-way in the 0..400 ps window, with σ_I = 10 ps so
/// it never leaves the window (20σ margin).
#[test]
fn pileup_survival_mid_window() {
    let n = 1_000_000;
    for (rho_s, rho_b) in [(1.0, 0.1), (1.0, 0.3), (1.0, 1.0), (0.5, 0.3)] {
        let c = counts(&source(30.0, 10.0, rho_s, rho_b, 7), n);
        let signal_wins = (c.detections - c.background_wins) as f64 / n as f64;
        let p = rho_s * (-rho_b / 2.0_f64).exp();
        // Binomial standard error sqrt(p(1−p)/N) ≤ 5e-4; 5 SE keeps a false alarm at
        // ~6e-7 per case while a 1% error in the model would fail by > 10 SE.
        let se = (p * (1.0 - p) / n as f64).sqrt();
        assert!(
            (signal_wins - p).abs() < 5.0 * se,
            "rho_s {rho_s} rho_b {rho_b}: survival {signal_wins}, expected {p} ± {se}"
        );
        // No detection at all needs no signal photon and no background arrival:
        // P = (1 − ρ_s)·e^(−ρ_b).
        let q = (1.0 - rho_s) * (-rho_b).exp();
        let none = 1.0 - c.detections as f64 / n as f64;
        let se_q = (q * (1.0 - q) / n as f64).sqrt().max(1.0 / n as f64);
        assert!(
            (none - q).abs() < 5.0 * se_q,
            "rho_s {rho_s} rho_b {rho_b}: no-detection {none}, expected {q}"
        );
    }
}

/// Off-centre: signal at 15 mm = 100 ps = W/4, so ρ_s* = e^(−ρ_b/4).
#[test]
fn pileup_survival_general_position() {
    let n = 1_000_000;
    let rho_b = 1.0;
    let c = counts(&source(15.0, 5.0, 1.0, rho_b, 11), n);
    let survival = (c.detections - c.background_wins) as f64 / n as f64;
    let p = (-rho_b / 4.0_f64).exp();
    // Same binomial standard error argument as above (SE = 4.3e-4).
    let se = (p * (1.0 - p) / n as f64).sqrt();
    assert!(
        (survival - p).abs() < 5.0 * se,
        "survival {survival}, expected {p}"
    );
}

/// Gaps between successive detections (a run of misses plus the detecting pulse) are
/// geometric on {1, 2, …} with mean 1/ρ_s and σ = sqrt(1 − ρ_s)/ρ_s.
#[test]
fn missed_pulse_run_lengths_are_geometric() {
    let n = 2_000_000;
    for rho in [0.3, 0.1] {
        let src = source(30.0, 10.0, rho, 0.0, 3);
        let mut out = vec![None; n];
        src.fill(0, &mut out);
        let hits: Vec<usize> = (0..n).filter(|&i| out[i].is_some()).collect();
        let gaps: Vec<f64> = hits.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
        let m = gaps.len() as f64;
        let mean = gaps.iter().sum::<f64>() / m;
        let var = gaps.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / (m - 1.0);
        let sd = var.sqrt();
        let mean_th = 1.0 / rho;
        let sd_th = (1.0 - rho).sqrt() / rho;
        // SE of the mean: σ/sqrt(M). SE of the sample σ: (σ/2)·sqrt((κ − 1)/M) with the
        // geometric kurtosis κ = 9 + ρ²/(1 − ρ). M ≈ ρN ≥ 2·10^5 gaps. 5 SE each.
        let se_mean = sd_th / m.sqrt();
        let kurt = 9.0 + rho * rho / (1.0 - rho);
        let se_sd = sd_th / 2.0 * ((kurt - 1.0) / m).sqrt();
        assert!(
            (mean - mean_th).abs() < 5.0 * se_mean,
            "rho {rho}: mean gap {mean}, expected {mean_th} ± {se_mean}"
        );
        assert!(
            (sd - sd_th).abs() < 5.0 * se_sd,
            "rho {rho}: gap sigma {sd}, expected {sd_th} ± {se_sd}"
        );
    }
}
