//! The superpixel front end (`tofprobe_pixel::superpixel`): its reciprocal-table division
//! against the exact quotient and the float mean for every (sum, n) of G ≤ 4 and every T,
//! and its noise against the closed form of `tofprobe_dsp::superpixel` on the Monte Carlo.

use tofprobe_dsp::superpixel::superpixel_noise;
use tofprobe_pixel::{NO_DETECTION, Superpixel};
use tofprobe_scene::{MM_PER_PS, PhotonSource, Scene, SceneConfig, SensorConfig};

/// Every n = 1 ..= G² and every sum s = 0 ..= n·(2^T − 1): the table's multiply-shift is
/// exactly ⌊(s + ⌊n/2⌋)/n⌋, within ½ LSB of the float mean s/n, and a tie rounds up.
/// Reports the first (G, T, n, s) that differs.
#[test]
fn the_table_divides_exactly_for_every_sum() {
    for g in 1..=4u32 {
        for t in 1..=16u32 {
            let sp = Superpixel::new(g, t).unwrap();
            for n in 1..=g * g {
                for s in 0..=n * ((1 << t) - 1) {
                    let q = sp.mean(s, n);
                    let exact = (s + n / 2) / n;
                    assert_eq!(q, exact, "G = {g}, T = {t}, n = {n}, s = {s}");
                    let err = f64::from(q) - f64::from(s) / f64::from(n);
                    assert!(
                        (-0.5..=0.5).contains(&err),
                        "G = {g}, T = {t}, n = {n}, s = {s}: error {err}"
                    );
                    // A tie (n even, s/n = m + ½) rounds up: the error is +½, never −½.
                    assert!(err > -0.5, "G = {g}, n = {n}, s = {s}: tie rounded down");
                    assert!(q < 1 << t, "G = {g}, T = {t}: {q} needs more than T bits");
                }
            }
        }
    }
}

/// The same check fails for a table of ⌊2^k/n⌋ (a plausible wrong table): the exhaustive
/// walk is able to catch a wrong reciprocal. Its first failure is named.
#[test]
fn a_floor_table_is_caught() {
    let sp = Superpixel::new(4, 7).unwrap();
    let k = sp.shift();
    let first = (1..=16u32).find_map(|n| {
        let m = (1u64 << k) / u64::from(n);
        (0..=n * 127).find_map(|s| {
            let x = u64::from(s + n / 2);
            let q = ((x * m) >> k) as u32;
            (q != (s + n / 2) / n).then_some((n, s))
        })
    });
    // n = 3, s = 2: x = 3, 3·⌊2^k/3⌋ < 2^k, so the floor table gives 0 for 3/3.
    assert_eq!(first, Some((3, 2)));
}

/// One pulse: valid' = any valid, the mean over the valid SPADs only, codes truncated to T
/// bits first (the T pins), no detection among G² → no detection.
#[test]
fn combine_one_pulse() {
    let sp = Superpixel::new(2, 7).unwrap();
    assert_eq!(sp.table().len(), 4);
    assert_eq!(sp.shift(), 7 + 4);
    let n = NO_DETECTION;
    assert_eq!(sp.combine(&[n, n, n, n]), NO_DETECTION);
    assert_eq!(sp.combine(&[n, 40, n, n]), 40);
    assert_eq!(sp.combine(&[10, 11, n, n]), 11); // 10.5 rounds up
    assert_eq!(sp.combine(&[10, 11, 11, n]), 11); // 10.67
    assert_eq!(sp.combine(&[10, 10, 11, n]), 10); // 10.33
    assert_eq!(sp.combine(&[127, 127, 127, 127]), 127);
    // 130 on 7 pins is 2: (2 + 4)/2 = 3.
    assert_eq!(sp.combine(&[130, 4, n, n]), 3);
    let g1 = Superpixel::new(1, 7).unwrap();
    assert_eq!(g1.combine(&[93]), 93);
    assert_eq!(g1.combine(&[n]), NO_DETECTION);
    for (g, t) in [(0, 7), (5, 7), (2, 0), (2, 17)] {
        let e = Superpixel::new(g, t).unwrap_err().to_string();
        assert!(
            e.contains(if g == 0 || g == 5 {
                "superpixel"
            } else {
                "tdc_bits"
            }),
            "{e}"
        );
    }
}

