//! The crate's one error type.

use std::path::PathBuf;

/// Errors of the co-simulation drivers.
#[derive(Debug, thiserror::Error)]
pub enum CosimError {
    /// An EDA tool is not installed (or its `TOFPROBE_*` variable names no program).
    #[error("{0}; run scripts/install-tools.sh to install it")]
    MissingTool(tofprobe_io::tools::ToolNotFound),
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
        "{}: the RTL was rendered for {} = {}, the configuration being run has {} = {}: re-render it (`tofprobe rtl`) or run the configuration it was rendered for",
        .0.dir.display(), .0.parameter, .0.rtl, .0.parameter, .0.config
    )]
    RtlMismatch(Box<ParamDiff>),
    /// The RTL's header cannot be read.
    #[error("{path}: {message}")]
    RtlHeader { path: PathBuf, message: String },
    /// The probe ROM image in the RTL directory is malformed or fails its manifest.
    #[error("probe ROM {path}: {message}")]
    RomImage { path: PathBuf, message: String },
    /// The probe ROM image differs from the configuration's ROM.
    #[error(
        "{}: the probe ROM image differs from the configuration's ROM at entry {}: register bit(s) {:?} differ (RTL {}, configuration {}); {} entr(y/ies) differ in all",
        .0.dir.display(), .0.entry, .0.bits, .0.rtl, .0.config, .0.differing
    )]
    RomMismatch(Box<RomDiff>),
    /// An option outside its range.
    #[error("{option} = {value} is out of range: {allowed}")]
    Option {
        option: &'static str,
        value: String,
        allowed: String,
    },
    /// A report file exists and was not written by this generator.
    #[error(
        "{path}: exists and was not written by tofprobe-cosim: refusing to overwrite it; remove it or choose another file"
    )]
    Foreign { path: PathBuf },
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

/// A parameter of `--rtl DIR` that differs from the configuration's.
#[derive(Debug)]
pub struct ParamDiff {
    pub dir: PathBuf,
    pub parameter: String,
    pub rtl: String,
    pub config: String,
}

/// The first ROM entry of `--rtl DIR` that differs from the configuration's ROM.
#[derive(Debug)]
pub struct RomDiff {
    pub dir: PathBuf,
    pub entry: usize,
    /// Register bits of that entry that differ.
    pub bits: Vec<usize>,
    pub rtl: String,
    pub config: String,
    /// Entries that differ in all.
    pub differing: usize,
}
