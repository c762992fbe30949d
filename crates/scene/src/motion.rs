//! `[[scene.motion]]`: the motions that add to the static depth, as written in TOML
//! (`kind = "sine" | "square" | "disk" | "step" | "ramp" | "impulse"`, and the spatial
//! `"plate_mode" | "rotor" | "edge"` of [`crate::spatial`]), and their checks.

use serde::{Deserialize, Serialize};

use crate::error::{SceneError, check_positive, check_range};

/// Largest motion amplitude or height accepted (mm): far beyond any timing window.
pub(crate) const MAX_MM: f64 = 1e6;
/// Largest frequency accepted (Hz); the sensor further bounds it by f_s/2.
pub(crate) const MAX_HZ: f64 = 1e10;
/// Largest time accepted for a start or duration (s).
pub(crate) const MAX_S: f64 = 1e6;

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
    /// The (m, n) mode of a simply supported rectangular plate of `length_x_mm` ×
    /// `length_y_mm` whose corner is at (`x0_mm`, `y0_mm`) on the scene plane:
    /// `amplitude_mm · sin(mπx'/Lx) · sin(nπy'/Ly) · sin(2π·frequency_hz·t + phase_deg)`
    /// inside the plate, 0 outside. Several superpose into an operational deflection shape.
    #[serde(rename = "plate_mode")]
    PlateMode {
        /// Mode index along x (≥ 1).
        m: u32,
        /// Mode index along y (≥ 1).
        n: u32,
        /// Plate size along x (mm).
        length_x_mm: f64,
        /// Plate size along y (mm).
        length_y_mm: f64,
        /// Peak amplitude of the mode shape (mm).
        amplitude_mm: f64,
        /// Frequency (Hz).
        frequency_hz: f64,
        /// Phase at t = 0 (degrees).
        #[serde(default)]
        phase_deg: f64,
        /// Plate corner on the scene plane (mm).
        #[serde(default)]
        x0_mm: f64,
        /// See `x0_mm`.
        #[serde(default)]
        y0_mm: f64,
    },
    /// A disk of `blades` blades rotating at `rpm` about (`centre_x_mm`, `centre_y_mm`):
    /// between `hub_radius_mm` and `radius_mm` a pixel sees `blade_mm` where a blade covers
    /// it (a fraction `blade_fraction` of each blade period) and 0 between blades: the
    /// blade-pass frequency blades·rpm/60 and its harmonics.
    Rotor {
        /// Number of blades (≥ 1).
        blades: u32,
        /// Revolutions per minute.
        rpm: f64,
        /// Centre of rotation on the scene plane (mm).
        centre_x_mm: f64,
        /// See `centre_x_mm`.
        centre_y_mm: f64,
        /// Blade tip radius (mm).
        radius_mm: f64,
        /// Radius inside which the blades do not reach (mm).
        #[serde(default)]
        hub_radius_mm: f64,
        /// Depth change where a blade is (mm; negative: the blade is closer).
        blade_mm: f64,
        /// Fraction of each blade period covered by the blade (0 < f < 1).
        #[serde(default = "half")]
        blade_fraction: f64,
        /// Angle of the first blade at t = 0 (degrees).
        #[serde(default)]
        phase_deg: f64,
    },
    /// A depth step of `height_mm` whose front sweeps the plane at `velocity_mm_per_s` in
    /// direction `direction_deg` (0: +x, along a row; 90: +y, down a column). At t = 0 the
    /// front is `start_mm` along that direction from the origin; a pixel steps when the
    /// front reaches its centre, over `width_mm` of front (0: an instantaneous step).
    Edge {
        /// Height of the step (mm).
        height_mm: f64,
        /// Speed of the front on the plane (mm/s).
        velocity_mm_per_s: f64,
        /// Direction of travel (degrees from +x towards +y).
        #[serde(default)]
        direction_deg: f64,
        /// Front position along the direction at t = 0 (mm).
        #[serde(default)]
        start_mm: f64,
        /// Width of the front (mm): the step is a ramp over width/velocity seconds.
        #[serde(default)]
        width_mm: f64,
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
            MotionConfig::PlateMode { .. }
            | MotionConfig::Rotor { .. }
            | MotionConfig::Edge { .. } => validate_spatial(self, index)?,
        }
        Ok(())
    }

    /// The kind as written in TOML.
    pub fn kind(&self) -> &'static str {
        match self {
            MotionConfig::Sine { .. } => "sine",
            MotionConfig::Square { .. } => "square",
            MotionConfig::Disk { .. } => "disk",
            MotionConfig::Step { .. } => "step",
            MotionConfig::Ramp { .. } => "ramp",
            MotionConfig::Impulse { .. } => "impulse",
            MotionConfig::PlateMode { .. } => "plate_mode",
            MotionConfig::Rotor { .. } => "rotor",
            MotionConfig::Edge { .. } => "edge",
        }
    }

    /// Whether the motion depends on position on the scene plane (it needs an array).
    pub fn is_spatial(&self) -> bool {
        matches!(
            self,
            MotionConfig::PlateMode { .. } | MotionConfig::Rotor { .. } | MotionConfig::Edge { .. }
        )
    }

    /// The fundamental frequency of a sine or square wave (Hz): it must stay below the
    /// Nyquist rate f_s/2 of the pulse train, or the motion aliases.
    pub(crate) fn tone_hz(&self) -> Option<f64> {
        match self {
            MotionConfig::Sine { frequency_hz, .. }
            | MotionConfig::Square { frequency_hz, .. }
            | MotionConfig::PlateMode { frequency_hz, .. } => Some(*frequency_hz),
            _ => None,
        }
    }
}

