//! Missing-pulse imputation of the one float front end ([`crate::preprocess::FrontEnd`]):
//! the pixel's 1NN hold, and beyond the paper (its own future work) a motion model — a
//! constant-velocity Kalman filter on [depth, velocity], and its fixed-gain (α-β) form,
//! which is what a pixel could build.
//!
//! # The model (per pulse, T = 1 pulse)
//! State x = [d, v] (mm, mm/pulse), F = [[1, 1], [0, 1]], measurement z = d + w with
//! Var w = R = σ_w². Process noise: a piecewise-constant white acceleration of sd σ_a
//! (mm/pulse²), Q = σ_a²·[[1/4, 1/2], [1/2, 1]] (Kalata's model, whose steady state is
//! the α-β filter of [`response::steady_state_gains`]). Per pulse: predict (x = F x,
//! P = F P Fᵀ + Q); a detected pulse is a measurement update (Joseph form, which keeps P
//! symmetric and positive in f64), a missed pulse is the prediction alone; the output is
//! the depth after the update, fed to the same prefilter/DFT path as the hold's.
//!
//! # Priming
//! Pulses before the first detection output 0 (as the hold: the pixel accumulates nothing
//! before it primes). The first detection z₀ starts x = [z₀, 0], P = diag(R, R/pulse²):
//! the depth known to one measurement's sd, the velocity uninformative (a velocity that
//! moves the depth by one measurement sd per pulse, ≫ any vibration's A·ω), so the second
//! detection is never gated away and the velocity is learnt from the data.
//!
//! # The gate (background)
//! Background photons are uniform over the timing window: not Gaussian noise around the
//! depth but outliers, which a Kalman filter would follow with its full gain. A detection
//! whose innovation ν = z − d̂ has |ν| > k·sqrt(S) (S = P_dd + R, the innovation's
//! variance) is treated as a miss. k = 3 ([`DEFAULT_GATE_SD`]) rejects 0.27 % of the
//! signal's detections and, in a 60 mm window around a 7.5 mm-sd signal, ≈ 25 % of the
//! background. The α-β form gates at the steady-state S = R/(1 − α) once it has settled
//! ([`AlphaBeta`]).
//!
//! # Defaults from the scene's physics ([`KalmanParams::from_scene`])
//! σ_w = σ_s, the depth noise of one detection (jitter and TDC LSB, a²/12); σ_a = A·ω², the
//! peak acceleration of the scene's vibration (A mm at ω = 2π·f/f_s rad/pulse). This is
//! the filter that minimises the depth's mean-square error for that motion; with a tone
//! far below the noise of one detection (Table 2: 0.1 mm in 7.5 mm) its bandwidth,
//! ≈ (σ_a/σ_w)^½ rad/pulse, falls below the tone: it attenuates the tone and the noise
//! alike ([`response`] gives both in closed form for the fixed-gain form).

pub mod response;
#[cfg(test)]
mod tests;

use crate::error::DspError;

/// The gate's default width in innovation sds (0.27 % of Gaussian detections rejected).
pub const DEFAULT_GATE_SD: f64 = 3.0;

/// How a missed pulse is filled.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Imputation {
    /// The pixel's 1NN hold: the last detected depth is repeated.
    #[default]
    Hold,
    /// The constant-velocity Kalman filter (covariance tracked per pulse).
    Kalman(KalmanParams),
    /// The fixed-gain constant-velocity filter (a pixel's form: two constant gains).
    AlphaBeta(AlphaBeta),
}

/// The Kalman filter's noise model (mm and pulses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanParams {
    /// σ_a: sd of the piecewise-constant acceleration, mm/pulse² (≥ 0).
    pub process_noise: f64,
    /// σ_w: sd of one detection's depth, mm (> 0).
    pub measurement_noise: f64,
    /// k: detections with |innovation| > k·sqrt(S) are treated as misses (> 0; ∞: none).
    pub gate_sd: f64,
}

