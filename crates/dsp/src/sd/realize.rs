//! CIFB (cascade of integrators, feedback) realisation of an NTF with unity STF, and its
//! state-space (ABCD) form, following the toolbox's `realizeNTF(ntf, 'CIFB')` and
//! `stuffABCD(a, g, b, c, 'CIFB')`.
//!
//! The loop filter L1 = 1 − 1/NTF is matched at 2·order points z = 1.1·e^{j2πi/200}
//! (i = 1, 2, …, skipping points within 0.09 of a zero) by least squares; the system is
//! consistent, so the solution is exact and real.

use super::ntf::{Ntf, eval_roots};
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// CIFB coefficients: feedback `a` (order), resonator `g` (order/2), input feed-ins `b`
/// (order + 1; unity STF: b = [a, 1]), integrator gains `c` (order, all 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Cifb {
    pub a: Vec<f64>,
    pub g: Vec<f64>,
    pub b: Vec<f64>,
    pub c: Vec<f64>,
}

/// Realises `ntf` as a CIFB structure with unity STF.
pub fn realize_cifb(ntf: &Ntf) -> Cifb {
    let order = ntf.order();
    let order2 = order / 2;
    let odd = order % 2;
    // The toolbox forces the zeros onto Re z = 1 for CIFB (resonators give z = 1 ± j√g).
    let zeros: Vec<Complex64> = ntf
        .zeros
        .iter()
        .map(|z| Complex64::new(1.0, z.im))
        .collect();
    let g: Vec<f64> = (0..order2).map(|i| zeros[2 * i + odd].im.powi(2)).collect();

    let points: Vec<Complex64> = (1..=200)
        .map(|i| Complex64::from_polar(1.1, 2.0 * PI * i as f64 / 200.0))
        .filter(|z| zeros.iter().all(|q| (q - z).norm() > 0.09))
        .take(2 * order)
        .collect();

    // Rows: Re and Im of Σ_j a_j T[j](z) = −L1(z) at every point.
    let mut rows: Vec<Vec<f64>> = Vec::with_capacity(4 * order);
    let mut rhs: Vec<f64> = Vec::with_capacity(4 * order);
    for &z in &points {
        let l1 = 1.0 - eval_roots(&ntf.poles, z) / eval_roots(&zeros, z);
        let mut t = vec![Complex64::new(0.0, 0.0); order];
        let dfactor = z - 1.0;
        let mut product = Complex64::new(1.0, 0.0);
        let mut j = order as isize - 1;
        while j > odd as isize {
            let ju = j as usize;
            product /= eval_roots(&zeros[ju - 1..ju + 1], z);
            t[ju] = product * dfactor;
            t[ju - 1] = product;
            j -= 2;
        }
        if odd == 1 {
            t[0] = product / (z - 1.0);
        }
        rows.push(t.iter().map(|v| v.re).collect());
        rhs.push(-l1.re);
        rows.push(t.iter().map(|v| v.im).collect());
        rhs.push(-l1.im);
    }
    let a = least_squares(rows, rhs);
    let mut b = a.clone();
    b.push(1.0);
    Cifb {
        a,
        g,
        b,
        c: vec![1.0; order],
    }
}

/// Householder-QR least squares for a small dense system (rows ≥ columns).
// Index loops mirror the textbook algorithm; iterator chains over two axes would hide it.
#[allow(clippy::needless_range_loop)]
fn least_squares(mut m: Vec<Vec<f64>>, mut y: Vec<f64>) -> Vec<f64> {
    let rows = m.len();
    let cols = m[0].len();
    for k in 0..cols {
        let norm = (k..rows).map(|i| m[i][k] * m[i][k]).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        let alpha = if m[k][k] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (k..rows).map(|i| m[i][k]).collect();
        v[0] -= alpha;
        let vnorm2: f64 = v.iter().map(|x| x * x).sum();
        if vnorm2 == 0.0 {
            continue;
        }
        for j in k..cols {
            let s: f64 = (k..rows).map(|i| v[i - k] * m[i][j]).sum::<f64>() * 2.0 / vnorm2;
            for i in k..rows {
                m[i][j] -= s * v[i - k];
            }
        }
        let s: f64 = (k..rows).map(|i| v[i - k] * y[i]).sum::<f64>() * 2.0 / vnorm2;
        for i in k..rows {
            y[i] -= s * v[i - k];
        }
    }
    let mut x = vec![0.0; cols];
    for k in (0..cols).rev() {
        let s: f64 = (k + 1..cols).map(|j| m[k][j] * x[j]).sum();
        x[k] = if m[k][k] != 0.0 {
            (y[k] - s) / m[k][k]
        } else {
            0.0
        };
    }
    x
}

/// State-space form x\[n+1\] = A x\[n\] + B1 u\[n\] + B2 v\[n\], y\[n\] = C x\[n\] + D1 u\[n\], with the
/// quantiser v\[n\] = sign(y\[n\]) (+1 at y = 0, as the toolbox's `ds_quantize`).
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    pub order: usize,
    /// Row-major order × order.
    pub a: Vec<f64>,
    pub b1: Vec<f64>,
    pub b2: Vec<f64>,
    pub c: Vec<f64>,
    pub d1: f64,
}

