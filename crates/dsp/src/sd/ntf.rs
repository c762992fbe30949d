//! Noise-transfer-function synthesis for a lowpass two-level ΣΔ modulator.
//!
//! This follows the standard toolbox (python-deltasigma `synthesizeNTF0`, itself a port of
//! Schreier's MATLAB `synthesizeNTF`) step for step, so its published numbers are ours to
//! 1e-6: the zeros sit at DC (or at the in-band-noise-optimal `ds_optzeros` angles), and
//! the poles are the maximally flat (Butterworth-like) set scaled by a secant iteration on
//! one parameter until the out-of-band gain |NTF(−1)| equals H_inf (the Lee criterion).

use crate::error::DspError;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// Highest modulator order supported (the CIFB realisation and stability sweeps are
/// validated up to here; the toolbox's optimal-zero table goes further).
pub const MAX_ORDER: usize = 6;
/// Lowest oversampling ratio accepted: below this a lowpass NTF has no useful band.
pub const MIN_OSR: f64 = 4.0;

/// A noise transfer function in zero/pole form with unity gain at z = ∞ (k = 1).
///
/// `zeros` are ordered reals first, then conjugate pairs (negative imaginary part first)
/// by increasing angle: the order `realizeNTF` assigns them to resonators.
#[derive(Debug, Clone, PartialEq)]
pub struct Ntf {
    pub zeros: Vec<Complex64>,
    pub poles: Vec<Complex64>,
}

impl Ntf {
    /// Modulator order (number of poles).
    pub fn order(&self) -> usize {
        self.poles.len()
    }

    /// NTF(z) = Π(z − z_i) / Π(z − p_i).
    pub fn eval(&self, z: Complex64) -> Complex64 {
        eval_roots(&self.zeros, z) / eval_roots(&self.poles, z)
    }

    /// |NTF(e^{j2πf})| at a normalised frequency f = f_Hz / f_s.
    pub fn gain_at(&self, f_norm: f64) -> f64 {
        self.eval(Complex64::from_polar(1.0, 2.0 * PI * f_norm))
            .norm()
    }
}

/// Π(z − r_i): the toolbox's `evalRPoly` with unit leading coefficient.
pub fn eval_roots(roots: &[Complex64], z: Complex64) -> Complex64 {
    roots
        .iter()
        .fold(Complex64::new(1.0, 0.0), |acc, r| acc * (z - r))
}

/// The toolbox's `ds_optzeros(n, 1)`: zero positions, as fractions of the band edge angle
/// π/OSR, that minimise the in-band noise (roots of Legendre polynomials).
fn optimal_zero_fractions(order: usize) -> Vec<f64> {
    let s = f64::sqrt;
    let half: Vec<f64> = match order {
        1 => vec![0.0],
        2 => vec![s(1.0 / 3.0)],
        3 => vec![s(3.0 / 5.0), 0.0],
        4 => vec![
            s(3.0 / 7.0 + s(9.0 / 49.0 - 3.0 / 35.0)),
            s(3.0 / 7.0 - s(9.0 / 49.0 - 3.0 / 35.0)),
        ],
        5 => vec![
            s(5.0 / 9.0 + s(25.0 / 81.0 - 5.0 / 21.0)),
            s(5.0 / 9.0 - s(25.0 / 81.0 - 5.0 / 21.0)),
            0.0,
        ],
        // The toolbox tabulates order 6 to 8 digits (Gauss–Legendre nodes).
        _ => vec![0.23862059, 0.66120988, 0.9324696],
    };
    let mut z = half;
    z.sort_by(f64::total_cmp);
    let mut out = Vec::with_capacity(order);
    let mut rest = &z[..];
    if order % 2 == 1 {
        out.push(z[0]);
        rest = &z[1..];
    }
    for &v in rest {
        out.push(v);
        out.push(-v);
    }
    out
}

