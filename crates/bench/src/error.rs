//! `BenchError`: the ways a benchmark can fail — a configuration that does not resolve, an
//! option out of range, an output that cannot be written, or an internal computation that
//! did not succeed (named with the benchmark).

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the benchmark crate.
#[derive(Debug, Error)]
pub enum BenchError {
    /// The configuration does not load or resolve.
    #[error(transparent)]
    Design(Box<tofprobe_design::DesignError>),
    /// A benchmark option out of range: its name (as on the command line), the value and
    /// what is allowed.
    #[error("--{option} = {value}: expected {allowed}")]
    Option {
        option: String,
        value: String,
        allowed: String,
    },
    /// An ISA name that is not one, or one this CPU lacks (`--isa`, `TOFPROBE_ISA`).
    #[error(transparent)]
    Isa(#[from] tofprobe_io::isa::IsaError),
    /// An output file that cannot be written.
    #[error("cannot write {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    /// A computation inside the benchmark failed (it should not: the inputs are the
    /// benchmark's own).
    #[error("bench {bench}: {message}")]
    Internal {
        bench: &'static str,
        message: String,
    },
}

impl BenchError {
    /// An option out of range.
    pub fn option(option: impl ToString, value: impl ToString, allowed: impl ToString) -> Self {
        BenchError::Option {
            option: option.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }

    /// A failed internal computation of benchmark `bench`.
    pub fn internal(bench: &'static str, e: impl std::fmt::Display) -> Self {
        BenchError::Internal {
            bench,
            message: e.to_string(),
        }
    }
}

// Boxed: the design error names the file, key and value inline (clippy::result_large_err).
impl From<tofprobe_design::DesignError> for BenchError {
    fn from(e: tofprobe_design::DesignError) -> Self {
        BenchError::Design(Box::new(e))
    }
}
