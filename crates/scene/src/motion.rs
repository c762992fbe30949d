//! `[[scene.motion]]`: the motions that add to the static depth, as written in TOML
//! (`kind = "sine" | "square" | "disk" | "step" | "ramp" | "impulse"`), and their checks.

use serde::{Deserialize, Serialize};

use crate::error::{SceneError, check_positive, check_range};

/// Largest motion amplitude or height accepted (mm): far beyond any timing window.
const MAX_MM: f64 = 1e6;
/// Largest frequency accepted (Hz); the sensor further bounds it by f_s/2.
const MAX_HZ: f64 = 1e10;
/// Largest time accepted for a start or duration (s).
const MAX_S: f64 = 1e6;

fn half() -> f64 {
    0.5
}

/// One motion term of δ(t). Each is zero-mean or starts from zero, and adds to `depth_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum MotionConfig {
    /// `amplitude_mm · sin(2π·frequency_hz·t + phase_deg)`.
    Sine {
        /// Peak amplitude (mm).
        amplitude_mm: f64,
        /// Frequency (Hz).
        frequency_hz: f64,
        /// Phase at t = 0 (degrees).
        #[serde(default)]
        phase_deg: f64,
    },
    /// `+amplitude_mm` for the first `duty` of each period, `−amplitude_mm` for the rest.
    Square {
        /// Half the peak-to-peak swing (mm).
        amplitude_mm: f64,
        /// Frequency (Hz).
        frequency_hz: f64,
        /// Fraction of the period at `+amplitude_mm` (0 < duty < 1, default 0.5).
        #[serde(default = "half")]
        duty: f64,
        /// Phase at t = 0 (degrees of a period).
        #[serde(default)]
        phase_deg: f64,
    },
    /// A spinning disk whose surface height is a table of equal sectors per revolution.
    Disk {
        /// Sector depths (mm), one per equal sector, in the order they pass the beam.
        depths_mm: Vec<f64>,
        /// Revolutions per second.
        revolutions_per_s: f64,
        /// Angle at t = 0 (degrees).
        #[serde(default)]
        phase_deg: f64,
    },
    /// `height_mm` from `at_s` on.
    Step {
        /// Time of the step (s).
        at_s: f64,
        /// Height of the step (mm, negative moves closer).
        height_mm: f64,
    },
    /// Linear move by `height_mm` over `duration_s` from `start_s`, then holds.
    Ramp {
        /// Start of the ramp (s).
        start_s: f64,
        /// Duration of the ramp (s).
        duration_s: f64,
        /// Total change (mm; negative for a falling edge).
        height_mm: f64,
    },
    /// A rectangular pulse of `height_mm` from `start_s` for `width_s`.
    Impulse {
        /// Start (s).
        start_s: f64,
        /// Width (s).
        width_s: f64,
        /// Height (mm).
        height_mm: f64,
    },
}

impl MotionConfig {
    /// Checks this motion's fields; `index` is its position in `[[scene.motion]]`.
    pub fn validate(&self, index: usize) -> Result<(), SceneError> {
        let f = |name: &str| format!("scene.motion[{index}].{name}");
        match self {
            MotionConfig::Sine {
                amplitude_mm,
                frequency_hz,
                phase_deg,
            } => {
                check_range(&f("amplitude_mm"), *amplitude_mm, 0.0, MAX_MM)?;
                check_positive(&f("frequency_hz"), *frequency_hz, MAX_HZ)?;
                check_range(&f("phase_deg"), *phase_deg, -1e6, 1e6)?;
            }
            MotionConfig::Square {
                amplitude_mm,
                frequency_hz,
                duty,
                phase_deg,
            } => {
                check_range(&f("amplitude_mm"), *amplitude_mm, 0.0, MAX_MM)?;
                check_positive(&f("frequency_hz"), *frequency_hz, MAX_HZ)?;
                if !(duty.is_finite() && *duty > 0.0 && *duty < 1.0) {
                    return Err(SceneError::out_of_range(
                        f("duty"),
                        duty,
                        "0 < duty < 1 (0.5 is a symmetric square wave)",
                    ));
                }
                check_range(&f("phase_deg"), *phase_deg, -1e6, 1e6)?;
            }
            MotionConfig::Disk {
                depths_mm,
                revolutions_per_s,
                phase_deg,
            } => {
                if depths_mm.is_empty() {
                    return Err(SceneError::out_of_range(
                        f("depths_mm"),
                        "[]",
                        "a list of at least one depth (mm) per revolution",
                    ));
                }
                for (j, d) in depths_mm.iter().enumerate() {
                    check_range(&f(&format!("depths_mm[{j}]")), *d, -MAX_MM, MAX_MM)?;
                }
                check_positive(&f("revolutions_per_s"), *revolutions_per_s, MAX_HZ)?;
                check_range(&f("phase_deg"), *phase_deg, -1e6, 1e6)?;
            }
            MotionConfig::Step { at_s, height_mm } => {
                check_range(&f("at_s"), *at_s, 0.0, MAX_S)?;
                check_range(&f("height_mm"), *height_mm, -MAX_MM, MAX_MM)?;
            }
            MotionConfig::Ramp {
                start_s,
                duration_s,
                height_mm,
            } => {
                check_range(&f("start_s"), *start_s, 0.0, MAX_S)?;
                check_positive(&f("duration_s"), *duration_s, MAX_S)?;
                check_range(&f("height_mm"), *height_mm, -MAX_MM, MAX_MM)?;
            }
            MotionConfig::Impulse {
                start_s,
                width_s,
                height_mm,
            } => {
                check_range(&f("start_s"), *start_s, 0.0, MAX_S)?;
                check_positive(&f("width_s"), *width_s, MAX_S)?;
                check_range(&f("height_mm"), *height_mm, -MAX_MM, MAX_MM)?;
            }
        }
        Ok(())
    }

    /// The fundamental frequency of a sine or square wave (Hz): it must stay below the
    /// Nyquist rate f_s/2 of the pulse train, or the motion aliases.
    pub(crate) fn tone_hz(&self) -> Option<f64> {
        match self {
            MotionConfig::Sine { frequency_hz, .. } | MotionConfig::Square { frequency_hz, .. } => {
                Some(*frequency_hz)
            }
            _ => None,
        }
    }
}
