//! The one error type of the scene crate: every message names the offending field, its
//! value and the allowed range (and, where one exists, a value that would work).

use thiserror::Error;

/// Why a scene, sensor or acquisition configuration was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SceneError {
    /// A single value lies outside its allowed range.
    #[error("{field} = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// Dotted path of the field, e.g. `sensor.signal_rate`.
        field: String,
        /// The rejected value, as written.
        value: String,
        /// The allowed range, in words or as an inequality.
        allowed: String,
    },
    /// The scene's depth range does not fit in the sensor's timing window. Blames
    /// `scene.depth_mm` (with the range of depths that fit) when the motion fits the
    /// window at all, else the motion's size against the window's length.
    #[error("scene.depth_mm = {depth_mm} {span}; allowed: {allowed}")]
    WindowExcludesDepth {
        /// `scene.depth_mm` as configured.
        depth_mm: f64,
        /// The depth range its motion spans and the window it leaves (with the
        /// `sensor.window_start_ps` / `window_length_ps` that set it), in words.
        span: String,
        /// The range of `scene.depth_mm` (or the window) that would work, in words.
        allowed: String,
    },
    /// Neither or both of `acquisition.pulses` and `acquisition.duration_s` were given.
    #[error(
        "acquisition: give exactly one of `pulses` (an integer >= 1) or `duration_s` \
         (seconds > 0); got {given}"
    )]
    PulsesOrDuration {
        /// What was given, in words.
        given: String,
    },
    /// A time-tagged record file (PicoQuant PTU, Becker & Hickl SPC) could not be read or
    /// replayed: the file, where in it, what the reader expected and what it found.
    #[error("{file}: {at}: expected {expected}, found {found}")]
    Tttr {
        /// The file as given.
        file: String,
        /// Where: `header tag 12 (TTResult_NumberOfRecords)`, `record 1234 (byte 5800)`, …
        at: String,
        /// What the reader expected there (and, for options, the value that would work).
        expected: String,
        /// What it found.
        found: String,
    },
}

impl SceneError {
    /// Shorthand for [`SceneError::OutOfRange`].
    pub fn out_of_range(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        SceneError::OutOfRange {
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }
}

/// Checks `lo <= v <= hi` (and finiteness); `what` names the field.
pub(crate) fn check_range(field: &str, v: f64, lo: f64, hi: f64) -> Result<(), SceneError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(SceneError::out_of_range(
            field,
            tofprobe_io::text::number(v),
            format!("{lo} <= {} <= {hi}", leaf(field)),
        ))
    }
}

/// Checks `lo < v <= hi` (and finiteness).
pub(crate) fn check_positive(field: &str, v: f64, hi: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 && v <= hi {
        Ok(())
    } else {
        Err(SceneError::out_of_range(
            field,
            tofprobe_io::text::number(v),
            format!("0 < {} <= {hi}", leaf(field)),
        ))
    }
}

/// The last component of a dotted field path, for the range text.
fn leaf(field: &str) -> &str {
    field.rsplit('.').next().unwrap_or(field)
}
