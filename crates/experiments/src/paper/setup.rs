//! Builds the photon source of one experiment: σ_s (total) → jitter, window and depth.

use tofprobe_dsp::closed_form::jitter_for_total_mm;
use tofprobe_scene::{MM_PER_PS, MotionConfig, PhotonSource, Scene, SceneConfig, SensorConfig};

use crate::ExperimentError;

/// Laser rate of every experiment (the paper's 10 MHz).
pub const FS_HZ: f64 = 10e6;
/// TDC LSB of the Table 2 experiments (mm).
pub const LSB_MM: f64 = 1.0;
/// The noise band of Table 2 (Hz).
pub const BAND: (f64, f64) = (1_000.0, 10_000.0);
/// The tone frequency of Table 2's amplitude rows.
pub const F0_HZ: f64 = 4_500.0;
/// The timing window where background matters (mm).
pub const BG_WINDOW_MM: f64 = 60.0;

/// One sensor + scene setting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// Total σ_s (jitter and TDC quantisation), mm.
    pub sigma_s_mm: f64,
    pub lsb_mm: f64,
    pub rho_s: f64,
    pub rho_b: f64,
    /// Timing window length (mm); the window starts at 0 and δ0 is its centre.
    pub window_mm: f64,
    /// Optional sine motion (Hz, amplitude mm).
    pub tone: Option<(f64, f64)>,
}

impl Setup {
    /// The window rule: 60 mm with background; with ρ_b = 0, max(60, 12σ_s) so that the
    /// window holds ±6σ_s and never clips the jitter (a clipped tail would read as missed
    /// pulses and shrink σ).
    pub fn window_for(sigma_s_mm: f64, rho_b: f64) -> f64 {
        if rho_b > 0.0 {
            BG_WINDOW_MM
        } else {
            BG_WINDOW_MM.max(12.0 * sigma_s_mm)
        }
    }

    pub fn depth_mm(&self) -> f64 {
        0.5 * self.window_mm
    }

    /// Jitter σ_I giving the total σ_s with this LSB: sqrt(σ_s² − a²/12).
    pub fn jitter_mm(&self) -> Result<f64, ExperimentError> {
        Ok(jitter_for_total_mm(self.sigma_s_mm, self.lsb_mm)?)
    }

    pub fn source(&self, seed: u64) -> Result<PhotonSource, ExperimentError> {
        let sensor = SensorConfig {
            laser_rate_hz: FS_HZ,
            jitter_ps: self.jitter_mm()? / MM_PER_PS,
            tdc_lsb_ps: self.lsb_mm / MM_PER_PS,
            window_start_ps: 0.0,
            window_length_ps: self.window_mm / MM_PER_PS,
            signal_rate: self.rho_s,
            background_rate: self.rho_b,
        };
        let motions = self
            .tone
            .map(|(f, a)| MotionConfig::Sine {
                amplitude_mm: a,
                frequency_hz: f,
                phase_deg: 0.0,
            })
            .into_iter()
            .collect();
        let scene = Scene::new(&SceneConfig {
            depth_mm: self.depth_mm(),
            motions,
        })?;
        Ok(PhotonSource::new(&sensor, &scene, seed)?)
    }
}
