//! TDC quantisation and the timing window's edges against closed forms.

use crate::common;

use common::{sensor, static_scene};
use tofprobe_scene::{MM_PER_PS, PhotonSource};

#[test]
fn zero_jitter_gives_one_code() {
    // 30 mm = 200 ps → code floor(200 / 5) = 40, whose centre is 202.5 ps = 30.375 mm.
    let src = PhotonSource::new(&sensor(0.0, 1.0, 0.0), &static_scene(30.0), 1).unwrap();
    let rec = src.record(10_000);
    assert!(rec.iter().all(|c| *c == Some(40)));
    assert!((src.code_to_depth_mm(40) - 30.375).abs() < 1e-12);
}

#[test]
fn codes_stay_in_the_window_with_a_partial_last_code() {
    // 401 ps / 5 ps → 81 codes, the last one 1 ps wide. Uniform background fills every
    // code; none may reach 81.
    let mut s = sensor(0.0, 0.0, 2.0);
    s.window_length_ps = 401.0;
    assert_eq!(s.tdc_codes(), 81);
    let src = PhotonSource::new(&s, &static_scene(30.0), 3).unwrap();
    let rec = src.record(200_000);
    let max = rec.iter().flatten().max().copied();
    assert_eq!(max, Some(80));
}

#[test]
fn arrivals_before_the_window_are_lost() {
    // Signal at 1.5 mm = 10 ps with σ_I = 50 ps, window from 0: detected iff the jittered
    // arrival is ≥ 0, probability Φ(10/50) = 0.57926. N = 10^6: binomial SE 4.9e-4; 5 SE.
    let src = PhotonSource::new(&sensor(50.0, 1.0, 0.0), &static_scene(1.5), 5).unwrap();
    let n = 1_000_000;
    let mut out = vec![None; n];
    let c = src.fill_counted(0, &mut out);
    let p = 0.579_259_709_439_103; // Φ(0.2)
    let got = c.detections as f64 / n as f64;
    let se = (p * (1.0 - p) / n as f64).sqrt();
    assert!((got - p).abs() < 5.0 * se, "{got} vs {p}");
    assert!((1.5 / MM_PER_PS - 10.0).abs() < 1e-12);
}
