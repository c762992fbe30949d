//! The standard normal by Marsaglia & Tsang's ziggurat (J. Stat. Softw. 5(8), 2000), 256
//! layers, split for batches: a branch-free fast pass over a whole batch of 64-bit words
//! (one word per sample: 8 bits pick the layer, 52 bits the abscissa) that accepts the
//! ≈ 99.3 % of samples lying inside their layer's inner rectangle, and an exact scalar
//! finish of the rest (the wedge test, the tail beyond R, and a fresh ziggurat draw when
//! the wedge rejects). The pair is the ziggurat algorithm exactly, so the law is N(0, 1).
//!
//! The tables are built once from the published constants (R = 3.6541528853610088, layer
//! area V = 0.00492867323399 of the unnormalised density e^(−x²/2)) by the recurrence
//! x_{i+1} = √(−2 ln(V/x_i + f(x_i))).

use std::sync::OnceLock;

use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, RngExt};

/// Layers of the ziggurat.
const LAYERS: usize = 256;
/// The right edge of the base layer's rectangle (where the tail begins).
const R: f64 = 3.654_152_885_361_009;
/// The area of every layer (base layer: its rectangle plus the tail) under e^(−x²/2).
const V: f64 = 0.004_928_673_233_99;

/// x_i (the layers' right edges, x_0 = V / f(R) for the base strip) and f_i = e^(−x_i²/2).
#[derive(Debug)]
pub(crate) struct Tables {
    pub x: [f64; LAYERS + 1],
    pub f: [f64; LAYERS + 1],
    /// (x_i, x_{i+1}) side by side: the fast pass's one 16-byte load per sample.
    pub edges: [[f64; 2]; LAYERS],
}

fn density(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

/// The tables, built on first use.
pub(crate) fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let mut x = [0.0; LAYERS + 1];
        x[0] = V / density(R);
        x[1] = R;
        for i in 1..LAYERS - 1 {
            x[i + 1] = (-2.0 * (V / x[i] + density(x[i])).ln()).sqrt();
        }
        // The top layer's cap reaches x = 0 (its recurrence value is 0 up to rounding).
        x[LAYERS] = 0.0;
        let mut f = [0.0; LAYERS + 1];
        for (fi, &xi) in f.iter_mut().zip(x.iter()) {
            *fi = density(xi);
        }
        let edges = std::array::from_fn(|i| [x[i], x[i + 1]]);
        Tables { x, f, edges }
    })
}

/// The symmetric abscissa u ∈ [−1, 1) of a word (its top 52 bits), as rand_distr does.
#[inline(always)]
fn abscissa(bits: u64) -> f64 {
    f64::from_bits((bits >> 12) | 0x4000_0000_0000_0000) - 3.0
}

/// The fast pass: `z[k]` is the candidate u·x_i of `bits[k]`; the indices whose candidate
/// is outside its layer's inner rectangle are appended to `rejects` (their `z` must be
/// finished by [`finish`]). The layers' edges are copied per sample (plain loads), then the
/// candidates and the reject flags are one branch-free vectorised loop; the rare rejects
/// are then collected in order.
#[inline(always)]
pub(crate) fn fast_pass(
    t: &Tables,
    bits: &[u64],
    z: &mut [f64],
    (flags, edges): (&mut [u64], &mut [[f64; 2]]),
    rejects: &mut Vec<u32>,
) {
    debug_assert!(bits.len() == z.len() && z.len() == flags.len() && z.len() == edges.len());
    // The layer's two edges copied per sample by scalar 16-byte loads: on AMD Zen 4 a
    // vector gather of eight is slower than eight plain loads (the two gathers were
    // ≈ 40 % of the kernel at (ρ_s, ρ_b) = (1, 0)).
    for (e, &b) in edges.iter_mut().zip(bits) {
        *e = t.edges[(b & 0xff) as usize];
    }
    for ((zk, fk), (&b, e)) in z
        .iter_mut()
        .zip(flags.iter_mut())
        .zip(bits.iter().zip(edges.iter()))
    {
        let x = abscissa(b) * e[0];
        *zk = x;
        // All ones or zero: the vector compare's own mask, stored as it is (packing it
        // to bytes cost more than the compare on AVX2).
        *fk = 0u64.wrapping_sub(u64::from(x.abs() >= e[1]));
    }
    rejects.clear();
    // A reject is rare (≈ 0.7 %): eight flags at a time are or-ed (two vector loads), and
    // only a group with a reject is visited flag by flag, in order.
    for (j, w) in flags.chunks(8).enumerate() {
        if w.iter().fold(0, |a, &f| a | f) != 0 {
            for (k, &f) in w.iter().enumerate() {
                if f != 0 {
                    rejects.push((8 * j + k) as u32);
                }
            }
        }
    }
}

/// Finishes a candidate the fast pass rejected: the ziggurat's slow path for the word
/// `bits` (its candidate recomputed), then whole fresh draws from `rng` until one is
/// accepted.
pub(crate) fn finish(t: &Tables, mut bits: u64, rng: &mut Xoshiro256PlusPlus) -> f64 {
    loop {
        let i = (bits & 0xff) as usize;
        let u = abscissa(bits);
        let x = u * t.x[i];
        if x.abs() < t.x[i + 1] {
            return x;
        }
        if i == 0 {
            return tail(rng, u);
        }
        if t.f[i + 1] + (t.f[i] - t.f[i + 1]) * rng.random::<f64>() < density(x) {
            return x;
        }
        bits = rng.next_u64();
    }
}

/// A sample of the normal tail beyond R with the sign of u (Marsaglia 1964).
fn tail(rng: &mut Xoshiro256PlusPlus, u: f64) -> f64 {
    loop {
        // Open (0, 1] uniforms: ln is finite.
        let a = -open01(rng).ln() / R;
        let b = -open01(rng).ln();
        if 2.0 * b > a * a {
            return if u < 0.0 { -(R + a) } else { R + a };
        }
    }
}

/// A uniform on (0, 1] with 53 bits.
pub(crate) fn open01(rng: &mut Xoshiro256PlusPlus) -> f64 {
    ((rng.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables close: the top edge is ~0, the layers shrink, and every layer's area
    /// x_i (f_{i+1} − f_i) is V (the base strip's rectangle plus tail is V by construction).
    #[test]
    fn tables_are_a_ziggurat() {
        let t = tables();
        let top = (-2.0 * (V / t.x[LAYERS - 1] + density(t.x[LAYERS - 1])).ln()).max(0.0);
        assert!(top.sqrt() < 1e-6, "top edge {}", top.sqrt());
        for i in 1..LAYERS {
            assert!(t.x[i + 1] < t.x[i]);
            let area = t.x[i] * (t.f[i + 1] - t.f[i]);
            assert!(
                (area - V).abs() < 1e-9 * V.max(1.0) + 1e-12,
                "layer {i}: {area}"
            );
        }
    }
}