impl StateSpace {
    /// `stuffABCD(a, g, b, c, 'CIFB')`.
    pub fn from_cifb(k: &Cifb) -> Self {
        let n = k.a.len();
        let odd = n % 2;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 1.0;
            if i + 1 < n {
                a[(i + 1) * n + i] = k.c[i];
            }
        }
        // Resonator feedback −g from state i+1 into state i, i = odd, odd+2, …
        for (gi, i) in (odd..n.saturating_sub(1)).step_by(2).enumerate() {
            if gi < k.g.len() {
                a[i * n + i + 1] = -k.g[gi];
            }
        }
        let mut c = vec![0.0; n];
        c[n - 1] = k.c[n - 1];
        StateSpace {
            order: n,
            a,
            b1: k.b[..n].to_vec(),
            b2: k.a.iter().map(|v| -v).collect(),
            c,
            d1: k.b[n],
        }
    }

    /// The nonzero entries of A as (row, column, value), for sparse inner loops.
    pub fn a_entries(&self) -> Vec<(usize, usize, f64)> {
        let n = self.order;
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let v = self.a[i * n + j];
                if v != 0.0 {
                    out.push((i, j, v));
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::ntf::{Ntf, synthesize_ntf};
    use super::*;

    fn close(got: &[f64], want: &[f64]) {
        assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
        for (g, w) in got.iter().zip(want) {
            // The toolbox digits are rounded to 1e-10; allow 1e-6.
            assert!((g - w).abs() < 1e-6, "{got:?} vs {want:?}");
        }
    }

    #[test]
    fn cifb_matches_toolbox_dc_zeros() {
        let k = realize_cifb(&synthesize_ntf(3, 32.0, false, 1.5).unwrap());
        close(&k.a, &[0.0439826180, 0.2881356970, 0.7997388607]);
        close(&k.b, &[0.0439826180, 0.2881356970, 0.7997388607, 1.0]);
        close(&k.g, &[0.0]);
    }

    #[test]
    fn cifb_matches_toolbox_optimised_zeros() {
        let k = realize_cifb(&synthesize_ntf(3, 32.0, true, 1.5).unwrap());
        close(&k.a, &[0.0443873867, 0.2842562417, 0.8025105853]);
        close(&k.g, &[0.0057718323]);
    }

    /// The realised loop must reproduce the NTF: with the linearised quantiser (v = y + e)
    /// the transfer from e to v is (I think of it as) 1/(1 − C(zI − A)^{-1}B2); compare it
    /// with the synthesised NTF at a few points for every order.
    #[test]
    fn state_space_reproduces_the_ntf() {
        for order in 1..=6 {
            for opt in [false, true] {
                let ntf = synthesize_ntf(order, 16.0, opt, 1.5).unwrap();
                let ss = StateSpace::from_cifb(&realize_cifb(&ntf));
                for f in [0.001, 0.05, 0.2, 0.45] {
                    let z = Complex64::from_polar(1.0, 2.0 * PI * f);
                    let l = loop_gain(&ss, z);
                    let h = 1.0 / (1.0 - l);
                    // CIFB places its zeros at 1 ± j√g: the NTF it realises has the
                    // synthesised zeros moved onto Re z = 1 (exactly, for opt = 0).
                    let moved = Ntf {
                        zeros: ntf
                            .zeros
                            .iter()
                            .map(|q| Complex64::new(1.0, q.im))
                            .collect(),
                        poles: ntf.poles.clone(),
                    };
                    let want = moved.eval(z);
                    assert!(
                        (h - want).norm() < 1e-6 * want.norm().max(1e-3),
                        "{order} {f}"
                    );
                }
            }
        }
    }

    /// C (zI − A)^{-1} B2 by Gaussian elimination (the independent reference).
    #[allow(clippy::needless_range_loop)]
    fn loop_gain(ss: &StateSpace, z: Complex64) -> Complex64 {
        let n = ss.order;
        let mut m: Vec<Vec<Complex64>> = (0..n)
            .map(|i| {
                let mut r: Vec<Complex64> = (0..n)
                    .map(|j| {
                        let d = if i == j { z } else { Complex64::new(0.0, 0.0) };
                        d - ss.a[i * n + j]
                    })
                    .collect();
                r.push(Complex64::new(ss.b2[i], 0.0));
                r
            })
            .collect();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&x, &y| m[x][k].norm().total_cmp(&m[y][k].norm()))
                .unwrap();
            m.swap(k, p);
            for i in k + 1..n {
                let f = m[i][k] / m[k][k];
                for j in k..=n {
                    let t = m[k][j];
                    m[i][j] -= f * t;
                }
            }
        }
        let mut x = vec![Complex64::new(0.0, 0.0); n];
        for k in (0..n).rev() {
            let s: Complex64 = (k + 1..n).map(|j| m[k][j] * x[j]).sum();
            x[k] = (m[k][n] - s) / m[k][k];
        }
        (0..n).map(|i| x[i] * ss.c[i]).sum()
    }
}
