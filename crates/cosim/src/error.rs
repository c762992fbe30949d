//! The crate's one error type.

use std::path::PathBuf;

/// Errors of the co-simulation drivers.
#[derive(Debug, thiserror::Error)]
pub enum CosimError {
    /// An EDA tool is not installed.
    #[error("`{tool}` was not found on PATH: run scripts/install-tools.sh to install it")]
    MissingTool { tool: &'static str },
    /// A tool ran but failed.
    #[error("{tool} failed (exit status {status}); its output:\n{output}")]
    ToolFailed {
        tool: &'static str,
        status: String,
        output: String,
    },
    /// The harness printed no completion line.
    #[error("{tool} ended without its completion line; its output:\n{output}")]
    NoCompletion { tool: &'static str, output: String },
    /// The configuration does not fit the harness.
    #[error(
        "registers = {value} is out of range for co-simulation: allowed 1..=64 (the harness watches a 64-bit write-enable vector)"
    )]
    TooManyRegisters { value: usize },
    /// Rendering or vector generation failed.
    #[error(transparent)]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
    /// The pixel rejects the parameters (the one validation).
    #[error(transparent)]
    Pixel(#[from] tofprobe_pixel::PixelError),
    /// File-system error, with the path.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl CosimError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        CosimError::Io {
            path: path.into(),
            source,
        }
    }
}
