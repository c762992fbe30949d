//! `CliError`: every way a `tofprobe` command can fail on user input or I/O. `main` prints
//! it as `error: …` and exits with status 2; nothing here panics.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the CLI crate.
#[derive(Debug, Error)]
pub enum CliError {
    /// The configuration file does not exist or cannot be read.
    #[error("cannot read configuration `{path}`: {source}")]
    Read {
        /// The path as given.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The configuration path is a directory.
    #[error("configuration `{path}` is a directory; expected a TOML file")]
    IsDirectory {
        /// The path as given.
        path: PathBuf,
    },
    /// The configuration file is not valid UTF-8.
    #[error(
        "configuration `{path}` is not valid UTF-8 (first invalid byte at offset {offset}); \
         TOML files must be UTF-8"
    )]
    NotUtf8 {
        /// The path as given.
        path: PathBuf,
        /// Byte offset of the first invalid sequence.
        offset: usize,
    },
    /// TOML syntax error or a key/value that does not fit the schema (the message of the
    /// toml crate carries the line and column).
    #[error("in configuration `{origin}`: {message}")]
    Toml {
        /// The file name, or `<embedded default>`.
        origin: String,
        /// The parser's message, with line, column and the offending snippet.
        message: String,
    },
    /// A value out of range or inconsistent with another one.
    #[error("in configuration `{origin}`: {source}")]
    Scene {
        /// The file name, or `<embedded default>`.
        origin: String,
        /// What is wrong.
        source: tofprobe_scene::SceneError,
    },
    /// The `[pixel]` section cannot be built (the message names the key, the reason and
    /// the nearest valid value).
    #[error("in configuration `{origin}`: [pixel]: {source}")]
    Pixel {
        /// The file name, or `<embedded default>`.
        origin: String,
        /// What is wrong.
        source: tofprobe_pixel::PixelError,
    },
    /// The `[probe]` section or the probe ROM cannot be built.
    #[error("in configuration `{origin}`: [probe]: {source}")]
    Probe {
        /// The file name, or `<embedded default>`.
        origin: String,
        /// What is wrong.
        source: tofprobe_dsp::DspError,
    },
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
