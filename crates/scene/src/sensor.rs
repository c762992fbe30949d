//! `[sensor]`: the laser, the SPAD's timing jitter, the TDC and its timing window, and the
//! signal/background photon rates per pulse.

use serde::{Deserialize, Serialize};

use crate::MM_PER_PS;
use crate::error::{SceneError, check_positive, check_range};

/// Largest number of TDC codes in the window (16-bit codes, the pixel contract's T ≤ 16).
pub const MAX_TDC_CODES: u32 = 1 << 16;

/// The sensor section of the configuration. All times in picoseconds of round-trip time
/// of flight (1 ps ↔ [`MM_PER_PS`] mm of depth); rates are mean photons per laser pulse.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// Laser pulse rate f_s (Hz).
    pub laser_rate_hz: f64,
    /// Gaussian timing jitter σ_I of a signal photon (ps, one sigma).
    pub jitter_ps: f64,
    /// TDC least significant bit (ps).
    pub tdc_lsb_ps: f64,
    /// Start of the timing window (ps after the laser pulse); code 0 starts here.
    pub window_start_ps: f64,
    /// Length of the timing window (ps); arrivals after it are not detected.
    pub window_length_ps: f64,
    /// Signal rate ρ_s: probability that a pulse yields a signal photon (0..1).
    pub signal_rate: f64,
    /// Background rate ρ_b: mean background arrivals per pulse inside the window (Poisson).
    pub background_rate: f64,
}

impl SensorConfig {
    /// Checks every field against its allowed range.
    pub fn validate(&self) -> Result<(), SceneError> {
        check_positive("sensor.laser_rate_hz", self.laser_rate_hz, 1e10)?;
        check_range("sensor.jitter_ps", self.jitter_ps, 0.0, 1e6)?;
        check_positive("sensor.tdc_lsb_ps", self.tdc_lsb_ps, 1e6)?;
        check_range("sensor.window_start_ps", self.window_start_ps, 0.0, 1e9)?;
        check_positive("sensor.window_length_ps", self.window_length_ps, 1e9)?;
        check_range("sensor.signal_rate", self.signal_rate, 0.0, 1.0)?;
        check_range("sensor.background_rate", self.background_rate, 0.0, 100.0)?;
        if self.window_length_ps < self.tdc_lsb_ps {
            return Err(SceneError::out_of_range(
                "sensor.window_length_ps",
                self.window_length_ps,
                format!(
                    "window_length_ps >= tdc_lsb_ps = {} (at least one TDC code)",
                    self.tdc_lsb_ps
                ),
            ));
        }
        let codes = (self.window_length_ps / self.tdc_lsb_ps - 1e-9).ceil();
        if codes > f64::from(MAX_TDC_CODES) {
            return Err(SceneError::out_of_range(
                "sensor.window_length_ps",
                self.window_length_ps,
                format!(
                    "window_length_ps / tdc_lsb_ps <= {MAX_TDC_CODES} codes, i.e. \
                     window_length_ps <= {}",
                    f64::from(MAX_TDC_CODES) * self.tdc_lsb_ps
                ),
            ));
        }
        // The window must close before the next laser pulse fires, otherwise a late photon
        // would be attributed to the wrong pulse.
        let period_ps = 1e12 / self.laser_rate_hz;
        let end = self.window_start_ps + self.window_length_ps;
        if end > period_ps {
            return Err(SceneError::out_of_range(
                "sensor.window_length_ps",
                self.window_length_ps,
                format!(
                    "window_start_ps + window_length_ps <= laser period 1e12/laser_rate_hz = \
                     {period_ps} ps, i.e. window_length_ps <= {}",
                    period_ps - self.window_start_ps
                ),
            ));
        }
        Ok(())
    }

    /// Timing jitter as depth (mm, one sigma).
    pub fn jitter_mm(&self) -> f64 {
        self.jitter_ps * MM_PER_PS
    }

    /// TDC LSB as depth (mm).
    pub fn tdc_lsb_mm(&self) -> f64 {
        self.tdc_lsb_ps * MM_PER_PS
    }

    /// Window start as depth (mm).
    pub fn window_start_mm(&self) -> f64 {
        self.window_start_ps * MM_PER_PS
    }

    /// Window end as depth (mm).
    pub fn window_end_mm(&self) -> f64 {
        (self.window_start_ps + self.window_length_ps) * MM_PER_PS
    }

    /// Number of TDC codes in the window: ceil(window_length / lsb); a last partial bin
    /// counts as a code. (A tiny tolerance keeps 400/5 at exactly 80.)
    pub fn tdc_codes(&self) -> u32 {
        let codes = (self.window_length_ps / self.tdc_lsb_ps - 1e-9).ceil();
        codes.clamp(1.0, f64::from(MAX_TDC_CODES)) as u32
    }

    /// Bits of an unsigned TDC code covering [`Self::tdc_codes`] codes (at least 1).
    pub fn tdc_bits(&self) -> u32 {
        let codes = self.tdc_codes();
        if codes <= 1 {
            1
        } else {
            u32::BITS - (codes - 1).leading_zeros()
        }
    }
}
