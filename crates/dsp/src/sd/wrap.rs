//! How clean a periodic ROM's wrap is, in the units that matter: the in-band error the
//! wrap adds to the replayed bitstream, against the in-band quantisation error the
//! modulator leaves anyway.
//!
//! A period cut from a running modulator starts in state s₀ and ends in s_L ≠ s₀. Write
//! the loop with its quantisation error e = v − y as an input:
//! x' = A_cl·x + (B₁ + B₂D₁)·u + B₂·e and v = C·x + D₁·u + e, with A_cl = A + B₂C
//! (eigenvalues = the NTF poles, inside the unit circle). Over one period the output error ε = v − u is the periodic steady
//! state's response to the (periodic) u and e — whose L-point DFT is exactly
//! NTF(z_k)·E_k, u passing with unity STF — plus the transient r_n = C·A_clⁿ·(s₀ − x*)
//! from the start state's distance to the periodic state x*. Since s_L − s₀ =
//! (A_clᴸ − I)(s₀ − x*), the transient's DFT is, exactly,
//!
//!   R_k = C·(I − A_cl·z_k⁻¹)⁻¹·δ,   δ = s₀ − s_L,   z_k = e^{j2πk/L},
//!
//! so the wrap's in-band energy Σ_{k<K} |R_k|² is the quadratic form δᵀQδ with
//! Q = Σ_{k<K} Re(g_kᴴ g_k), g_k = C(I − A_cl z_k⁻¹)⁻¹ (K = ⌈L/(2·OSR)⌉ in-band bins, DC
//! included). A mismatch in the last integrator, right before the quantiser, is shaped
//! like quantisation noise and costs almost nothing in band; one in the first integrator
//! passes like the input. The state mismatch alone (max |δ|) says neither: measured, the
//! default loop's δ ≈ 0.1 sits almost entirely in the last state and adds 10⁻⁵–10⁻³ of
//! the in-band noise, while an order-5 loop's δ of the same size can add 50%.

use super::realize::StateSpace;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;
use std::f64::consts::PI;

/// The wrap's in-band error for one modulator and period: δ ↦ δᵀQδ.
#[derive(Debug, Clone, PartialEq)]
pub struct WrapMetric {
    order: usize,
    /// Period L.
    pub period: usize,
    /// In-band bins K (0..K, DC included).
    pub band_bins: usize,
    /// Row-major order × order.
    q: Vec<f64>,
}

impl WrapMetric {
    /// Q for `ss` over a period of `period` samples with band edge f_s/(2·OSR).
    pub fn new(ss: &StateSpace, period: usize, osr: f64) -> Self {
        let n = ss.order;
        let band_bins = ((period as f64 / (2.0 * osr)).ceil() as usize).clamp(1, period);
        let acl = closed_loop(ss);
        let mut q = vec![0.0; n * n];
        for k in 0..band_bins {
            let g = transient_transfer(ss, &acl, k, period);
            for i in 0..n {
                for j in 0..n {
                    q[i * n + j] += (g[i].conj() * g[j]).re;
                }
            }
        }
        WrapMetric {
            order: n,
            period,
            band_bins,
            q,
        }
    }

    /// In-band energy (Σ_{k<K} |R_k|², unnormalised DFT units) of the transient a state
    /// mismatch δ = s₀ − s_L starts.
    pub fn energy(&self, delta: &[f64]) -> f64 {
        let n = self.order;
        let mut e = 0.0;
        for i in 0..n {
            for j in 0..n {
                e += delta[i] * self.q[i * n + j] * delta[j];
            }
        }
        e
    }

    /// The transient's in-band DFT R_k, k < K, for a mismatch δ (for tests and plots).
    pub fn transient_spectrum(&self, ss: &StateSpace, delta: &[f64]) -> Vec<Complex64> {
        let acl = closed_loop(ss);
        (0..self.band_bins)
            .map(|k| {
                transient_transfer(ss, &acl, k, self.period)
                    .iter()
                    .zip(delta)
                    .map(|(g, d)| g * d)
                    .sum()
            })
            .collect()
    }
}

/// The NTF the realised loop implements, 1 + C(zI − A_cl)⁻¹B₂. It equals the synthesised
/// NTF for zeros at DC; with optimised zeros the toolbox's CIFB resonator
/// [[1, −g], [c, 1]] puts them at 1 ± j√(g·c), just off the unit circle (|z| − 1 ≈ θ²/2),
/// so the realised in-band NTF differs from the synthesised one by a few percent.
pub fn realised_ntf(ss: &StateSpace, z: Complex64) -> Complex64 {
    let n = ss.order;
    let acl = closed_loop(ss);
    let mut m = vec![Complex64::new(0.0, 0.0); n * n];
    for r in 0..n {
        for c in 0..n {
            let id = if r == c { z } else { Complex64::new(0.0, 0.0) };
            m[r * n + c] = id - acl[r * n + c];
        }
    }
    let w = solve(
        n,
        m,
        ss.b2.iter().map(|&b| Complex64::new(b, 0.0)).collect(),
    );
    Complex64::new(1.0, 0.0) + w.iter().zip(&ss.c).map(|(w, c)| w * c).sum::<Complex64>()
}

