//! `ExperimentError`: every way a study on a resolved design fails (the design itself, a model,
//! a tool, an output file). Messages name what to change or install.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the experiments crate.
#[derive(Debug, Error)]
pub enum ExperimentError {
    /// The configuration does not resolve (the message names the key and a valid value).
    #[error(transparent)]
    Design(Box<tofprobe_design::DesignError>),
    /// A float reference refused its input.
    #[error(transparent)]
    Dsp(#[from] tofprobe_dsp::DspError),
    /// The scene or sensor model refused its input.
    #[error(transparent)]
    Scene(#[from] tofprobe_scene::SceneError),
    /// The bit-true pixel refused its parameters.
    #[error(transparent)]
    Pixel(#[from] tofprobe_pixel::PixelError),
    /// A file of the paper reproduction cannot be written.
    #[error("cannot write `{path}`: {source}")]
    Io {
        /// The output path.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A plot cannot be drawn.
    #[error("plot `{path}`: {message}")]
    Plot {
        /// The output path.
        path: String,
        /// Why.
        message: String,
    },
    /// An output file cannot be written.
    #[error("cannot write `{path}`: {message}")]
    Output {
        /// The output path.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A study option out of range.
    #[error("--{option} = {value} is out of range: allowed {allowed}")]
    Option {
        /// The option's name without dashes.
        option: String,
        /// The value given.
        value: String,
        /// The allowed range.
        allowed: String,
    },
    /// A sizing report failed (tool or liberty missing, synthesis error, …).
    #[error("{0}")]
    Eda(#[from] tofprobe_eda::EdaError),
    /// RTL generation or vector writing failed.
    #[error("{0}")]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
    /// Co-simulation failed to run (a tool missing: the message names the install script).
    #[error("{0}")]
    Cosim(#[from] tofprobe_cosim::CosimError),
    /// The array model refused (boxed: it carries the design's error).
    #[error(transparent)]
    Array(#[from] Box<tofprobe_array::ArrayError>),
}

impl ExperimentError {
    /// An option out of range.
    pub fn option(option: &str, value: impl ToString, allowed: &str) -> Self {
        ExperimentError::Option {
            option: option.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }
}

// Boxed: the design error carries the generator's and the pixel's errors inline, and every
// study function returns this type (clippy::result_large_err).
impl From<tofprobe_design::DesignError> for ExperimentError {
    fn from(e: tofprobe_design::DesignError) -> Self {
        ExperimentError::Design(Box::new(e))
    }
}
