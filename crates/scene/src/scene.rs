//! `[scene]` and the motion model δ(t) = δ0 + Σ motions, evaluated either at one time or,
//! fast, over a block of consecutive laser pulses.

use std::f64::consts::{PI, TAU};

use serde::{Deserialize, Serialize};

use crate::error::{SceneError, check_range};
use crate::motion::MotionConfig;

/// Highest harmonic of a square wave or disk listed by [`Scene::tones`].
pub const MAX_HARMONIC: u32 = 63;

/// The scene section: a static depth plus a list of motions (`[[scene.motion]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// Static depth δ0 (mm).
    pub depth_mm: f64,
    /// Motions added to δ0, written as `[[scene.motion]]` tables.
    #[serde(default, rename = "motion", skip_serializing_if = "Vec::is_empty")]
    pub motions: Vec<MotionConfig>,
}

/// A validated scene: δ(t) in mm for t in seconds.
#[derive(Debug, Clone)]
pub struct Scene {
    depth_mm: f64,
    motions: Vec<MotionConfig>,
}

impl Scene {
    /// Validates the configuration and builds the scene.
    pub fn new(config: &SceneConfig) -> Result<Scene, SceneError> {
        check_range("scene.depth_mm", config.depth_mm, 0.0, 1e9)?;
        for (i, m) in config.motions.iter().enumerate() {
            m.validate(i)?;
        }
        Ok(Scene {
            depth_mm: config.depth_mm,
            motions: config.motions.clone(),
        })
    }

    /// The static depth δ0 (mm).
    pub fn static_depth_mm(&self) -> f64 {
        self.depth_mm
    }

    /// The motions, as configured.
    pub fn motions(&self) -> &[MotionConfig] {
        &self.motions
    }

    /// Whether a motion depends on position (the scene needs an array to be sampled); the
    /// first such motion's index and kind.
    pub fn spatial_motion(&self) -> Option<(usize, &'static str)> {
        self.motions
            .iter()
            .enumerate()
            .find(|(_, m)| m.is_spatial())
            .map(|(i, m)| (i, m.kind()))
    }

    /// The scene one point (x, y) mm of the plane sees: every spatial motion reduced to the
    /// temporal motion (and static offset) at that point ([`crate::spatial::reduce`]),
    /// temporal motions as they are.
    pub fn at_point(&self, x_mm: f64, y_mm: f64) -> Scene {
        let mut depth_mm = self.depth_mm;
        let mut motions = Vec::with_capacity(self.motions.len());
        for m in &self.motions {
            let p = crate::spatial::reduce(m, x_mm, y_mm);
            depth_mm += p.static_mm;
            motions.extend(p.motion);
        }
        Scene { depth_mm, motions }
    }

    /// δ(t) in mm at time `t_s` seconds.
    pub fn depth_mm(&self, t_s: f64) -> f64 {
        self.depth_mm + self.motions.iter().map(|m| motion_at(m, t_s)).sum::<f64>()
    }

