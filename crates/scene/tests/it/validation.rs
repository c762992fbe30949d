//! Every validation error names the field, the value and the allowed range.

use crate::common;

use common::{sensor, static_scene};
use tofprobe_scene::{
    AcquisitionConfig, MotionConfig, PhotonSource, Scene, SceneConfig, SceneError, SensorConfig,
};

/// Asserts that `err` mentions each of `parts`.
fn mentions(err: SceneError, parts: &[&str]) {
    let msg = err.to_string();
    for p in parts {
        assert!(msg.contains(p), "`{msg}` does not mention `{p}`");
    }
}

fn sensor_err(f: impl FnOnce(&mut SensorConfig)) -> SceneError {
    let mut s = sensor(50.0, 1.0, 0.0);
    f(&mut s);
    s.validate().expect_err("must be rejected")
}

#[test]
fn sensor_fields() {
    mentions(
        sensor_err(|s| s.laser_rate_hz = -1.0),
        &["sensor.laser_rate_hz", "-1", "0 < laser_rate_hz <="],
    );
    mentions(
        sensor_err(|s| s.jitter_ps = -5.0),
        &["sensor.jitter_ps", "-5", "0 <= jitter_ps <="],
    );
    mentions(
        sensor_err(|s| s.tdc_lsb_ps = 0.0),
        &["sensor.tdc_lsb_ps", "= 0", "0 < tdc_lsb_ps"],
    );
    mentions(
        sensor_err(|s| s.window_start_ps = f64::NAN),
        &["sensor.window_start_ps", "NaN", "0 <= window_start_ps"],
    );
    mentions(
        sensor_err(|s| s.window_length_ps = 0.0),
        &["sensor.window_length_ps", "0 < window_length_ps"],
    );
    mentions(
        sensor_err(|s| s.signal_rate = 1.5),
        &["sensor.signal_rate", "1.5", "0 <= signal_rate <= 1"],
    );
    mentions(
        sensor_err(|s| s.signal_rate = -0.1),
        &["sensor.signal_rate", "-0.1", "0 <= signal_rate <= 1"],
    );
    mentions(
        sensor_err(|s| s.background_rate = -1.0),
        &[
            "sensor.background_rate",
            "-1",
            "0 <= background_rate <= 100",
        ],
    );
    mentions(
        sensor_err(|s| s.window_length_ps = 3.0),
        &["sensor.window_length_ps", "3", "tdc_lsb_ps = 5"],
    );
    mentions(
        sensor_err(|s| s.window_length_ps = 1e6),
        &[
            "sensor.window_length_ps",
            "1000000",
            "65536 codes",
            "327680",
        ],
    );
    mentions(
        sensor_err(|s| {
            s.laser_rate_hz = 1e9;
            s.window_length_ps = 2000.0;
        }),
        &[
            "sensor.window_length_ps",
            "2000",
            "laser period",
            "1000 ps",
            "window_length_ps <= 1000",
        ],
    );
    assert_eq!(sensor(50.0, 1.0, 0.0).validate(), Ok(()));
}

#[test]
fn sensor_helpers_of_the_default() {
    let s = sensor(50.0, 1.0, 0.0);
    assert_eq!(s.tdc_codes(), 80);
    assert_eq!(s.tdc_bits(), 7);
    assert!((s.jitter_mm() - 7.5).abs() < 1e-12);
    assert!((s.tdc_lsb_mm() - 0.75).abs() < 1e-12);
}

#[test]
fn acquisition_fields() {
    let a = |pulses, duration_s| AcquisitionConfig {
        pulses,
        duration_s,
        seed: 1,
    };
    mentions(
        a(Some(0), None).validate(10e6).unwrap_err(),
        &["acquisition.pulses", "= 0", "1 <= pulses"],
    );
    mentions(
        a(None, Some(-1.0)).validate(10e6).unwrap_err(),
        &["acquisition.duration_s", "-1", "<= duration_s <="],
    );
    mentions(
        a(None, None).validate(10e6).unwrap_err(),
        &["pulses", "duration_s", "neither"],
    );
    mentions(
        a(Some(5), Some(1.0)).validate(10e6).unwrap_err(),
        &["pulses", "duration_s", "both"],
    );
    assert_eq!(a(None, Some(1.0)).pulses(10e6), 10_000_000);
    assert_eq!(a(Some(77), None).pulses(10e6), 77);
}