/// A + B₂C: the loop with the quantiser replaced by y + e.
fn closed_loop(ss: &StateSpace) -> Vec<f64> {
    let n = ss.order;
    let mut acl = ss.a.clone();
    for r in 0..n {
        for c in 0..n {
            acl[r * n + c] += ss.b2[r] * ss.c[c];
        }
    }
    acl
}

/// g_k = C(I − A_cl z_k⁻¹)⁻¹ as a row, solved as (I − A_cl z⁻¹)ᵀ g_kᵀ = Cᵀ.
fn transient_transfer(ss: &StateSpace, acl: &[f64], k: usize, period: usize) -> Vec<Complex64> {
    let n = ss.order;
    let zinv = Complex64::from_polar(1.0, -2.0 * PI * k as f64 / period as f64);
    let mut m = vec![Complex64::new(0.0, 0.0); n * n];
    for r in 0..n {
        for c in 0..n {
            // Transposed: m[r][c] = (I − A_cl z⁻¹)[c][r].
            let id = if r == c { 1.0 } else { 0.0 };
            m[r * n + c] = Complex64::new(id, 0.0) - zinv * acl[c * n + r];
        }
    }
    let rhs: Vec<Complex64> = ss.c.iter().map(|&c| Complex64::new(c, 0.0)).collect();
    solve(n, m, rhs)
}

/// Gaussian elimination with partial pivoting (order ≤ 6; I − A_cl z⁻¹ is regular on the
/// unit circle because the NTF poles lie inside it).
fn solve(n: usize, mut m: Vec<Complex64>, mut b: Vec<Complex64>) -> Vec<Complex64> {
    for i in 0..n {
        let piv = (i..n)
            .max_by(|&a, &c| m[a * n + i].norm().total_cmp(&m[c * n + i].norm()))
            .unwrap_or(i);
        if piv != i {
            for c in 0..n {
                m.swap(i * n + c, piv * n + c);
            }
            b.swap(i, piv);
        }
        for r in i + 1..n {
            let f = m[r * n + i] / m[i * n + i];
            for c in i..n {
                let t = m[i * n + c];
                m[r * n + c] -= f * t;
            }
            let t = b[i];
            b[r] -= f * t;
        }
    }
    let mut x = vec![Complex64::new(0.0, 0.0); n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for c in i + 1..n {
            s -= m[i * n + c] * x[c];
        }
        x[i] = s / m[i * n + i];
    }
    x
}

