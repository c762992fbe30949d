//! The one error type of the pixel crate. Every message names the field, the value it had,
//! what the hardware allows and, where one exists, the nearest value that would work, so a
//! user can fix a `[pixel]` section from the message alone.

use thiserror::Error;

/// Errors of the bit-true pixel model and its configuration.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum PixelError {
    /// A parameter outside what the hardware can do.
    #[error("pixel.{field} = {value} is not possible: {reason}; nearest valid value: {nearest}")]
    Invalid {
        /// The `[pixel]` key (or derived quantity) at fault.
        field: &'static str,
        /// The value it had.
        value: String,
        /// Why the hardware cannot do it (the allowed range).
        reason: String,
        /// The nearest value that would work.
        nearest: String,
    },
    /// Stimuli or a ROM that do not match the configuration they are run with.
    #[error("{what}: got {got}, the configuration needs {needed}")]
    Mismatch {
        /// What does not match.
        what: &'static str,
        /// What was supplied.
        got: String,
        /// What the configuration needs.
        needed: String,
    },
    /// A valid pulse whose TDC code the pixel's T pins cannot carry.
    #[error(
        "`tdc[{pulse}]` = {code} is outside the pixel's TDC codes 0 ..= {max} \
         (pixel.tdc_bits = {bits}); a code in that range would work, or valid[{pulse}] = False"
    )]
    CodeOutOfRange {
        /// The first such pulse.
        pulse: usize,
        /// Its code (as written: any integer type's value).
        code: String,
        /// The largest code, 2^T − 1.
        max: u32,
        /// T.
        bits: u32,
    },
}

impl PixelError {
    /// Builds a [`PixelError::Invalid`].
    pub fn invalid(
        field: &'static str,
        value: impl ToString,
        reason: impl ToString,
        nearest: impl ToString,
    ) -> Self {
        PixelError::Invalid {
            field,
            value: value.to_string(),
            reason: reason.to_string(),
            nearest: nearest.to_string(),
        }
    }

    /// Builds a [`PixelError::Mismatch`].
    pub fn mismatch(what: &'static str, got: impl ToString, needed: impl ToString) -> Self {
        PixelError::Mismatch {
            what,
            got: got.to_string(),
            needed: needed.to_string(),
        }
    }
}
