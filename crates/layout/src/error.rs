//! `LayoutError`: every way the layout flow fails. Messages name the tool and its Debian
//! package, the option with its allowed range and a value that works, or the cell a
//! liberty/LEF pair disagrees on.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the layout crate.
#[derive(Debug, Error)]
pub enum LayoutError {
    /// Synthesis or pre-route timing (the project's yosys/OpenSTA drivers) failed.
    #[error("{0}")]
    Eda(#[from] tofprobe_eda::EdaError),
    /// A program the flow drives is not installed.
    #[error("{found}; install Debian's `{package}` (scripts/install-tools.sh does)")]
    ToolMissing {
        /// What the one locator (`tofprobe_io::tools::locate`) looked for and where.
        found: tofprobe_io::tools::ToolNotFound,
        /// The Debian package that provides it.
        package: &'static str,
    },
    /// A tool ran and failed; the tail of its log says why.
    #[error("{step}: `{tool}` failed ({status}); log {log}:\n{tail}")]
    ToolFailed {
        /// The flow step.
        step: &'static str,
        /// The program.
        tool: &'static str,
        /// Exit status or what went wrong.
        status: String,
        /// Its log file.
        log: PathBuf,
        /// The log's last lines.
        tail: String,
    },
    /// Routing failed at every density tried.
    #[error(
        "routing failed at every density tried ({tried}); unrouted nets at the last ({last}): {nets}. \
         A lower --density (e.g. {suggest}) leaves the router more room"
    )]
    Unrouted {
        /// The densities tried, in order.
        tried: String,
        /// The last density.
        last: f64,
        /// The unrouted nets (first few) and their count.
        nets: String,
        /// A density that may route.
        suggest: f64,
    },
    /// An option out of range.
    #[error("--{option} = {value}: allowed {allowed}")]
    Option {
        /// The option.
        option: &'static str,
        /// The value given.
        value: String,
        /// The allowed range and a value that works.
        allowed: String,
    },
    /// The liberty and the cell LEF disagree on a cell the netlist uses.
    #[error(
        "the netlist uses cell `{cell}`, which the liberty {liberty} defines but the LEF {lef} does not: place and route needs both views of every cell"
    )]
    CellMismatch {
        /// The cell.
        cell: String,
        /// The liberty.
        liberty: PathBuf,
        /// The LEF.
        lef: PathBuf,
    },
    /// A technology file is missing.
    #[error("{tech}: {what} not found at {path} ({hint})")]
    TechFile {
        /// The technology.
        tech: &'static str,
        /// Which file.
        what: &'static str,
        /// Where it was looked for.
        path: PathBuf,
        /// Where it comes from.
        hint: &'static str,
    },
    /// A tool's output did not have the expected shape.
    #[error("{tool}: cannot find {what} in {path}")]
    Parse {
        /// The tool.
        tool: &'static str,
        /// What was looked for.
        what: String,
        /// The file read.
        path: PathBuf,
    },
    /// A file could not be read or written.
    #[error("{action} {path}: {source}")]
    Io {
        /// Reading, writing, creating …
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl LayoutError {
    /// An I/O error on `path`.
    pub fn io(action: &'static str, path: &std::path::Path, source: std::io::Error) -> Self {
        LayoutError::Io {
            action,
            path: path.to_path_buf(),
            source,
        }
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, LayoutError>;
