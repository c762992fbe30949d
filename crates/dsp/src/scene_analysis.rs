//! `mode = "auto"`: which analysis a scene calls for. Periodic motions (sine, square,
//! disk) have tones, which the Fourier mode measures at a few bins; transients (step,
//! ramp, impulse) have none and spread over the whole spectrum, which the Haar mode
//! localises in time and scale.

use serde::{Deserialize, Serialize};
use tofprobe_scene::{MotionConfig, SceneConfig};

/// The pixel's two analyses (mirrors `tofprobe_pixel::Mode`, which lies downstream).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AnalysisMode {
    Fourier,
    Haar,
}

/// The choice, why, and a note when the scene mixes both kinds of motion.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ModeChoice {
    pub mode: AnalysisMode,
    pub reason: String,
    pub note: Option<String>,
}

fn listed(ms: &[(usize, &MotionConfig)]) -> String {
    ms.iter()
        .map(|(i, m)| format!("scene.motion[{i}] ({})", m.kind()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Periodic only → Fourier; transient only → Haar; a static scene → Fourier (its noise
/// floor is what there is to measure); both → Fourier (the pixel's default, the tones are
/// measured, the transients raise the floor) with a note naming the transients and
/// `mode = "haar"` to localise them.
pub fn mode_for_scene(scene: &SceneConfig) -> ModeChoice {
    let (periodic, transient): (Vec<_>, Vec<_>) =
        scene.motions.iter().enumerate().partition(|(_, m)| {
            // A sweeping edge is a step at each pixel (its time depends on the pixel).
            crate::haar::checks::transient_span_s(m).is_none()
                && !matches!(m, MotionConfig::Edge { .. })
        });
    match (periodic.is_empty(), transient.is_empty()) {
        (true, true) => ModeChoice {
            mode: AnalysisMode::Fourier,
            reason: "static scene: no motion, Fourier measures the noise floor".into(),
            note: None,
        },
        (false, true) => ModeChoice {
            mode: AnalysisMode::Fourier,
            reason: format!("periodic motion only: {}", listed(&periodic)),
            note: None,
        },
        (true, false) => ModeChoice {
            mode: AnalysisMode::Haar,
            reason: format!(
                "transient motion only: {}; Haar localises it in time and scale",
                listed(&transient)
            ),
            note: None,
        },
        (false, false) => ModeChoice {
            mode: AnalysisMode::Fourier,
            reason: format!("periodic motion: {}", listed(&periodic)),
            note: Some(format!(
                "the scene also has transients ({}) that a Fourier frame spreads over the spectrum; set mode = \"haar\" to localise them",
                listed(&transient)
            )),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(motions: Vec<MotionConfig>) -> SceneConfig {
        SceneConfig {
            depth_mm: 30.0,
            motions,
        }
    }

    #[test]
    fn periodic_gives_fourier_transient_gives_haar() {
        let sine = MotionConfig::Sine {
            amplitude_mm: 0.1,
            frequency_hz: 4500.0,
            phase_deg: 0.0,
        };
        let ramp = MotionConfig::Ramp {
            start_s: 0.01,
            duration_s: 4e-4,
            height_mm: 25.0,
        };
        assert_eq!(mode_for_scene(&scene(vec![])).mode, AnalysisMode::Fourier);
        let c = mode_for_scene(&scene(vec![sine.clone()]));
        assert_eq!((c.mode, c.note.is_none()), (AnalysisMode::Fourier, true));
        let c = mode_for_scene(&scene(vec![ramp.clone()]));
        assert_eq!(c.mode, AnalysisMode::Haar);
        assert!(c.reason.contains("scene.motion[0] (ramp)"), "{}", c.reason);
        let c = mode_for_scene(&scene(vec![sine, ramp]));
        assert_eq!(c.mode, AnalysisMode::Fourier);
        let note = c.note.unwrap();
        assert!(
            note.contains("scene.motion[1] (ramp)") && note.contains("haar"),
            "{note}"
        );
    }
}
