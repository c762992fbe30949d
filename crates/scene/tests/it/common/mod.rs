//! Shared builders for the scene crate's integration tests.
#![allow(dead_code)]

use tofprobe_scene::{MotionConfig, PhotonSource, Scene, SceneConfig, SensorConfig};

/// The default sensor of the paper's Fig. 8 case with the given rates and jitter.
pub fn sensor(jitter_ps: f64, signal_rate: f64, background_rate: f64) -> SensorConfig {
    SensorConfig {
        laser_rate_hz: 10e6,
        jitter_ps,
        tdc_lsb_ps: 5.0,
        window_start_ps: 0.0,
        window_length_ps: 400.0,
        signal_rate,
        background_rate,
    }
}

/// A static scene at `depth_mm`.
pub fn static_scene(depth_mm: f64) -> Scene {
    Scene::new(&SceneConfig {
        depth_mm,
        motions: vec![],
    })
    .expect("valid static scene")
}

/// A scene with a sine, a square wave and an impulse on 30 mm.
pub fn busy_scene() -> Scene {
    Scene::new(&SceneConfig {
        depth_mm: 30.0,
        motions: vec![
            MotionConfig::Sine {
                amplitude_mm: 2.0,
                frequency_hz: 4500.0,
                phase_deg: 10.0,
            },
            MotionConfig::Square {
                amplitude_mm: 1.0,
                frequency_hz: 1000.0,
                duty: 0.3,
                phase_deg: 0.0,
            },
            MotionConfig::Impulse {
                start_s: 0.005,
                width_s: 0.001,
                height_mm: 3.0,
            },
        ],
    })
    .expect("valid busy scene")
}

/// A source over a static scene.
pub fn source(depth_mm: f64, jitter_ps: f64, rho_s: f64, rho_b: f64, seed: u64) -> PhotonSource {
    PhotonSource::new(
        &sensor(jitter_ps, rho_s, rho_b),
        &static_scene(depth_mm),
        seed,
    )
    .expect("valid source")
}