    /// A bound on δ(t) over all t: (min, max) in mm. Each motion contributes its own
    /// extremes, so the bound is tight for one motion and conservative for several.
    pub fn depth_range_mm(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (self.depth_mm, self.depth_mm);
        for m in &self.motions {
            let (a, b) = match m {
                MotionConfig::Sine { amplitude_mm, .. }
                | MotionConfig::Square { amplitude_mm, .. } => (-amplitude_mm, *amplitude_mm),
                MotionConfig::Disk { depths_mm, .. } => depths_mm
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| {
                        (a.min(d), b.max(d))
                    }),
                MotionConfig::Step { height_mm, .. }
                | MotionConfig::Ramp { height_mm, .. }
                | MotionConfig::Impulse { height_mm, .. } => {
                    (height_mm.min(0.0), height_mm.max(0.0))
                }
                spatial => crate::spatial::range_mm(spatial),
            };
            lo += a;
            hi += b;
        }
        (lo, hi)
    }

    /// Checks every sine/square frequency against the Nyquist rate of the pulse train.
    pub fn check_nyquist(&self, laser_rate_hz: f64) -> Result<(), SceneError> {
        for (i, m) in self.motions.iter().enumerate() {
            if let Some(f) = m.tone_hz()
                && f >= laser_rate_hz / 2.0
            {
                return Err(SceneError::out_of_range(
                    format!("scene.motion[{i}].frequency_hz"),
                    f,
                    format!(
                        "0 < frequency_hz < laser_rate_hz / 2 = {} (Nyquist)",
                        laser_rate_hz / 2.0
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The scene's tones as (frequency Hz, amplitude mm), for choosing DFT bins: sines
    /// exactly; square waves and disks as their Fourier-series harmonics up to
    /// `MAX_HARMONIC` (those with a non-negligible amplitude). Steps, ramps and impulses
    /// are not periodic and have no tones. Tones at the same frequency are not merged.
    pub fn tones(&self) -> Vec<(f64, f64)> {
        let mut tones = Vec::new();
        // A spatial motion's tones are those of its largest response: a plate mode at its
        // antinode, a rotor at its blade tips; an edge has none.
        let as_temporal: Vec<MotionConfig> = self
            .motions
            .iter()
            .filter_map(|m| match m {
                MotionConfig::PlateMode {
                    amplitude_mm,
                    frequency_hz,
                    phase_deg,
                    ..
                } => Some(MotionConfig::Sine {
                    amplitude_mm: *amplitude_mm,
                    frequency_hz: *frequency_hz,
                    phase_deg: *phase_deg,
                }),
                MotionConfig::Rotor { .. } => crate::spatial::rotor_disk(m),
                other => Some(other.clone()),
            })
            .collect();
        for m in &as_temporal {
            match m {
                MotionConfig::Sine {
                    amplitude_mm,
                    frequency_hz,
                    ..
                } => tones.push((*frequency_hz, *amplitude_mm)),
                MotionConfig::Square {
                    amplitude_mm,
                    frequency_hz,
                    duty,
                    ..
                } => {
                    // ±A with duty D: harmonic k has amplitude (4A / πk)·|sin(πkD)|
                    // (odd harmonics 4A/πk only, at D = 1/2).
                    for k in 1..=MAX_HARMONIC {
                        let kf = f64::from(k);
                        let a = 4.0 * amplitude_mm / (PI * kf) * (PI * kf * duty).sin().abs();
                        if a > 1e-12 * amplitude_mm.max(f64::MIN_POSITIVE) {
                            tones.push((kf * frequency_hz, a));
                        }
                    }
                }
                MotionConfig::Disk {
                    depths_mm,
                    revolutions_per_s,
                    ..
                } => {
                    let m_len = depths_mm.len() as f64;
                    let scale = depths_mm.iter().fold(0.0f64, |a, d| a.max(d.abs()));
                    for k in 1..=MAX_HARMONIC {
                        let kf = f64::from(k);
                        // Complex Fourier coefficient of the piecewise-constant sector
                        // pattern: c_k = Σ_j d_j (e^{−iθ_j} − e^{−iθ_{j+1}}) / (2πik).
                        let (mut re, mut im) = (0.0, 0.0);
                        for (j, d) in depths_mm.iter().enumerate() {
                            let a0 = TAU * kf * j as f64 / m_len;
                            let a1 = TAU * kf * (j + 1) as f64 / m_len;
                            // e^{−ia0} − e^{−ia1}
                            re += d * (a0.cos() - a1.cos());
                            im += d * (-a0.sin() + a1.sin());
                        }
                        let c = (re * re + im * im).sqrt() / (TAU * kf);
                        let a = 2.0 * c;
                        if a > 1e-9 * scale.max(f64::MIN_POSITIVE) {
                            tones.push((kf * revolutions_per_s, a));
                        }
                    }
                }
                _ => {}
            }
        }
        tones
    }

    /// Writes δ(t_n) (mm) for pulses n = first_pulse .. first_pulse + out.len(), with
    /// t_n = n · period_s. Sines use a rotation recurrence anchored with an exact sin/cos at
    /// `first_pulse`, so the cost per pulse is a few multiplies; over one block of
    /// [`crate::BLOCK_PULSES`] its error stays below 1e-12 of the amplitude (see the tests).
    ///
    /// A spatial motion has no value without a position: it contributes 0 here (a photon
    /// source refuses such a scene; an array samples `at_point`).
    pub fn fill_depths_mm(&self, first_pulse: u64, period_s: f64, out: &mut [f64]) {
        out.fill(self.depth_mm);
        for m in &self.motions {
            match m {
                MotionConfig::Sine {
                    amplitude_mm,
                    frequency_hz,
                    phase_deg,
                } => {
                    // Phase of the anchor reduced modulo one period in cycles first, so
                    // the angle stays small and accurate for large pulse indices.
                    let cycles =
                        (*frequency_hz * period_s * first_pulse as f64).fract() + phase_deg / 360.0;
                    let (mut s, mut c) = (TAU * cycles).sin_cos();
                    let (ds, dc) = (TAU * frequency_hz * period_s).sin_cos();
                    for d in out.iter_mut() {
                        *d += amplitude_mm * s;
                        let s1 = s * dc + c * ds;
                        c = c * dc - s * ds;
                        s = s1;
                    }
                }
                _ => {
                    for (i, d) in out.iter_mut().enumerate() {
                        let t = (first_pulse + i as u64) as f64 * period_s;
                        *d += motion_at(m, t);
                    }
                }
            }
        }
    }
}

/// Fractional part of x in [0, 1), also for negative x.
fn frac(x: f64) -> f64 {
    x - x.floor()
}

/// The contribution of one motion at time t (s).
fn motion_at(m: &MotionConfig, t: f64) -> f64 {
    match m {
        MotionConfig::Sine {
            amplitude_mm,
            frequency_hz,
            phase_deg,
        } => amplitude_mm * (TAU * (frac(frequency_hz * t) + phase_deg / 360.0)).sin(),
        MotionConfig::Square {
            amplitude_mm,
            frequency_hz,
            duty,
            phase_deg,
        } => {
            if frac(frequency_hz * t + phase_deg / 360.0) < *duty {
                *amplitude_mm
            } else {
                -amplitude_mm
            }
        }
        MotionConfig::Disk {
            depths_mm,
            revolutions_per_s,
            phase_deg,
        } => {
            let pos = frac(revolutions_per_s * t + phase_deg / 360.0) * depths_mm.len() as f64;
            depths_mm[(pos as usize).min(depths_mm.len() - 1)]
        }
        MotionConfig::Step { at_s, height_mm } => {
            if t >= *at_s {
                *height_mm
            } else {
                0.0
            }
        }
        MotionConfig::Ramp {
            start_s,
            duration_s,
            height_mm,
        } => height_mm * ((t - start_s) / duration_s).clamp(0.0, 1.0),
        MotionConfig::Impulse {
            start_s,
            width_s,
            height_mm,
        } => {
            if t >= *start_s && t < start_s + width_s {
                *height_mm
            } else {
                0.0
            }
        }
        MotionConfig::PlateMode { .. } | MotionConfig::Rotor { .. } | MotionConfig::Edge { .. } => {
            0.0
        }
    }
}
