//! Closed forms of the constant-velocity imputation: the steady-state gains of the Kalman
//! filter (the α-β relation), and the mean response and noise floor of the fixed-gain
//! (α-β) form under random detections — the 1NN hold's closed forms
//! (`closed_form::hold_response_sq`, `hold_noise_factor`) are its case α = 1, β = 0.
//!
//! # Steady state (Kalata, piecewise-constant white acceleration, period T)
//! Tracking index λ = σ_a·T²/σ_w; r = (4 + λ − sqrt(8λ + λ²))/4; α = 1 − r²,
//! β = 2(1 − r)² (velocity gain β/T), which satisfy β²/(1 − α) = λ² and
//! β = 2(2 − α) − 4·sqrt(1 − α).
//!
//! # Fixed gains K = [α, β] under detections of probability ρ per pulse
//! Predicted state x̂ (before pulse n's update), output y = d̂ + δ_n·α·(z − d̂), δ_n
//! Bernoulli(ρ), independent of the past. Because δ_n is independent of x̂_n the mean obeys
//! the linear filter with gains ρK: m\[n+1\] = A m\[n\] + ρFK s\[n\], A = F(I − ρKH), output
//! (1 − ρα)Hm + ρα s, so H_mean(z) = (1 − ρα)·ρ[(z − 1)(α + β) + β]/det + ρα,
//! det = (z − a)(z − 1) + ρβ, a = 1 − ρα − ρβ ([`mean_response`]). The noise x̃ = x̂ − m
//! obeys x̃\[n+1\] = A x̃ + FK·η\[n\], η = δw − (δ − ρ)Hx̃ (+ (δ − ρ)(s − Hm), the signal's
//! own tracking error, neglected: 10^−4 of σ² for Table 2's 0.1 mm tone), a white sequence
//! (each term's multiplier is independent of everything before it and has zero mean) of
//! variance ρσ² + ρ(1 − ρ)·Var(Hx̃). With c = H P₁ Hᵀ, P₁ = A P₁ Aᵀ + FK(FK)ᵀ, Var η =
//! ρσ²/(1 − ρ(1 − ρ)c); the output noise (1 − ρα)Hx̃ + αη has transfer H_mean/ρ, so its
//! spectrum is σ²·|H_mean|²/(ρ(1 − ρ(1 − ρ)c)) ([`noise_factor`], in units of σ²).
//! Consequence: SNR at any ω = A²ρ(1 − ρ(1 − ρ)c)/σ² per N_eff, at most ρA²/σ² (the
//! detections alone), (2 − ρ) times the hold's: no imputation gains more than
//! 10·log10(2 − ρ) dB over the hold at equal response ([`snr_bound_db`]).

use rustfft::num_complex::Complex64;

use crate::error::DspError;

/// Kalata's steady-state (α, β) of the constant-velocity Kalman filter at tracking index
/// λ = σ_a·T²/σ_w (β per period: the velocity gain is β/T).
pub fn steady_state_gains(lambda: f64) -> (f64, f64) {
    // r = (4 + λ − sqrt(8λ + λ²))/4, written as 1 − u with u = (sqrt(8λ + λ²) − λ)/4 =
    // 2λ/(sqrt(8λ + λ²) + λ), which keeps its precision at tiny λ (no cancellation).
    let u = 2.0 * lambda / ((8.0 * lambda + lambda * lambda).sqrt() + lambda);
    if u.is_nan() || u <= 0.0 {
        return (0.0, 0.0);
    }
    // α = 1 − (1 − u)² = u(2 − u), β = 2u².
    (u * (2.0 - u), 2.0 * u * u)
}

/// The fixed gains [α, β] checked for the closed forms at detection rate ρ.
fn check(alpha: f64, beta: f64, rho: f64) -> Result<(), DspError> {
    if !(rho > 0.0 && rho <= 1.0) {
        return Err(DspError::out_of_range("rho", rho, "0 < ρ ≤ 1"));
    }
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(DspError::out_of_range("alpha", alpha, "0 < α ≤ 1"));
    }
    if !(0.0..1.0).contains(&beta) {
        return Err(DspError::out_of_range("beta", beta, "0 ≤ β < 1"));
    }
    Ok(())
}