/// Validates the design parameters shared by synthesis and configuration.
pub fn validate_design(order: usize, osr: f64, h_inf: f64) -> Result<(), DspError> {
    if !(1..=MAX_ORDER).contains(&order) {
        return Err(DspError::out_of_range(
            "probe.order",
            order,
            format!("1..={MAX_ORDER}"),
        ));
    }
    if !osr.is_finite() || osr < MIN_OSR {
        return Err(DspError::out_of_range(
            "probe.osr",
            tofprobe_io::text::number(osr),
            format!(">= {MIN_OSR}"),
        ));
    }
    let limit = (1u32 << order) as f64;
    if !h_inf.is_finite() || h_inf <= 1.0 || h_inf >= limit {
        return Err(DspError::out_of_range(
            "probe.h_inf",
            tofprobe_io::text::number(h_inf),
            format!("1 < h_inf < 2^order = {limit}"),
        )
        .with_hint("1.5 is the Lee criterion for a two-level quantiser"));
    }
    Ok(())
}

/// Synthesises a lowpass NTF: `synthesizeNTF(order, osr, opt, H_inf, f0 = 0)` with
/// opt = 0 (`optimised = false`, all zeros at DC) or opt = 1 (optimised zeros).
pub fn synthesize_ntf(
    order: usize,
    osr: f64,
    optimised: bool,
    h_inf: f64,
) -> Result<Ntf, DspError> {
    validate_design(order, osr, h_inf)?;
    let dw = PI / osr;
    let angles: Vec<f64> = if optimised {
        optimal_zero_fractions(order)
            .into_iter()
            .map(|f| f * dw)
            .collect()
    } else {
        vec![0.0; order]
    };
    let zeros: Vec<Complex64> = angles
        .iter()
        .map(|&a| Complex64::from_polar(1.0, a))
        .collect();

    // Secant iteration on x (the toolbox's, including its start, step and stopping rule).
    let n = order as f64;
    let mut x = 0.3f64.powi(order as i32 - 1);
    let mut fprev = 0.0;
    let mut delta_x = 0.0;
    let mut poles = vec![Complex64::new(0.0, 0.0); order];
    let mut converged = false;
    for itn in 1..=100 {
        let me2 = -0.5 * x.powf(2.0 / n);
        for (i, p) in poles.iter_mut().enumerate() {
            let w = (2.0 * (i as f64 + 1.0) + 1.0) * PI / n;
            let mb2 = Complex64::new(1.0, 0.0) + Complex64::from_polar(me2, w);
            let mut v = mb2 - (mb2 * mb2 - 1.0).sqrt();
            if v.norm() > 1.0 {
                v = 1.0 / v;
            }
            *p = v;
        }
        let m1 = Complex64::new(-1.0, 0.0);
        let f = (eval_roots(&zeros, m1) / eval_roots(&poles, m1)).re - h_inf;
        delta_x = if itn == 1 {
            -f / 100.0
        } else {
            -f * delta_x / (f - fprev)
        };
        let xplus = x + delta_x;
        x = if xplus > 0.0 { xplus } else { x * 0.1 };
        fprev = f;
        if f.abs() < 1e-10 || delta_x.abs() < 1e-10 {
            converged = true;
            break;
        }
        if x > 1e6 {
            break;
        }
    }
    if !converged {
        return Err(DspError::out_of_range(
            "probe.h_inf",
            tofprobe_io::text::number(h_inf),
            format!("a value the order-{order}, OSR-{osr} NTF can reach"),
        )
        .with_hint("the pole iteration did not converge; lower h_inf"));
    }
    Ok(Ntf {
        zeros: order_zeros(zeros),
        poles: pair_sort(poles),
    })
}

/// Reals first, then conjugate pairs by increasing |angle| (negative imaginary first).
fn order_zeros(mut z: Vec<Complex64>) -> Vec<Complex64> {
    for v in z.iter_mut() {
        if v.im.abs() < 1e-12 {
            v.im = 0.0;
        }
    }
    z.sort_by(|a, b| {
        let ka = (a.im != 0.0, a.im.abs(), a.im);
        let kb = (b.im != 0.0, b.im.abs(), b.im);
        ka.partial_cmp(&kb).unwrap_or(std::cmp::Ordering::Equal)
    });
    z
}

