//! Validation of Haar frames for users: N a power of two (the pixel derives the wavelet
//! signs from its pulse counter), U within log₂N − 1, and notes for transients that fall
//! outside the frame (they would not be seen).

use tofprobe_scene::{MotionConfig, SceneConfig};

use crate::error::DspError;

/// The powers of two just below and above n (n ≥ 1; below is at least 2).
pub fn nearest_powers_of_two(n: u64) -> (u64, u64) {
    let below = if n < 2 {
        2
    } else {
        1u64 << (63 - n.leading_zeros())
    };
    let above = n.max(2).checked_next_power_of_two().unwrap_or(1 << 63);
    (below, above)
}

/// The pixel's Haar frame must hold 2^k ≥ 2 pulses; the error names the nearest powers
/// of two.
pub fn check_frame_pulses(pulses: u64) -> Result<(), DspError> {
    if pulses >= 2 && pulses.is_power_of_two() {
        return Ok(());
    }
    let (lo, hi) = nearest_powers_of_two(pulses);
    let hint = if lo == hi {
        format!("{lo} pulses works")
    } else {
        format!(
            "the nearest powers of two are {lo} (2^{}) and {hi} (2^{})",
            lo.ilog2(),
            hi.ilog2()
        )
    };
    Err(DspError::out_of_range(
        "frame_pulses (Haar N)",
        pulses,
        "a power of two ≥ 2 (the Haar signs come from the pulse counter's bits)",
    )
    .with_hint(hint))
}

/// U ≤ log₂N − 1 (each half of the finest wavelet needs a pulse); the error names the
/// largest U that works.
pub fn check_scales(pulses: u64, u_max: u32) -> Result<(), DspError> {
    if pulses < 2 {
        return Err(DspError::out_of_range(
            "frame_pulses (Haar N)",
            pulses,
            "≥ 2 (one pulse per half of the coarsest wavelet)",
        )
        .with_hint("2 pulses works"));
    }
    let largest = pulses.ilog2() - 1;
    if u_max > largest {
        return Err(DspError::out_of_range(
            "haar_scales (U)",
            u_max,
            format!("0..={largest} for N = {pulses} (2^(U+1) ≤ N)"),
        )
        .with_hint(format!("U = {largest} is the largest that works")));
    }
    Ok(())
}

/// Start and end (s) of a transient motion's change; None for periodic motions.
pub fn transient_span_s(m: &MotionConfig) -> Option<(f64, f64)> {
    match m {
        MotionConfig::Step { at_s, .. } => Some((*at_s, *at_s)),
        MotionConfig::Ramp {
            start_s,
            duration_s,
            ..
        } => Some((*start_s, start_s + duration_s)),
        MotionConfig::Impulse {
            start_s, width_s, ..
        } => Some((*start_s, start_s + width_s)),
        _ => None,
    }
}

fn describe(m: &MotionConfig) -> String {
    let ms = |t: f64| format!("{:.6} ms", t * 1e3);
    match m {
        MotionConfig::Step { at_s, height_mm } => {
            format!("step of {height_mm} mm at {}", ms(*at_s))
        }
        MotionConfig::Ramp {
            start_s,
            duration_s,
            height_mm,
        } => format!(
            "ramp of {height_mm} mm from {} to {}",
            ms(*start_s),
            ms(start_s + duration_s)
        ),
        MotionConfig::Impulse {
            start_s,
            width_s,
            height_mm,
        } => format!(
            "impulse of {height_mm} mm from {} to {}",
            ms(*start_s),
            ms(start_s + width_s)
        ),
        other => format!("{other:?}"),
    }
}

/// Notes for the scene's transients that the frame [0, frame_s) does not (fully) contain:
/// one line each, naming the motion (`scene.motion[i]`, its kind and times) and the frame.
pub fn transients_outside_frame(scene: &SceneConfig, frame_s: f64) -> Vec<String> {
    let frame = format!("{:.6} ms", frame_s * 1e3);
    scene
        .motions
        .iter()
        .enumerate()
        .filter_map(|(i, m)| {
            let (a, b) = transient_span_s(m)?;
            if a >= frame_s {
                Some(format!(
                    "scene.motion[{i}] ({}) starts after the frame ends at {frame}: the Haar frame does not see it",
                    describe(m)
                ))
            } else if b > frame_s {
                Some(format!(
                    "scene.motion[{i}] ({}) ends after the frame ends at {frame}: only its start is seen",
                    describe(m)
                ))
            } else {
                None
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_must_be_a_power_of_two() {
        assert!(check_frame_pulses(1 << 19).is_ok());
        let e = check_frame_pulses(100_000).unwrap_err().to_string();
        assert!(
            e.contains("100000") && e.contains("65536") && e.contains("131072"),
            "{e}"
        );
        let e = check_frame_pulses(500_000).unwrap_err().to_string();
        assert!(e.contains("262144") && e.contains("524288"), "{e}");
        assert!(
            check_frame_pulses(0)
                .unwrap_err()
                .to_string()
                .contains("2 pulses")
        );
        assert_eq!(nearest_powers_of_two(3), (2, 4));
    }

    #[test]
    fn scales_within_log2_n() {
        assert!(check_scales(1 << 17, 16).is_ok());
        let e = check_scales(1 << 10, 10).unwrap_err().to_string();
        assert!(
            e.contains("haar_scales (U) = 10") && e.contains("U = 9"),
            "{e}"
        );
        assert!(check_scales(1, 0).is_err());
    }

    #[test]
    fn transients_outside_the_frame_are_noted() {
        let scene = SceneConfig {
            depth_mm: 30.0,
            motions: vec![
                MotionConfig::Impulse {
                    start_s: 1.5e-3,
                    width_s: 1e-4,
                    height_mm: 3.0,
                },
                MotionConfig::Ramp {
                    start_s: 8e-3,
                    duration_s: 3e-3,
                    height_mm: -2.0,
                },
                MotionConfig::Step {
                    at_s: 20e-3,
                    height_mm: 1.0,
                },
                MotionConfig::Sine {
                    amplitude_mm: 1.0,
                    frequency_hz: 1e3,
                    phase_deg: 0.0,
                },
            ],
        };
        let notes = transients_outside_frame(&scene, 0.01);
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(notes[0].contains("scene.motion[1]") && notes[0].contains("11.000000 ms"));
        assert!(notes[1].contains("scene.motion[2]") && notes[1].contains("20.000000 ms"));
        assert!(transients_outside_frame(&scene, 0.05).is_empty());
    }
}