fn motion_err(m: MotionConfig) -> SceneError {
    Scene::new(&SceneConfig {
        depth_mm: 30.0,
        motions: vec![
            MotionConfig::Step {
                at_s: 0.0,
                height_mm: 0.0,
            },
            m,
        ],
    })
    .expect_err("must be rejected")
}

#[test]
fn motion_fields() {
    mentions(
        motion_err(MotionConfig::Sine {
            amplitude_mm: 0.1,
            frequency_hz: 0.0,
            phase_deg: 0.0,
        }),
        &["scene.motion[1].frequency_hz", "= 0", "0 < frequency_hz"],
    );
    mentions(
        motion_err(MotionConfig::Sine {
            amplitude_mm: -0.1,
            frequency_hz: 10.0,
            phase_deg: 0.0,
        }),
        &["scene.motion[1].amplitude_mm", "-0.1", "0 <= amplitude_mm"],
    );
    mentions(
        motion_err(MotionConfig::Square {
            amplitude_mm: 1.0,
            frequency_hz: 10.0,
            duty: 1.0,
            phase_deg: 0.0,
        }),
        &["scene.motion[1].duty", "= 1", "0 < duty < 1"],
    );
    mentions(
        motion_err(MotionConfig::Disk {
            depths_mm: vec![],
            revolutions_per_s: 100.0,
            phase_deg: 0.0,
        }),
        &["scene.motion[1].depths_mm", "[]", "at least one"],
    );
    mentions(
        motion_err(MotionConfig::Disk {
            depths_mm: vec![1.0],
            revolutions_per_s: -100.0,
            phase_deg: 0.0,
        }),
        &[
            "scene.motion[1].revolutions_per_s",
            "-100",
            "0 < revolutions_per_s",
        ],
    );
    mentions(
        motion_err(MotionConfig::Ramp {
            start_s: 0.0,
            duration_s: 0.0,
            height_mm: 1.0,
        }),
        &["scene.motion[1].duration_s", "= 0", "0 < duration_s"],
    );
    mentions(
        motion_err(MotionConfig::Impulse {
            start_s: -1.0,
            width_s: 1e-3,
            height_mm: 1.0,
        }),
        &["scene.motion[1].start_s", "-1", "0 <= start_s"],
    );
    mentions(
        motion_err(MotionConfig::Step {
            at_s: 0.0,
            height_mm: f64::INFINITY,
        }),
        &["scene.motion[1].height_mm", "inf", "height_mm <="],
    );
    mentions(
        Scene::new(&SceneConfig {
            depth_mm: -3.0,
            motions: vec![],
        })
        .unwrap_err(),
        &["scene.depth_mm", "-3", "0 <= depth_mm"],
    );
}

#[test]
fn window_must_contain_the_scene() {
    // 70 mm is beyond the 0..60 mm window of the default sensor.
    let err = PhotonSource::new(&sensor(50.0, 1.0, 0.0), &static_scene(70.0), 1).unwrap_err();
    mentions(
        err,
        &[
            "scene.depth_mm = 70",
            "[0, 60) mm",
            "sensor.window_start_ps = 0",
            "sensor.window_length_ps = 400",
            ">= 471.7",
        ],
    );
    // A sine that swings out of the window is rejected too.
    let swinging = Scene::new(&SceneConfig {
        depth_mm: 58.0,
        motions: vec![MotionConfig::Sine {
            amplitude_mm: 3.0,
            frequency_hz: 100.0,
            phase_deg: 0.0,
        }],
    })
    .unwrap();
    mentions(
        PhotonSource::new(&sensor(50.0, 1.0, 0.0), &swinging, 1).unwrap_err(),
        &["55..61", "outside the timing window"],
    );
}

#[test]
fn tones_must_be_below_nyquist() {
    let fast = Scene::new(&SceneConfig {
        depth_mm: 30.0,
        motions: vec![MotionConfig::Sine {
            amplitude_mm: 0.1,
            frequency_hz: 6e6,
            phase_deg: 0.0,
        }],
    })
    .unwrap();
    mentions(
        PhotonSource::new(&sensor(50.0, 1.0, 0.0), &fast, 1).unwrap_err(),
        &[
            "scene.motion[0].frequency_hz",
            "6000000",
            "laser_rate_hz / 2 = 5000000",
        ],
    );
}