/// Poles in a stable presentation order: conjugate pairs (by real part), then reals.
fn pair_sort(mut p: Vec<Complex64>) -> Vec<Complex64> {
    for v in p.iter_mut() {
        if v.im.abs() < 1e-12 * v.norm().max(1.0) {
            v.im = 0.0;
        }
    }
    p.sort_by(|a, b| {
        let ka = (a.im == 0.0, a.re, a.im);
        let kb = (b.im == 0.0, b.re, b.im);
        ka.partial_cmp(&kb).unwrap_or(std::cmp::Ordering::Equal)
    });
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_roots(got: &[Complex64], want: &[(f64, f64)]) {
        // Every wanted root must be matched by a distinct synthesised one to 1e-6 (the
        // issue's digits are rounded to 1e-10, the toolbox converges to |f| < 1e-10).
        let mut used = vec![false; got.len()];
        for &(re, im) in want {
            let i = (0..got.len())
                .find(|&i| !used[i] && (got[i] - Complex64::new(re, im)).norm() < 1e-6)
                .unwrap_or_else(|| panic!("root {re}+{im}j not in {got:?}"));
            used[i] = true;
        }
        assert_eq!(got.len(), want.len());
    }

    #[test]
    fn matches_toolbox_order3_osr32_dc_zeros() {
        let ntf = synthesize_ntf(3, 32.0, false, 1.5).unwrap();
        assert_roots(&ntf.zeros, &[(1.0, 0.0), (1.0, 0.0), (1.0, 0.0)]);
        assert_roots(
            &ntf.poles,
            &[
                (0.7654312939, 0.2793129269),
                (0.7654312939, -0.2793129269),
                (0.6693985515, 0.0),
            ],
        );
        // The defining property: out-of-band gain H_inf at z = −1.
        assert!((ntf.gain_at(0.5) - 1.5).abs() < 1e-9);
    }

    #[test]
    fn matches_toolbox_order3_osr32_optimised_zeros() {
        let ntf = synthesize_ntf(3, 32.0, true, 1.5).unwrap();
        assert_roots(
            &ntf.zeros,
            &[
                (1.0, 0.0),
                (0.9971099075, 0.0759725762),
                (0.9971099075, -0.0759725762),
            ],
        );
        assert_roots(
            &ntf.poles,
            &[
                (0.7645146348, 0.2800520473),
                (0.7645146348, -0.2800520473),
                (0.6684601451, 0.0),
            ],
        );
    }

    #[test]
    fn every_supported_design_reaches_its_h_inf() {
        for order in 1..=6 {
            for osr in [4.0, 8.0, 32.0, 128.0] {
                for opt in [false, true] {
                    let ntf = synthesize_ntf(order, osr, opt, 1.5).unwrap();
                    assert!((ntf.gain_at(0.5) - 1.5).abs() < 1e-8, "{order} {osr} {opt}");
                    assert!(ntf.poles.iter().all(|p| p.norm() < 1.0));
                }
            }
        }
    }

    #[test]
    fn rejects_bad_designs_with_the_range() {
        let e = synthesize_ntf(0, 32.0, false, 1.5).unwrap_err().to_string();
        assert!(e.contains("probe.order") && e.contains("1..=6"), "{e}");
        assert!(synthesize_ntf(7, 32.0, false, 1.5).is_err());
        let e = synthesize_ntf(3, 3.0, false, 1.5).unwrap_err().to_string();
        assert!(e.contains("probe.osr") && e.contains(">= 4"), "{e}");
        let e = synthesize_ntf(3, 32.0, false, 1.0).unwrap_err().to_string();
        assert!(e.contains("probe.h_inf"), "{e}");
        assert!(synthesize_ntf(1, 32.0, false, 2.0).is_err());
    }
}
