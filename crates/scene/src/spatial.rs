//! Motions that depend on position on the scene plane: plate modes, rotors and sweeping
//! edges (`[[scene.motion]]` kinds `plate_mode`, `rotor`, `edge`). Coordinates are mm on
//! the plane, x along a row (columns), y down a column (rows), origin at the array's
//! corner. A pixel sees the motion at its centre: [`reduce`] turns a spatial motion into the
//! temporal motion (and static offset) one point sees, so the Monte Carlo and every
//! single-pixel path run unchanged on each pixel's own scene (`Scene::at_point`).

use std::f64::consts::PI;

pub use crate::motion::{MAX_BLADES, MAX_MODE, MAX_PLANE_MM};
use crate::motion::{MotionConfig, SECTORS_PER_BLADE};

/// What one point of the plane sees of a spatial motion: a static offset (mm, an edge that
/// has already passed) and the temporal motion, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMotion {
    pub static_mm: f64,
    pub motion: Option<MotionConfig>,
}

/// The motion a point (x, y) mm sees; a temporal motion is returned as it is.
pub fn reduce(m: &MotionConfig, x: f64, y: f64) -> PointMotion {
    let none = PointMotion {
        static_mm: 0.0,
        motion: None,
    };
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
            let (u, v) = ((x - x0_mm) / length_x_mm, (y - y0_mm) / length_y_mm);
            if !((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
                return none;
            }
            let shape = (f64::from(*m) * PI * u).sin() * (f64::from(*n) * PI * v).sin();
            let a = amplitude_mm * shape;
            if a.abs() <= 1e-12 * amplitude_mm {
                return none;
            }
            // A negative shape is the same sine half a period later.
            let phase = if a < 0.0 {
                phase_deg + 180.0
            } else {
                *phase_deg
            };
            PointMotion {
                static_mm: 0.0,
                motion: Some(MotionConfig::Sine {
                    amplitude_mm: a.abs(),
                    frequency_hz: *frequency_hz,
                    phase_deg: phase,
                }),
            }
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
            let (dx, dy) = (x - centre_x_mm, y - centre_y_mm);
            let r = dx.hypot(dy);
            if r > *radius_mm || r < *hub_radius_mm {
                return none;
            }
            let covered = (blade_fraction * SECTORS_PER_BLADE as f64).round() as usize;
            let depths_mm: Vec<f64> = (0..*blades as usize * SECTORS_PER_BLADE)
                .map(|i| {
                    if i % SECTORS_PER_BLADE < covered {
                        *blade_mm
                    } else {
                        0.0
                    }
                })
                .collect();
            // The pattern passes the point at angle φ when the disk has turned by φ.
            let angle = dy.atan2(dx).to_degrees();
            PointMotion {
                static_mm: 0.0,
                motion: Some(MotionConfig::Disk {
                    depths_mm,
                    revolutions_per_s: rpm / 60.0,
                    phase_deg: phase_deg - angle,
                }),
            }
        }
        MotionConfig::Edge {
            height_mm,
            velocity_mm_per_s,
            direction_deg,
            start_mm,
            width_mm,
        } => {
            let (s, c) = direction_deg.to_radians().sin_cos();
            let p = x * c + y * s;
            let arrive = (p - start_mm) / velocity_mm_per_s;
            let duration = width_mm / velocity_mm_per_s;
            if arrive + duration <= 0.0 {
                // The front passed this point before the record began.
                return PointMotion {
                    static_mm: *height_mm,
                    motion: None,
                };
            }
            if duration <= 0.0 {
                return PointMotion {
                    static_mm: 0.0,
                    motion: Some(MotionConfig::Step {
                        at_s: arrive,
                        height_mm: *height_mm,
                    }),
                };
            }
            if arrive >= 0.0 {
                return PointMotion {
                    static_mm: 0.0,
                    motion: Some(MotionConfig::Ramp {
                        start_s: arrive,
                        duration_s: duration,
                        height_mm: *height_mm,
                    }),
                };
            }
            // Mid-front at t = 0: the part already risen is static, the rest a ramp.
            let done = -arrive / duration;
            PointMotion {
                static_mm: height_mm * done,
                motion: Some(MotionConfig::Ramp {
                    start_s: 0.0,
                    duration_s: duration + arrive,
                    height_mm: height_mm * (1.0 - done),
                }),
            }
        }
        other => PointMotion {
            static_mm: 0.0,
            motion: Some(other.clone()),
        },
    }
}

