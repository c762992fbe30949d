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
    Design(Box<tofprobe_design::DesignError>),
    /// An experiment (spectrum, transients, reproduction, trade-off, options) failed.
    #[error(transparent)]
    Experiment(#[from] tofprobe_experiments::ExperimentError),
    /// The hardware flow (RTL, vectors, co-simulation, sizing, sign-off) failed.
    #[error(transparent)]
    Flow(Box<tofprobe_flow::FlowError>),
    /// `reproduce` could not run (not a missed row: that is the FAIL verdict).
    #[error("reproduce: {0}")]
    Reproduce(Box<tofprobe_experiments::ExperimentError>),
    /// Tile sets that `merge` refuses (the message names the set).
    #[error("merge: {0}")]
    Merge(String),
    /// An array run that cannot go ahead (the message names the array's key or the set).
    #[error("array: {0}")]
    Array(String),
    /// An output set read (`cosim --rtl`, `check-set`) is not whole: killed mid-commit or
    /// changed since (the message names the missing marker or the file that fails).
    #[error("{0}")]
    IncompleteSet(std::io::Error),
    /// `layout` failed (a tool missing names its Debian package; routing failure names
    /// the unrouted nets and the densities tried).
    #[error("layout: {0}")]
    Layout(#[from] tofprobe_layout::LayoutError),
    /// JSON serialisation failed (should not happen for plain numbers).
    /// An instruction set refused (`--isa`, `TOFPROBE_ISA`): its origin, value, the names
    /// allowed or what the CPU lacks.
    #[error(transparent)]
    Isa(#[from] tofprobe_io::isa::IsaError),
    #[error("cannot serialise JSON output: {0}")]
    Json(#[from] serde_json::Error),
}

impl CliError {
    /// A command-line option out of range.
    pub fn option(option: impl ToString, value: impl ToString, allowed: impl ToString) -> Self {
        CliError::Experiment(tofprobe_experiments::ExperimentError::Option {
            option: option.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        })
    }

    /// `reproduce`'s own failure, named as such.
    pub fn reproduce(e: tofprobe_experiments::ExperimentError) -> Self {
        CliError::Reproduce(Box::new(e))
    }

    /// An output file that cannot be written.
    pub fn output(path: PathBuf, message: String) -> Self {
        CliError::Experiment(tofprobe_experiments::ExperimentError::Output { path, message })
    }
}

/// Generator, co-simulation and report errors reach the CLI through the study crate's
/// error, which prints them as they are.
macro_rules! through_study {
    ($($t:ty),*) => {$(
        impl From<$t> for CliError {
            fn from(e: $t) -> Self {
                CliError::Experiment(e.into())
            }
        }
    )*};
}
through_study!(
    tofprobe_rtlgen::RtlError,
    tofprobe_cosim::CosimError,
    tofprobe_eda::EdaError
);

impl From<tofprobe_flow::FlowError> for CliError {
    fn from(e: tofprobe_flow::FlowError) -> Self {
        match e {
            tofprobe_flow::FlowError::Design(d) => CliError::Design(d),
            other => CliError::Flow(Box::new(other)),
        }
    }
}

impl From<tofprobe_array::ArrayError> for CliError {
    fn from(e: tofprobe_array::ArrayError) -> Self {
        match e {
            tofprobe_array::ArrayError::Design(d) => CliError::Design(d),
            tofprobe_array::ArrayError::Output { path, message } => CliError::output(path, message),
            e @ tofprobe_array::ArrayError::TileSet { .. } => CliError::Merge(e.to_string()),
            tofprobe_array::ArrayError::Option {
                option,
                value,
                allowed,
            } => CliError::option(option, value, allowed),
            other => CliError::Array(other.to_string()),
        }
    }
}

impl From<tofprobe_bench::BenchError> for CliError {
    fn from(e: tofprobe_bench::BenchError) -> Self {
        use tofprobe_bench::BenchError as B;
        match e {
            B::Design(d) => CliError::Design(d),
            B::Option {
                option,
                value,
                allowed,
            } => CliError::option(option, value, allowed),
            B::Output { path, message } => CliError::output(path, message),
            B::Isa(e) => CliError::Isa(e),
            B::Internal { bench, message } => CliError::option(
                format!("bench {bench}"),
                message,
                "an internal computation that succeeds",
            ),
        }
    }
}

// Boxed: the design error names the file, key and value inline (clippy::result_large_err).
impl From<tofprobe_design::DesignError> for CliError {
    fn from(e: tofprobe_design::DesignError) -> Self {
        CliError::Design(Box::new(e))
    }
}