/// The mean response H_mean(e^{jω}) of the fixed-gain filter at detection rate ρ.
pub fn mean_response(alpha: f64, beta: f64, rho: f64, omega: f64) -> Result<Complex64, DspError> {
    check(alpha, beta, rho)?;
    let z = Complex64::from_polar(1.0, omega);
    let (ra, rb) = (rho * alpha, rho * beta);
    let a = 1.0 - ra - rb;
    let det = (z - a) * (z - 1.0) + rb;
    let num = rho * ((z - 1.0) * (alpha + beta) + beta);
    Ok((1.0 - ra) * num / det + ra)
}

/// c = H P₁ Hᵀ with P₁ = A P₁ Aᵀ + g gᵀ (g = FK = [α + β, β]): the predicted depth's
/// variance per unit of white innovation variance, by the doubling iteration
/// P ← P + AᵏP(Aᵏ)ᵀ, Aᵏ ← (Aᵏ)² (exact sums of positive terms; a linear solve would lose
/// ≈ 12 digits at ρα ≈ 10^−4, where A's eigenvalues are within 10^−4 of 1).
fn innovation_depth_variance(alpha: f64, beta: f64, rho: f64) -> Result<f64, DspError> {
    let (ra, rb) = (rho * alpha, rho * beta);
    let mut a = [[1.0 - ra - rb, 1.0], [-rb, 1.0]];
    let g = [alpha + beta, beta];
    let mut p = [[g[0] * g[0], g[0] * g[1]], [g[0] * g[1], g[1] * g[1]]];
    for _ in 0..200 {
        let ap = mul(&a, &p);
        let apat = mul(&ap, &transpose(&a));
        let before = p[0][0];
        for i in 0..2 {
            for j in 0..2 {
                p[i][j] += apat[i][j];
            }
        }
        if !p[0][0].is_finite() {
            break;
        }
        if p[0][0] == before {
            return Ok(p[0][0]);
        }
        a = mul(&a, &a);
    }
    Err(DspError::out_of_range(
        "alpha, beta",
        format!("({alpha}, {beta}) at rho {rho}"),
        "gains whose mean filter A = F(I − ρKH) is stable",
    ))
}

fn mul(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let e = |i: usize, j: usize| a[i][0] * b[0][j] + a[i][1] * b[1][j];
    [[e(0, 0), e(0, 1)], [e(1, 0), e(1, 1)]]
}

fn transpose(a: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}

/// The output noise spectrum in units of σ² (the hold's F(ρ, ω) at α = 1, β = 0): the
/// noise floor is sqrt(π σ² F/N_eff) as eq. 12's.
pub fn noise_factor(alpha: f64, beta: f64, rho: f64, omega: f64) -> Result<f64, DspError> {
    let h = mean_response(alpha, beta, rho, omega)?;
    let c = innovation_depth_variance(alpha, beta, rho)?;
    let stab = 1.0 - rho * (1.0 - rho) * c;
    if stab.is_nan() || stab <= 0.0 {
        return Err(DspError::out_of_range(
            "alpha, beta",
            format!("({alpha}, {beta}) at rho {rho}"),
            "gains of a mean-square stable filter (ρ(1 − ρ)c < 1)",
        ));
    }
    Ok(h.norm_sqr() / (rho * stab))
}

/// SNR gain over the hold at equal response (dB): 10·log10((2 − ρ)(1 − ρ(1 − ρ)c)); its
/// bound as the gains vanish (c → 0) is 10·log10(2 − ρ).
pub fn snr_gain_over_hold_db(alpha: f64, beta: f64, rho: f64) -> Result<f64, DspError> {
    check(alpha, beta, rho)?;
    let c = innovation_depth_variance(alpha, beta, rho)?;
    Ok(10.0 * ((2.0 - rho) * (1.0 - rho * (1.0 - rho) * c)).log10())
}

/// The bound of any imputation's SNR gain over the hold: 10·log10(2 − ρ) dB.
pub fn snr_bound_db(rho: f64) -> f64 {
    10.0 * (2.0 - rho).log10()
}
