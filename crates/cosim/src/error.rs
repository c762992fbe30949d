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
    /// `--rtl DIR` was rendered for other parameters than the configuration being run.
    #[error(
        "{dir}: the RTL was rendered for {parameter} = {rtl}, the configuration being run has {parameter} = {config}: re-render it (`tofprobe rtl`) or run the configuration it was rendered for"
    )]
    RtlMismatch {
        dir: PathBuf,
        parameter: String,
        rtl: String,
        config: String,
    },
    /// The RTL's header cannot be read.
    #[error("{path}: {message}")]
    RtlHeader { path: PathBuf, message: String },
    /// The probe ROM image in the RTL directory is malformed or fails its manifest.
    #[error("probe ROM {path}: {message}")]
    RomImage { path: PathBuf, message: String },
    /// The probe ROM image differs from the configuration's ROM.
    #[error(
        "{dir}: the probe ROM image differs from the configuration's ROM at entry {entry}: register bit(s) {bits:?} differ (RTL {rtl}, configuration {config}); {differing} entr(y/ies) differ in all"
    )]
    RomMismatch {
        dir: PathBuf,
        entry: usize,
        bits: Vec<usize>,
        rtl: String,
        config: String,
        differing: usize,
    },
    /// An option outside its range.
    #[error("{option} = {value} is out of range: {allowed}")]
    Option {
        option: &'static str,
        value: String,
        allowed: String,
    },
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