/// In-band energy Σ_{k<K} |DFT(v − u)_k|² of one period of a ±1 stream `v` probing bin
/// `bin` at amplitude `amplitude` (I: cos, Q: sin, rectangular): the whole in-band error
/// of the replayed period, quantisation noise and wrap together. u's DFT is exact
/// (A·L/2 at bin k, phase 0 or −π/2), so only v is transformed.
pub fn inband_error_energy(
    v: impl Iterator<Item = bool>,
    period: usize,
    band_bins: usize,
    bin: u64,
    quadrature: bool,
    amplitude: f64,
) -> f64 {
    let mut buf: Vec<Complex64> = v
        .map(|b| Complex64::new(if b { 1.0 } else { -1.0 }, 0.0))
        .collect();
    debug_assert_eq!(buf.len(), period);
    FftPlanner::<f64>::new()
        .plan_fft_forward(period)
        .process(&mut buf);
    let half = amplitude * period as f64 / 2.0;
    let tone = if quadrature {
        Complex64::new(0.0, -half)
    } else {
        Complex64::new(half, 0.0)
    };
    buf[..band_bins.min(period)]
        .iter()
        .enumerate()
        .map(|(k, &x)| {
            if k as u64 == bin {
                (x - tone).norm_sqr()
            } else {
                x.norm_sqr()
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sd::{Modulator, realize_cifb, synthesize_ntf};

    /// The closed form judged against the definition: run a warmed-up modulator over one
    /// period, split the period's output error ε = v − u into the periodic part
    /// NTF(z_k)·E_k (NTF from the synthesised zeros and poles, E the DFT of the recorded
    /// quantiser error e = v − y) and the rest; the rest must be R_k = g_k·δ at every
    /// in-band bin, and its energy δᵀQδ. Tolerance: both sides are sums of L ≈ 10^4 terms
    /// of size ≈ 1 in f64, so agreement to 1e-9 of the largest |ε_k| is rounding.
    #[test]
    fn wrap_transient_matches_the_period_decomposition() {
        for (order, opt, l, k, amp) in [
            (3usize, false, 6000usize, 7u64, 0.5),
            (5, true, 4096, 3, 0.3),
            (3, true, 4096, 3, 0.5),
            (5, false, 4096, 3, 0.3),
            (4, false, 4096, 3, 0.4),
            (2, false, 4096, 3, 0.5),
            (2, true, 4096, 3, 0.5),
            (6, true, 4096, 3, 0.2),
        ] {
            let m = Modulator::design(order, 32.0, opt, 1.5).unwrap();
            let ntf = synthesize_ntf(order, 32.0, opt, 1.5).unwrap();
            // The realisation itself, judged by the synthesised NTF (see `realised_ntf`):
            // equal for zeros at DC; for optimised zeros, zeros at 1 ± j√(g·c).
            for f in [1e-4, 3e-3, 0.01, 0.1, 0.4] {
                let z = Complex64::from_polar(1.0, 2.0 * PI * f);
                let (re, sy) = (realised_ntf(&m.ss, z), ntf.eval(z));
                if !opt {
                    // |NTF| ≈ 1e-10 at 1e-4: the (z − 1)³ cancellation leaves ≈ 1e-16 absolute.
                    assert!(
                        (re - sy).norm() <= 1e-9 * sy.norm() + 1e-14,
                        "order {order} f {f}"
                    );
                }
            }
            if opt {
                let r = realize_cifb(&ntf);
                let odd = order % 2;
                for (i, g) in r.g.iter().enumerate() {
                    let z0 = Complex64::new(1.0, (g * r.c[odd + 2 * i]).sqrt());
                    let h = realised_ntf(&m.ss, z0).norm();
                    assert!(h < 1e-9, "order {order}: realised NTF({z0}) = {h}");
                }
            }
            let u: Vec<f64> = (0..l)
                .map(|n| amp * (2.0 * PI * ((k as usize * n) % l) as f64 / l as f64).cos())
                .collect();
            let mut x = m.zero_state();
            let mut v = vec![0.0; l];
            m.run(&u, &mut x, &mut v, amp, 0).unwrap(); // warm-up
            let s0 = x.clone();
            let mut e = vec![0.0; l];
            let mut one = [0.0];
            for n in 0..l {
                let y = m.ss.d1 * u[n] + m.ss.c.iter().zip(&x).map(|(c, s)| c * s).sum::<f64>();
                m.run(&u[n..n + 1], &mut x, &mut one, amp, 0).unwrap();
                v[n] = one[0];
                e[n] = one[0] - y;
            }
            let delta: Vec<f64> = s0.iter().zip(&x).map(|(a, b)| a - b).collect();
            let dft = |s: &[f64]| {
                let mut b: Vec<Complex64> = s.iter().map(|&t| Complex64::new(t, 0.0)).collect();
                FftPlanner::<f64>::new().plan_fft_forward(l).process(&mut b);
                b
            };
            let eps: Vec<f64> = v.iter().zip(&u).map(|(a, b)| a - b).collect();
            let (ek, qk) = (dft(&eps), dft(&e));
            let metric = WrapMetric::new(&m.ss, l, 32.0);
            assert_eq!(metric.band_bins, l.div_ceil(64));
            let r = metric.transient_spectrum(&m.ss, &delta);
            let scale = ek[..metric.band_bins]
                .iter()
                .map(|c| c.norm())
                .fold(0.0, f64::max);
            let mut energy = 0.0;
            let mut worst = 0.0f64;
            for kk in 0..metric.band_bins {
                let z = Complex64::from_polar(1.0, 2.0 * PI * kk as f64 / l as f64);
                let rest = ek[kk] - realised_ntf(&m.ss, z) * qk[kk];
                worst = worst.max((rest - r[kk]).norm() / scale);
                energy += r[kk].norm_sqr();
            }
            assert!(
                worst <= 1e-9,
                "order {order} opt {opt}: {worst:e} of the largest |ε_k|"
            );
            let q = metric.energy(&delta);
            assert!(
                (q - energy).abs() <= 1e-9 * energy.max(1e-30),
                "{q} vs {energy}"
            );
            // Third order and up never lock onto the period, so the transient is real
            // (second order at this L happens to: δ ≈ 1e-10, and R ≈ 0 on both sides).
            if order >= 3 {
                assert!(delta.iter().any(|d| d.abs() > 1e-3), "order {order} locked");
            }
        }
    }

    /// A mismatch in the last integrator (next to the quantiser) is shaped like
    /// quantisation noise; the same mismatch in the first passes like the input: the
    /// metric must weigh them orders of magnitude apart, as the module docs say.
    #[test]
    fn first_integrator_mismatch_costs_far_more_than_the_last() {
        let m = Modulator::design(3, 32.0, false, 1.5).unwrap();
        let metric = WrapMetric::new(&m.ss, 20_000, 32.0);
        let first = metric.energy(&[0.1, 0.0, 0.0]);
        let last = metric.energy(&[0.0, 0.0, 0.1]);
        assert!(first > 1e3 * last, "first {first}, last {last}");
        assert!(last > 0.0);
    }
}