/// The bound (min, max) of a spatial motion's depth change over the whole plane (mm).
pub(crate) fn range_mm(m: &MotionConfig) -> (f64, f64) {
    match m {
        MotionConfig::PlateMode { amplitude_mm, .. } => (-amplitude_mm, *amplitude_mm),
        MotionConfig::Rotor { blade_mm, .. } => (blade_mm.min(0.0), blade_mm.max(0.0)),
        MotionConfig::Edge { height_mm, .. } => (height_mm.min(0.0), height_mm.max(0.0)),
        _ => (0.0, 0.0),
    }
}

/// The rotor's depth pattern at its rim as a disk (for the scene's tones).
pub(crate) fn rotor_disk(m: &MotionConfig) -> Option<MotionConfig> {
    match m {
        MotionConfig::Rotor {
            centre_x_mm,
            centre_y_mm,
            radius_mm,
            ..
        } => reduce(m, centre_x_mm + radius_mm, *centre_y_mm).motion,
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(m: u32, n: u32) -> MotionConfig {
        MotionConfig::PlateMode {
            m,
            n,
            length_x_mm: 100.0,
            length_y_mm: 50.0,
            amplitude_mm: 0.2,
            frequency_hz: 1000.0,
            phase_deg: 10.0,
            x0_mm: 0.0,
            y0_mm: 0.0,
        }
    }

    /// The (2, 1) mode: +A·sin(π/2)… at the left antinode, the opposite phase across the
    /// nodal line x = Lx/2, nothing outside the plate.
    #[test]
    fn plate_mode_shape_and_its_nodal_line() {
        let left = reduce(&plate(2, 1), 25.0, 25.0).motion.unwrap();
        let right = reduce(&plate(2, 1), 75.0, 25.0).motion.unwrap();
        match (left, right) {
            (
                MotionConfig::Sine {
                    amplitude_mm: a,
                    phase_deg: p,
                    ..
                },
                MotionConfig::Sine {
                    amplitude_mm: b,
                    phase_deg: q,
                    ..
                },
            ) => {
                assert!((a - 0.2).abs() < 1e-12 && (b - 0.2).abs() < 1e-12);
                assert_eq!((p, q), (10.0, 190.0));
            }
            other => panic!("{other:?}"),
        }
        assert!(reduce(&plate(2, 1), 50.0, 25.0).motion.is_none(), "node");
        assert!(
            reduce(&plate(2, 1), 150.0, 25.0).motion.is_none(),
            "outside"
        );
    }

    /// An edge moving at 10 mm/s along +x from x = 0: the pixel at x = 5 mm steps at 0.5 s;
    /// one at x = −1 mm has stepped already.
    #[test]
    fn edge_arrival_times() {
        let e = MotionConfig::Edge {
            height_mm: -3.0,
            velocity_mm_per_s: 10.0,
            direction_deg: 0.0,
            start_mm: 0.0,
            width_mm: 0.0,
        };
        assert_eq!(
            reduce(&e, 5.0, 7.0).motion,
            Some(MotionConfig::Step {
                at_s: 0.5,
                height_mm: -3.0
            })
        );
        assert_eq!(reduce(&e, -1.0, 0.0).static_mm, -3.0);
    }

    /// A 3-blade rotor: a point on the blades sees a disk turning at rpm/60 whose pattern
    /// repeats 3 times per turn (blade-pass 3·rpm/60); a point beyond the tip sees nothing.
    #[test]
    fn rotor_blades_pass() {
        let r = MotionConfig::Rotor {
            blades: 3,
            rpm: 6000.0,
            centre_x_mm: 0.0,
            centre_y_mm: 0.0,
            radius_mm: 10.0,
            hub_radius_mm: 1.0,
            blade_mm: -2.0,
            blade_fraction: 0.5,
            phase_deg: 0.0,
        };
        match reduce(&r, 5.0, 0.0).motion {
            Some(MotionConfig::Disk {
                depths_mm,
                revolutions_per_s,
                ..
            }) => {
                assert_eq!(revolutions_per_s, 100.0);
                assert_eq!(depths_mm.len(), 3 * SECTORS_PER_BLADE);
                assert_eq!(depths_mm.iter().filter(|&&d| d == -2.0).count(), 48);
            }
            other => panic!("{other:?}"),
        }
        assert!(reduce(&r, 11.0, 0.0).motion.is_none());
        assert!(reduce(&r, 0.5, 0.0).motion.is_none(), "inside the hub");
    }
}
