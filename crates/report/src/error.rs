//! The report crate's single error type. Every message names what was wrong, the value,
//! and what to install, pass or change instead.

use std::path::PathBuf;

/// Everything that can go wrong while building a sizing report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// An external tool (yosys, sta, python3) is not on PATH.
    #[error(
        "`{tool}` was not found on PATH (nor via ${env}); install it ({install}) or set {env} to its path"
    )]
    ToolMissing {
        tool: &'static str,
        env: &'static str,
        install: &'static str,
    },
    /// The liberty file does not exist or cannot be read.
    #[error(
        "liberty file {path} cannot be read ({reason}); install Debian's `qflow-tech-osu018` for the default, or pass --liberty FILE"
    )]
    LibertyUnreadable { path: PathBuf, reason: String },
    /// The liberty file lacks a cell class the pixel needs.
    #[error(
        "liberty file {path} has no {what}; the pixel needs {why}: pass a liberty that has one (e.g. /usr/share/qflow/tech/osu018/osu018_stdcells.lib)"
    )]
    LibertyIncomplete {
        path: PathBuf,
        what: &'static str,
        why: &'static str,
    },
    /// The synthesised netlist still contains generic cells the liberty could not map.
    #[error(
        "liberty {path} cannot implement {cells}: yosys left these generic cells unmapped; pass a liberty with those functions"
    )]
    Unmapped { path: PathBuf, cells: String },
    /// An RTL source file is missing.
    #[error(
        "RTL file {path} does not exist; generate it (`tofprobe rtl`) or pass the pixel's Verilog"
    )]
    RtlMissing { path: PathBuf },
    /// A tool ran but failed.
    #[error("{tool} failed (exit status {status}); last lines of its log:\n{log_tail}")]
    ToolFailed {
        tool: &'static str,
        status: String,
        log_tail: String,
    },
    /// A tool's output did not contain the figure we parse from it.
    #[error("could not find {what} in the output of {tool}; output tail:\n{tail}")]
    Parse {
        tool: &'static str,
        what: &'static str,
        tail: String,
    },
    /// A parameter of the report is outside its range.
    #[error("{field} = {value} is out of range: {allowed}")]
    OutOfRange {
        field: &'static str,
        value: String,
        allowed: String,
    },
    /// Reading or writing a file failed.
    #[error("{action} {path}: {source}")]
    Io {
        action: &'static str,
        path: PathBuf,
        source: std::io::Error,
    },
    /// A cached or produced JSON document could not be (de)serialised.
    #[error("JSON for {what}: {source}")]
    Json {
        what: String,
        source: serde_json::Error,
    },
    /// A corner misses the clock the configuration needs: by how much, on which path.
    #[error(
        "timing fails on {library} {corner}: the {clock_mhz:.1} MHz clock ({period_ns:.3} ns) is missed by {violation_ns:.3} ns (critical path {critical_path_ns:.3} ns, f_max {f_max_mhz:.1} MHz) on the path {startpoint} -> {endpoint}; pipeline that path, lower C·f_laser or use a faster corner"
    )]
    TimingFailed {
        library: String,
        corner: String,
        clock_mhz: f64,
        period_ns: f64,
        violation_ns: f64,
        critical_path_ns: f64,
        f_max_mhz: f64,
        startpoint: String,
        endpoint: String,
    },
    /// The netlist is not equivalent to its RTL.
    #[error(
        "the netlist {netlist} is NOT equivalent to the RTL of `{top}` ({unproven} of {total} equivalence points unproven, e.g. {first}); log tail:\n{log_tail}"
    )]
    NotEquivalent {
        netlist: PathBuf,
        top: String,
        unproven: u64,
        total: u64,
        first: String,
        log_tail: String,
    },
    /// The gate-level simulation could not run (tools, files, netlist shape).
    #[error("gate-level simulation: {0}")]
    Cosim(#[from] tofprobe_cosim::CosimError),
    /// The gate-level simulation ran and differs from the golden vectors.
    #[error(
        "gate-level simulation of {netlist} ({cells}) differs from the golden vectors: {mismatches} mismatch(es), the first at cycle {cycle} (pulse {pulse}): {signal} expected {expected}, got {actual}"
    )]
    GateLevelMismatch {
        netlist: PathBuf,
        cells: String,
        mismatches: u64,
        cycle: u64,
        pulse: u64,
        signal: String,
        expected: String,
        actual: String,
    },
    /// Drawing the SVG plot failed.
    #[error("drawing the plot {path}: {reason}")]
    Plot { path: PathBuf, reason: String },
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, ReportError>;

impl ReportError {
    /// An I/O error on `path` while doing `action` ("reading", "writing", ...).
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            action,
            path: path.into(),
            source,
        }
    }
}
