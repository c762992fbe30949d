//! `CliError`: every way a `tofprobe` command can fail on user input or I/O. `main` prints
//! it as `error: …` and exits with status 2; nothing here panics.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the CLI crate.
#[derive(Debug, Error)]
pub enum CliError {
    /// The configuration does not load or resolve (the message names the file, the key,
    /// the value and a valid one).
    #[error(transparent)]
    Design(#[from] tofprobe_design::DesignError),
    /// A study (spectrum, flow, sizing, reproduction, trade-off) failed.
    #[error(transparent)]
    Study(#[from] tofprobe_study::StudyError),
    /// An output file cannot be written.
    #[error("cannot write `{path}`: {message}")]
    Output {
        /// The output path.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A command-line option out of range.
    #[error("--{option} = {value} is out of range: allowed {allowed}")]
    Option {
        /// The option's name without dashes.
        option: String,
        /// The value given.
        value: String,
        /// The allowed range.
        allowed: String,
    },
    /// A sizing report failed (tool or liberty missing, synthesis error, …); the message
    /// says what to install or pass.
    #[error("{0}")]
    Report(#[from] tofprobe_report::ReportError),
    /// JSON serialisation failed (should not happen for plain numbers).
    #[error("cannot serialise JSON output: {0}")]
    Json(#[from] serde_json::Error),
    /// RTL generation or vector writing failed.
    #[error("{0}")]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
    /// Co-simulation failed to run (a tool missing: the message names the install script).
    #[error("{0}")]
    Cosim(#[from] tofprobe_cosim::CosimError),
}
