//! `FlowError`: every way the hardware flow fails (the design, an experiment it reports on,
//! a tool, an output file). Messages name what to change or install.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the flow crate.
#[derive(Debug, Error)]
pub enum FlowError {
    /// The configuration does not resolve (the message names the key and a valid value).
    #[error(transparent)]
    Design(Box<tofprobe_design::DesignError>),
    /// An experiment the flow reports on failed (spectrum, transients, options).
    #[error(transparent)]
    Experiment(Box<tofprobe_experiments::ExperimentError>),
    /// A float reference refused its input.
    #[error(transparent)]
    Dsp(#[from] tofprobe_dsp::DspError),
    /// The scene or sensor model refused its input.
    #[error(transparent)]
    Scene(#[from] tofprobe_scene::SceneError),
    /// The bit-true pixel refused its parameters.
    #[error(transparent)]
    Pixel(#[from] tofprobe_pixel::PixelError),
    /// A sizing report or sign-off step failed (tool or liberty missing, synthesis error, …).
    #[error("{0}")]
    Eda(#[from] tofprobe_eda::EdaError),
    /// RTL generation or vector writing failed.
    #[error("{0}")]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
    /// The array model refused (a shape, a pixel's stream).
    #[error(transparent)]
    Array(Box<tofprobe_array::ArrayError>),
    /// Co-simulation failed to run (a tool missing: the message names the install script).
    #[error("{0}")]
    Cosim(#[from] tofprobe_cosim::CosimError),
}

impl FlowError {
    /// An option out of range (the same error, and message, as an experiment's).
    pub fn option(option: &str, value: impl ToString, allowed: &str) -> Self {
        tofprobe_experiments::ExperimentError::option(option, value, allowed).into()
    }

    /// An output that cannot be written.
    pub fn output(path: PathBuf, message: String) -> Self {
        tofprobe_experiments::ExperimentError::Output { path, message }.into()
    }
}

// Boxed: the design and experiment errors carry other crates' errors inline, and every flow
// function returns this type (clippy::result_large_err).
impl From<tofprobe_design::DesignError> for FlowError {
    fn from(e: tofprobe_design::DesignError) -> Self {
        FlowError::Design(Box::new(e))
    }
}

impl From<tofprobe_array::ArrayError> for FlowError {
    fn from(e: tofprobe_array::ArrayError) -> Self {
        FlowError::Array(Box::new(e))
    }
}

impl From<tofprobe_experiments::ExperimentError> for FlowError {
    fn from(e: tofprobe_experiments::ExperimentError) -> Self {
        match e {
            tofprobe_experiments::ExperimentError::Design(d) => FlowError::Design(d),
            other => FlowError::Experiment(Box::new(other)),
        }
    }
}
