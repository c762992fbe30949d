//! `[acquisition]`: how many laser pulses to simulate and the random seed.

use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// Largest record accepted (10^12 pulses, ~28 h at 10 MHz): beyond it a u64 pulse index
/// still works but run times stop making sense.
pub const MAX_PULSES: u64 = 1_000_000_000_000;

/// The acquisition section: exactly one of `pulses` or `duration_s`, and the seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AcquisitionConfig {
    /// Number of laser pulses N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulses: Option<u64>,
    /// Acquisition time (s); N = round(duration_s · laser_rate_hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// Seed of the Monte Carlo; the same seed gives the same record.
    #[serde(default)]
    pub seed: u64,
}

impl AcquisitionConfig {
    /// Number of pulses at the given laser rate (call [`Self::validate`] first; an invalid
    /// configuration gives 0 here).
    pub fn pulses(&self, laser_rate_hz: f64) -> u64 {
        match (self.pulses, self.duration_s) {
            (Some(n), _) => n,
            (None, Some(d)) if d.is_finite() && d > 0.0 => (d * laser_rate_hz).round() as u64,
            _ => 0,
        }
    }

    /// Checks that exactly one of `pulses` / `duration_s` is given and that N is in
    /// 1..=`MAX_PULSES`.
    pub fn validate(&self, laser_rate_hz: f64) -> Result<(), SceneError> {
        let n = match (self.pulses, self.duration_s) {
            (Some(_), Some(_)) => {
                return Err(SceneError::PulsesOrDuration {
                    given: "both".into(),
                });
            }
            (None, None) => {
                return Err(SceneError::PulsesOrDuration {
                    given: "neither".into(),
                });
            }
            (Some(n), None) => {
                if !(1..=MAX_PULSES).contains(&n) {
                    return Err(SceneError::out_of_range(
                        "acquisition.pulses",
                        n,
                        format!("1 <= pulses <= {MAX_PULSES}"),
                    ));
                }
                n
            }
            (None, Some(d)) => {
                let max_s = MAX_PULSES as f64 / laser_rate_hz;
                let min_s = 0.5 / laser_rate_hz;
                if !(d.is_finite() && d >= min_s && d <= max_s) {
                    return Err(SceneError::out_of_range(
                        "acquisition.duration_s",
                        d,
                        format!(
                            "{min_s:e} <= duration_s <= {max_s:e} (at least one pulse at \
                             laser_rate_hz = {laser_rate_hz})"
                        ),
                    ));
                }
                self.pulses(laser_rate_hz)
            }
        };
        debug_assert!(n >= 1);
        Ok(())
    }
}
