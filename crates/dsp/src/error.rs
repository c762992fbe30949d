//! The one error type of the dsp crate: every message names the offending field, its value
//! and what would be accepted, so a user can act on it.

use thiserror::Error;

/// Errors of the float references and the ΣΔ probe design.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DspError {
    /// A parameter outside its allowed range.
    #[error("{field} = {value} is out of range: allowed {allowed}{hint}")]
    OutOfRange {
        field: &'static str,
        value: String,
        allowed: String,
        /// Extra advice, already formatted with a leading "; " (or empty).
        hint: String,
    },
    /// A record too short (or empty) for what was asked of it.
    #[error("{what}: the record has {len} samples, at least {needed} are needed")]
    RecordTooShort {
        what: &'static str,
        len: usize,
        needed: usize,
    },
    /// The ΣΔ modulator's state left its bound: the input amplitude is too large.
    #[error(
        "the sigma-delta modulator is unstable at input amplitude {amplitude}: a state reached          {state:.3e} (bound {bound:.0e}) at sample {sample}; lower the amplitude{hint}"
    )]
    Unstable {
        amplitude: f64,
        sample: u64,
        state: f64,
        bound: f64,
        /// Extra advice, already formatted with a leading "; " (or empty).
        hint: String,
    },
    /// A scene or sensor the analysis simulates was rejected by the scene crate.
    #[error(transparent)]
    Scene(#[from] tofprobe_scene::SceneError),
    /// Reading or writing a file failed.
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// A ROM hex file or manifest that does not parse or does not match its manifest.
    #[error("{path}: line {line}: {message}")]
    RomFormat {
        path: String,
        line: usize,
        message: String,
    },
}

impl DspError {
    /// Convenience constructor for [`DspError::OutOfRange`] without a hint.
    pub fn out_of_range(field: &'static str, value: impl ToString, allowed: impl ToString) -> Self {
        DspError::OutOfRange {
            field,
            value: value.to_string(),
            allowed: allowed.to_string(),
            hint: String::new(),
        }
    }

    /// Adds advice (e.g. the value that would work) to an [`DspError::OutOfRange`].
    pub fn with_hint(self, hint: impl AsRef<str>) -> Self {
        match self {
            DspError::OutOfRange {
                field,
                value,
                allowed,
                ..
            } => DspError::OutOfRange {
                field,
                value,
                allowed,
                hint: format!("; {}", hint.as_ref()),
            },
            other => other,
        }
    }
}