/// Largest coordinate or length on the scene plane (mm): 100 m.
pub const MAX_PLANE_MM: f64 = 1e5;
/// Largest mode index: beyond it the mode's wavelength is below any pixel.
pub const MAX_MODE: u32 = 1000;
/// Most blades of a rotor.
pub const MAX_BLADES: u32 = 64;
/// Sectors per blade period of the rotor's depth table (the blade fraction is rounded to
/// 1/32 of a period).
pub(crate) const SECTORS_PER_BLADE: usize = 32;

/// Checks a spatial motion's fields (the kinds [`crate::spatial`] reduces to a point's) (`index`: its place in `[[scene.motion]]`).
fn validate_spatial(m: &MotionConfig, index: usize) -> Result<(), SceneError> {
    let f = |name: &str| format!("scene.motion[{index}].{name}");
    match m {
        MotionConfig::PlateMode {
            m,
            n,
            length_x_mm,
            length_y_mm,
            amplitude_mm,
            frequency_hz,
            phase_deg,
            x0_mm,
            y0_mm,
        } => {
            for (name, v) in [("m", m), ("n", n)] {
                if !(1..=MAX_MODE).contains(v) {
                    return Err(SceneError::out_of_range(
                        f(name),
                        v,
                        format!("1 <= {name} <= {MAX_MODE} (1 is the first mode: one half-wave)"),
                    ));
                }
            }
            check_positive(&f("length_x_mm"), *length_x_mm, MAX_PLANE_MM)?;
            check_positive(&f("length_y_mm"), *length_y_mm, MAX_PLANE_MM)?;
            check_range(&f("amplitude_mm"), *amplitude_mm, 0.0, MAX_MM)?;
            check_positive(&f("frequency_hz"), *frequency_hz, MAX_HZ)?;
            check_range(&f("phase_deg"), *phase_deg, -1e6, 1e6)?;
            check_range(&f("x0_mm"), *x0_mm, -MAX_PLANE_MM, MAX_PLANE_MM)?;
            check_range(&f("y0_mm"), *y0_mm, -MAX_PLANE_MM, MAX_PLANE_MM)?;
        }
        MotionConfig::Rotor {
            blades,
            rpm,
            centre_x_mm,
            centre_y_mm,
            radius_mm,
            hub_radius_mm,
            blade_mm,
            blade_fraction,
            phase_deg,
        } => {
            if !(1..=MAX_BLADES).contains(blades) {
                return Err(SceneError::out_of_range(
                    f("blades"),
                    blades,
                    format!("1 <= blades <= {MAX_BLADES}"),
                ));
            }
            check_positive(&f("rpm"), *rpm, MAX_HZ * 60.0)?;
            check_range(&f("centre_x_mm"), *centre_x_mm, -MAX_PLANE_MM, MAX_PLANE_MM)?;
            check_range(&f("centre_y_mm"), *centre_y_mm, -MAX_PLANE_MM, MAX_PLANE_MM)?;
            check_positive(&f("radius_mm"), *radius_mm, MAX_PLANE_MM)?;
            if !(hub_radius_mm.is_finite() && *hub_radius_mm >= 0.0 && hub_radius_mm < radius_mm) {
                return Err(SceneError::out_of_range(
                    f("hub_radius_mm"),
                    hub_radius_mm,
                    format!("0 <= hub_radius_mm < radius_mm = {radius_mm}"),
                ));
            }
            check_range(&f("blade_mm"), *blade_mm, -MAX_MM, MAX_MM)?;
            let k = (blade_fraction * SECTORS_PER_BLADE as f64).round();
            if !(blade_fraction.is_finite() && k >= 1.0 && k < SECTORS_PER_BLADE as f64) {
                return Err(SceneError::out_of_range(
                    f("blade_fraction"),
                    blade_fraction,
                    format!(
                        "1/{SECTORS_PER_BLADE} <= blade_fraction <= {}/{SECTORS_PER_BLADE} (0.5: blades as wide as the gaps)",
                        SECTORS_PER_BLADE - 1
                    ),
                ));
            }
            check_range(&f("phase_deg"), *phase_deg, -1e6, 1e6)?;
        }
        MotionConfig::Edge {
            height_mm,
            velocity_mm_per_s,
            direction_deg,
            start_mm,
            width_mm,
        } => {
            check_range(&f("height_mm"), *height_mm, -MAX_MM, MAX_MM)?;
            check_positive(&f("velocity_mm_per_s"), *velocity_mm_per_s, 1e9)?;
            check_range(&f("direction_deg"), *direction_deg, -360.0, 360.0)?;
            check_range(&f("start_mm"), *start_mm, -MAX_PLANE_MM, MAX_PLANE_MM)?;
            check_range(&f("width_mm"), *width_mm, 0.0, MAX_PLANE_MM)?;
        }
        _ => {}
    }
    Ok(())
}