impl KalmanParams {
    /// The scene's physics: σ_w = σ_s, σ_a = A·ω² (A mm, ω rad/pulse), the default gate.
    pub fn from_scene(sigma_s_mm: f64, amplitude_mm: f64, omega: f64) -> Self {
        KalmanParams {
            process_noise: amplitude_mm.abs() * omega * omega,
            measurement_noise: sigma_s_mm,
            gate_sd: DEFAULT_GATE_SD,
        }
    }

    fn check(&self) -> Result<(), DspError> {
        let p = self.process_noise;
        if !(p.is_finite() && p >= 0.0) {
            return Err(DspError::out_of_range(
                "process_noise",
                p,
                "finite, ≥ 0 mm/pulse²",
            ));
        }
        let m = self.measurement_noise;
        if !(m.is_finite() && m > 0.0) {
            return Err(DspError::out_of_range(
                "measurement_noise",
                m,
                "finite, > 0 mm",
            ));
        }
        if self.gate_sd.is_nan() || self.gate_sd <= 0.0 {
            return Err(DspError::out_of_range(
                "gate_sd",
                self.gate_sd,
                "> 0 (∞: no gate)",
            ));
        }
        Ok(())
    }
}

/// The fixed-gain form: d += v each pulse; on a detection d += α·ν, v += β·ν.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaBeta {
    /// Depth gain α (0 < α ≤ 1).
    pub alpha: f64,
    /// Velocity gain β (1/pulse, 0 ≤ β < 1).
    pub beta: f64,
    /// Gate (mm): |ν| above it is a miss, applied from the [`AlphaBeta::settle`]-th
    /// detection on (before, the state is still far from the depth and a gate could lock
    /// it onto background). ∞: no gate.
    pub gate_mm: f64,
}

impl AlphaBeta {
    /// The steady state of the Kalman filter `k` at detection rate ρ, each gain rounded to
    /// the nearest power of two (a shift in a pixel): Kalata's gains at the mean
    /// detection interval T = 1/ρ (λ = σ_a·T²/σ_w), α = α_T and β = β_T/T per pulse;
    /// the gate k·σ_w/sqrt(1 − α) (the steady-state innovation sd).
    pub fn from_kalman(k: &KalmanParams, rho: f64) -> Result<Self, DspError> {
        k.check()?;
        if !(rho > 0.0 && rho <= 1.0) {
            return Err(DspError::out_of_range("rho", rho, "0 < ρ ≤ 1"));
        }
        let t = 1.0 / rho;
        let lambda = k.process_noise * t * t / k.measurement_noise;
        let (a, b) = response::steady_state_gains(lambda);
        let alpha = pow2_round(a);
        let beta = if b > 0.0 { pow2_round(b / t) } else { 0.0 };
        let gate_mm = if alpha < 1.0 {
            k.gate_sd * k.measurement_noise / (1.0 - alpha).sqrt()
        } else {
            f64::INFINITY
        };
        let g = AlphaBeta {
            alpha,
            beta,
            gate_mm,
        };
        // σ_a = 0 gives α = 0: a filter that never moves (refused, naming α).
        g.check()?;
        Ok(g)
    }

    /// Detections before the gate applies: ⌈1/α⌉, the depth's settling time in
    /// detections (α = 1: the gate from the second detection on).
    pub fn settle(&self) -> u64 {
        (1.0 / self.alpha).ceil() as u64
    }

    fn check(&self) -> Result<(), DspError> {
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(DspError::out_of_range("alpha", self.alpha, "0 < α ≤ 1"));
        }
        if !(0.0..1.0).contains(&self.beta) {
            return Err(DspError::out_of_range("beta", self.beta, "0 ≤ β < 1"));
        }
        if self.gate_mm.is_nan() || self.gate_mm <= 0.0 {
            return Err(DspError::out_of_range(
                "gate_mm",
                self.gate_mm,
                "> 0 (∞: no gate)",
            ));
        }
        Ok(())
    }
}

/// 2^round(log2 x) for x > 0.
pub fn pow2_round(x: f64) -> f64 {
    x.log2().round().exp2()
}