/// σ = 3 LSB (15 ps jitter, 5 ps LSB), no background, a static target mid-window.
fn sensor(p: f64) -> SensorConfig {
    SensorConfig {
        laser_rate_hz: 10e6,
        jitter_ps: 15.0,
        tdc_lsb_ps: 5.0,
        window_start_ps: 0.0,
        window_length_ps: 640.0,
        signal_rate: p,
        background_rate: 0.0,
    }
}

/// The Monte Carlo of one superpixel: G² SPADs with their own seeds, `pulses` pulses,
/// combined; returns (valid' rate and its standard error, mean ε² about t − ½ and its
/// standard error).
fn monte_carlo(g: u32, p: f64, seed: u64, pulses: usize) -> (f64, f64, f64, f64) {
    let depth_mm = 40.0;
    let scene = Scene::new(&SceneConfig {
        depth_mm,
        motions: vec![],
    })
    .unwrap();
    let tau = depth_mm / MM_PER_PS / 5.0; // codes
    let spads = (g * g) as usize;
    let streams: Vec<Vec<u32>> = (0..spads)
        .map(|i| {
            let src = PhotonSource::new(&sensor(p), &scene, seed * 64 + i as u64).unwrap();
            let mut v = vec![0u32; pulses];
            src.fill_codes(0, &mut v);
            v
        })
        .collect();
    let refs: Vec<&[u32]> = streams.iter().map(Vec::as_slice).collect();
    let mut out = vec![0u32; pulses];
    let sp = Superpixel::new(g, 8).unwrap();
    let valid = sp.combine_streams(&refs, &mut out) as f64;
    let (mut m2, mut m4) = (0.0, 0.0);
    for &c in out.iter().filter(|&&c| c != NO_DETECTION) {
        let e = f64::from(c) - (tau - 0.5);
        m2 += e * e;
        m4 += e * e * e * e;
    }
    let rate = valid / pulses as f64;
    let (m2, m4) = (m2 / valid, m4 / valid);
    (
        rate,
        (rate * (1.0 - rate) / pulses as f64).sqrt(),
        m2,
        ((m4 - m2 * m2) / valid).sqrt(),
    )
}

/// The detection rate 1 − (1 − p)^{G²} and E[ε²] = Σ P(k | k ≥ 1)((σ² + 1/12)/k + E[r²|k])
/// against the Monte Carlo over three seeds each, for G = 2 (p = ½) and G = 3 (p = 0.2).
/// Tolerance: 5 standard errors of the sample itself (200 k pulses: ≈ 0.4 % of E[ε²]); the
/// closed form's own approximations (Sheppard, a uniform residue) are below 10⁻⁴ at
/// σ = 3 LSB. The naive σ²/G² (every SPAD averaging, whatever its detection) misses by
/// more than 50 standard errors, and so fails the same check.
#[test]
fn the_noise_closed_form_holds_on_the_monte_carlo() {
    let sigma = 3.0;
    for (g, p) in [(2u32, 0.5), (3, 0.2)] {
        let cf = superpixel_noise(g * g, p, sigma).unwrap();
        let naive = (sigma * sigma + 1.0 / 12.0) / f64::from(g * g) + 1.0 / 12.0;
        for seed in 1..=3u64 {
            let (rate, rate_se, mse, mse_se) = monte_carlo(g, p, seed, 200_000);
            assert!(
                (rate - cf.detection_rate).abs() < 5.0 * rate_se,
                "G = {g}, p = {p}, seed {seed}: rate {rate} vs {} (se {rate_se})",
                cf.detection_rate
            );
            assert!(
                (mse - cf.mse_lsb2).abs() < 5.0 * mse_se,
                "G = {g}, p = {p}, seed {seed}: E[ε²] {mse} vs the closed form {} (se {mse_se})",
                cf.mse_lsb2
            );
            assert!(
                (mse - naive).abs() > 50.0 * mse_se,
                "G = {g}, seed {seed}: σ²/G² = {naive} is not rejected by {mse} ± {mse_se}"
            );
        }
    }
}
