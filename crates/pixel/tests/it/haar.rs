//! Haar mode (issue point 5): the pixel's integer registers equal the un-normalised Haar
//! sums of crates/dsp (`haar_sums`, exact integers) on the same held depths, and the float
//! coefficients before normalisation (sums = coefficient · wavelet length) exactly.

use crate::common;

use common::Rng;
use proptest::prelude::*;
use tofprobe_dsp::haar::{haar_coefficients, haar_sums, register_count, wavelet_len};
use tofprobe_pixel::{Mode, PixelParams, TransactionModel};

fn haar_params(log2_n: u32, u: u32, width: u32) -> PixelParams {
    let mut p = PixelParams::fourier_default(width, 1 << log2_n, 1);
    p.mode = Mode::Haar;
    p.haar_scales = u;
    p.adders = 1;
    p.cycles_per_pulse = (u + 1) as usize;
    p.zoom = 40;
    p
}

/// The held depths the pixel sees: d = code − Z for valid pulses, else the previous held
/// value (the record starts with a valid detection so every pulse contributes).
fn held_sequence(stimuli: &[Option<u32>], zoom: u32) -> Vec<i64> {
    let mut held = 0;
    stimuli
        .iter()
        .map(|d| {
            if let Some(c) = d {
                held = i64::from(*c) - i64::from(zoom);
            }
            held
        })
        .collect()
}

fn haar_case(seed: u64) {
    let mut rng = Rng(seed);
    let log2_n = 1 + rng.below(10) as u32;
    let u = rng.below(u64::from(log2_n)) as u32;
    // W large enough for the exact sums: |sum| ≤ N·2^T (T = 7).
    let p = haar_params(log2_n, u, 8 + log2_n + 1);
    let n = 1usize << log2_n;
    let mut stimuli: Vec<Option<u32>> = (0..n)
        .map(|_| (!rng.chance(30)).then(|| rng.below(128) as u32))
        .collect();
    stimuli[0] = Some(rng.below(128) as u32);
    let mut tm = TransactionModel::new(&p).unwrap();
    let frames = tm.run_frames(&stimuli, None).unwrap();
    let held = held_sequence(&stimuli, p.zoom);
    let sums = haar_sums(&held, u).unwrap();
    assert_eq!(frames[0].words, sums, "integer Haar sums");
    assert_eq!(sums.len(), register_count(u));
    // The float transform before normalisation: coefficient × wavelet length.
    let floats: Vec<f64> = held.iter().map(|&h| h as f64).collect();
    let coeffs = haar_coefficients(&floats, u).unwrap();
    for (r, (&c, &y)) in coeffs.iter().zip(&frames[0].words).enumerate() {
        let scale = (r + 1).ilog2();
        let v = r + 1 - (1 << scale);
        let len = wavelet_len(n, scale, v) as f64;
        // |y| < 2^17 and len ≤ 2^10: c·len is exact in f64 (lengths are powers of two).
        assert_eq!(c * len, y as f64, "register {r}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]
    #[test]
    fn haar_registers_equal_dsp_haar(seed in any::<u64>()) {
        haar_case(seed);
    }
}

/// The default Haar pixel: U = 4 → 31 registers, 5 operations per pulse.
#[test]
fn default_haar_has_31_registers() {
    let p = haar_params(10, 4, 24);
    assert_eq!((p.registers(), p.ops_per_pulse()), (31, 5));
    let cfg = tofprobe_pixel::PixelConfig::default();
    assert_eq!(cfg.haar_scales, None);
    assert_eq!(tofprobe_pixel::config::DEFAULT_HAAR_SCALES, 4);
}