impl Imputation {
    /// The parameters' check (names the field and its range).
    pub fn check(&self) -> Result<(), DspError> {
        match self {
            Imputation::Hold => Ok(()),
            Imputation::Kalman(k) => k.check(),
            Imputation::AlphaBeta(g) => g.check(),
        }
    }
}

/// The imputer's state: the depth it outputs for the current pulse, once primed.
#[derive(Debug, Clone)]
pub(crate) struct Imputer {
    kind: Imputation,
    /// [d, v] after the last pulse.
    x: [f64; 2],
    /// P as (P_dd, P_dv, P_vv).
    p: [f64; 3],
    /// Detections accepted (the α-β gate's settling count).
    accepted: u64,
    primed: bool,
}

impl Imputer {
    pub(crate) fn new(kind: Imputation) -> Self {
        Imputer {
            kind,
            x: [0.0; 2],
            p: [0.0; 3],
            accepted: 0,
            primed: false,
        }
    }

    /// One pulse: `Some(depth)` once primed (the imputed depth of this pulse), else None.
    #[inline]
    pub(crate) fn step(&mut self, detection: Option<f64>) -> Option<f64> {
        if !self.primed {
            let z = detection?;
            self.primed = true;
            self.accepted = 1;
            self.x = [z, 0.0];
            if let Imputation::Kalman(k) = self.kind {
                let r = k.measurement_noise * k.measurement_noise;
                self.p = [r, 0.0, r];
            }
            return Some(z);
        }
        match self.kind {
            Imputation::Hold => {
                if let Some(z) = detection {
                    self.x[0] = z;
                }
            }
            Imputation::Kalman(k) => self.kalman(&k, detection),
            Imputation::AlphaBeta(g) => {
                self.x[0] += self.x[1];
                if let Some(z) = detection {
                    let nu = z - self.x[0];
                    if self.accepted < g.settle() || nu.abs() <= g.gate_mm {
                        self.accepted += 1;
                        self.x[0] += g.alpha * nu;
                        self.x[1] += g.beta * nu;
                    }
                }
            }
        }
        Some(self.x[0])
    }

    /// Whether a detection has been seen.
    #[inline]
    pub(crate) fn primed(&self) -> bool {
        self.primed
    }

    /// The imputed depth after the last pulse (0 before priming).
    #[inline]
    pub(crate) fn depth(&self) -> f64 {
        self.x[0]
    }

    /// The Kalman filter's predict and (gated) update.
    #[inline]
    fn kalman(&mut self, k: &KalmanParams, detection: Option<f64>) {
        let q = k.process_noise * k.process_noise;
        let [dd, dv, vv] = self.p;
        self.x[0] += self.x[1];
        // F P Fᵀ + Q.
        let (dd, dv, vv) = (dd + 2.0 * dv + vv + 0.25 * q, dv + vv + 0.5 * q, vv + q);
        self.p = [dd, dv, vv];
        let Some(z) = detection else { return };
        let r = k.measurement_noise * k.measurement_noise;
        let s = dd + r;
        let nu = z - self.x[0];
        if nu.abs() > k.gate_sd * s.sqrt() {
            return;
        }
        let (k0, k1) = (dd / s, dv / s);
        self.x[0] += k0 * nu;
        self.x[1] += k1 * nu;
        // Joseph: (I − KH) P (I − KH)ᵀ + K R Kᵀ.
        let a = 1.0 - k0;
        self.p = [
            a * a * dd + k0 * k0 * r,
            a * (dv - k1 * dd) + k0 * k1 * r,
            k1 * k1 * dd - 2.0 * k1 * dv + vv + k1 * k1 * r,
        ];
        self.accepted += 1;
    }

    /// The state [d, v] and covariance (P_dd, P_dv, P_vv) after the last pulse (tests).
    #[cfg(test)]
    pub(crate) fn state(&self) -> ([f64; 2], [f64; 3]) {
        (self.x, self.p)
    }
}
