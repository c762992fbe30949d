//! δ(t) of each motion kind against its closed form, the tones of a scene, and the error of
//! the fast block evaluation.

use std::f64::consts::{PI, TAU};

use tofprobe_scene::{BLOCK_PULSES, MotionConfig, Scene, SceneConfig};

fn scene(motions: Vec<MotionConfig>) -> Scene {
    Scene::new(&SceneConfig {
        depth_mm: 30.0,
        motions,
    })
    .expect("valid scene")
}

#[test]
fn each_motion_kind_at_known_times() {
    let sine = scene(vec![MotionConfig::Sine {
        amplitude_mm: 0.1,
        frequency_hz: 4500.0,
        phase_deg: 90.0,
    }]);
    // sin(2π·4500·t + π/2) = cos(2π·4500·t): +1 at t = 0, −1 at half a period.
    assert!((sine.depth_mm(0.0) - 30.1).abs() < 1e-12);
    assert!((sine.depth_mm(0.5 / 4500.0) - 29.9).abs() < 1e-12);

    let square = scene(vec![MotionConfig::Square {
        amplitude_mm: 2.0,
        frequency_hz: 100.0,
        duty: 0.25,
        phase_deg: 0.0,
    }]);
    assert_eq!(square.depth_mm(0.0), 32.0);
    assert_eq!(square.depth_mm(0.0024), 32.0);
    assert_eq!(square.depth_mm(0.0026), 28.0);
    assert_eq!(square.depth_mm(0.0101), 32.0);

    let disk = scene(vec![MotionConfig::Disk {
        depths_mm: vec![0.0, 1.0, 2.0, 3.0],
        revolutions_per_s: 100.0,
        phase_deg: 0.0,
    }]);
    // Sector j is under the beam for t ∈ [j/400, (j+1)/400) s within each 10 ms turn.
    for (t, d) in [
        (0.0, 30.0),
        (0.003, 31.0),
        (0.0051, 32.0),
        (0.0099, 33.0),
        (0.0101, 30.0),
    ] {
        assert_eq!(disk.depth_mm(t), d, "t = {t}");
    }

    let edges = scene(vec![
        MotionConfig::Step {
            at_s: 1e-3,
            height_mm: -1.0,
        },
        MotionConfig::Ramp {
            start_s: 2e-3,
            duration_s: 4e-3,
            height_mm: 4.0,
        },
        MotionConfig::Impulse {
            start_s: 10e-3,
            width_s: 1e-4,
            height_mm: 5.0,
        },
    ]);
    assert_eq!(edges.depth_mm(0.5e-3), 30.0);
    assert_eq!(edges.depth_mm(1.5e-3), 29.0);
    assert!((edges.depth_mm(3e-3) - 30.0).abs() < 1e-12); // 29 + 4·(1/4)
    assert!((edges.depth_mm(7e-3) - 33.0).abs() < 1e-12); // ramp done
    assert!((edges.depth_mm(10.05e-3) - 38.0).abs() < 1e-12); // impulse
    assert!((edges.depth_mm(10.2e-3) - 33.0).abs() < 1e-12);
    assert_eq!(edges.depth_range_mm(), (29.0, 39.0));
}

#[test]
fn square_wave_tones_are_its_odd_harmonics() {
    let s = scene(vec![MotionConfig::Square {
        amplitude_mm: 1.0,
        frequency_hz: 1000.0,
        duty: 0.5,
        phase_deg: 0.0,
    }]);
    let tones = s.tones();
    // Fourier series of a ±A square wave: 4A/(πk) at odd k, nothing at even k.
    assert!((tones[0].0 - 1000.0).abs() < 1e-9 && (tones[0].1 - 4.0 / PI).abs() < 1e-12);
    assert!((tones[1].0 - 3000.0).abs() < 1e-9 && (tones[1].1 - 4.0 / (3.0 * PI)).abs() < 1e-12);
    assert!(
        tones
            .iter()
            .all(|(f, _)| (f / 1000.0).round() as u64 % 2 == 1)
    );
}

#[test]
fn two_sector_disk_has_the_tones_of_a_square_wave() {
    // A disk [+1, −1] at 250 rev/s is a 250 Hz square wave of amplitude 1: an independent
    // check of the sector Fourier sum against the square-wave closed form.
    let disk = scene(vec![MotionConfig::Disk {
        depths_mm: vec![1.0, -1.0],
        revolutions_per_s: 250.0,
        phase_deg: 0.0,
    }])
    .tones();
    let square = scene(vec![MotionConfig::Square {
        amplitude_mm: 1.0,
        frequency_hz: 250.0,
        duty: 0.5,
        phase_deg: 0.0,
    }])
    .tones();
    assert_eq!(disk.len(), square.len());
    for (a, b) in disk.iter().zip(&square) {
        assert!(
            (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-12,
            "{a:?} {b:?}"
        );
    }
    let sine = scene(vec![MotionConfig::Sine {
        amplitude_mm: 0.1,
        frequency_hz: 4500.0,
        phase_deg: 0.0,
    }]);
    assert_eq!(sine.tones(), vec![(4500.0, 0.1)]);
}

#[test]
fn block_evaluation_matches_direct_evaluation() {
    let s = scene(vec![
        MotionConfig::Sine {
            amplitude_mm: 1.0,
            frequency_hz: 4500.0,
            phase_deg: 33.0,
        },
        MotionConfig::Sine {
            amplitude_mm: 1.0,
            frequency_hz: 1_234_567.0,
            phase_deg: 0.0,
        },
        MotionConfig::Square {
            amplitude_mm: 0.5,
            frequency_hz: 900.0,
            duty: 0.5,
            phase_deg: 0.0,
        },
    ]);
    let period = 1e-7;
    let mut out = vec![0.0; BLOCK_PULSES];
    // Late in a long record (pulse ~10^9) as well as at the start.
    for block in [0u64, 1, 244_140, 250_000] {
        let first = block * BLOCK_PULSES as u64;
        s.fill_depths_mm(first, period, &mut out);
        let mut worst: f64 = 0.0;
        for (i, d) in out.iter().enumerate() {
            let t = (first + i as u64) as f64 * period;
            worst = worst.max((d - s.depth_mm(t)).abs());
        }
        // Two error sources: the rotation recurrence accumulates ~1 ulp per step, ≤
        // 4096·2.2e-16 ≈ 1e-12 of the amplitude over a block (bound: 1e-11 mm); and both
        // evaluations round the phase f·t (in cycles) to an ulp of its magnitude, so they
        // may differ by 2π·A·4ε·f·t (≈ 7e-7 mm for the 1.2 MHz tone at t = 102 s, where
        // f·t ≈ 1.3e8 cycles). An off-by-one-pulse phase would be ≈ 0.77 mm.
        let t_end = (first + BLOCK_PULSES as u64) as f64 * period;
        let tol = 1e-11 + TAU * 4.0 * f64::EPSILON * (4500.0 + 1_234_567.0) * t_end;
        assert!(
            worst < tol,
            "block {block}: worst error {worst} mm, bound {tol}"
        );
    }
}
