//! The report crate's single error type. Every message names what was wrong, the value,
//! and what to install, pass or change instead.

use std::path::PathBuf;

/// Everything that can go wrong while building a sizing report.
#[derive(Debug, thiserror::Error)]
pub enum EdaError {
    /// An external tool (yosys, sta) was not found by the one locator
    /// (`tofprobe_io::tools::locate`: its `TOFPROBE_*` variable, else PATH).
    #[error("{found}; install it ({install})")]
    ToolMissing {
        found: tofprobe_io::tools::ToolNotFound,
        install: &'static str,
    },
    /// The script that builds the area-only sky130 liberty is not where the checkout has it.
    #[error(
        "the sky130 liberty script {} is missing: run from a tofprobe checkout, or set TOFPROBE_SKY130_LIB to an area-only sky130 liberty",
        .script.display()
    )]
    Sky130ScriptMissing { script: PathBuf },
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
    /// `register_file = "clock_gated"` on a liberty with no cells for a clock gate.
    #[error(
        "liberty {path} has no {missing}: `pixel.register_file = \"clock_gated\"` gates each register's clock with the liberty's integrated clock-gating cell or a latch and an AND gate; pass a liberty that has them (sky130_fd_sc_hd has `dlclkp`, osu018 a LATCH and AND2X1) or set `register_file = \"flops\"`"
    )]
    ClockGateCells {
        path: PathBuf,
        missing: &'static str,
    },
    /// `register_file = "latch"` on a liberty with no D latch for the registers.
    #[error(
        "liberty {path} has no {missing}: `pixel.register_file = \"latch\"` builds each register bit from the liberty's D latch; pass a liberty that has one (sky130_fd_sc_hd has `dlxtp`, osu018 a LATCH) or set `register_file = \"flops\"`"
    )]
    LatchCells {
        path: PathBuf,
        missing: &'static str,
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
        "timing fails on {} {}: the {:.1} MHz clock ({:.3} ns) is missed by {:.3} ns (critical path {:.3} ns, f_max {:.1} MHz) on the path {} -> {}; pipeline that path, lower C·f_laser or use a faster corner",
        .0.library, .0.corner, .0.clock_mhz, .0.period_ns, .0.violation_ns, .0.critical_path_ns, .0.f_max_mhz, .0.startpoint, .0.endpoint
    )]
    TimingFailed(Box<TimingFailure>),
    /// The netlist is not equivalent to its RTL.
    #[error(
        "the netlist {} is NOT equivalent to the RTL of `{}` ({} of {} equivalence points unproven, e.g. {}); log tail:\n{}",
        .0.netlist.display(), .0.top, .0.unproven, .0.total, .0.first, .0.log_tail
    )]
    NotEquivalent(Box<EquivFailure>),
    /// The gate-level simulation could not run (tools, files, netlist shape).
    #[error("gate-level simulation: {0}")]
    Cosim(#[from] tofprobe_cosim::CosimError),
    /// The gate-level simulation ran and differs from the golden vectors.
    #[error(
        "gate-level simulation of {} ({}) differs from the golden vectors: {} mismatch(es), the first at cycle {} (pulse {}): {} expected {}, got {}",
        .0.netlist.display(), .0.cells, .0.mismatches, .0.cycle, .0.pulse, .0.signal, .0.expected, .0.actual
    )]
    GateLevelMismatch(Box<GateLevelFailure>),
    /// The generator refused what an array measurement renders (the array's top, its ROM
    /// or the superpixel's front end).
    #[error("{0}")]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
    /// Drawing the SVG plot failed.
    #[error("drawing the plot {path}: {reason}")]
    Plot { path: PathBuf, reason: String },
}

/// A corner that misses its clock ([`EdaError::TimingFailed`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TimingFailure {
    pub library: String,
    pub corner: String,
    pub clock_mhz: f64,
    pub period_ns: f64,
    pub violation_ns: f64,
    pub critical_path_ns: f64,
    pub f_max_mhz: f64,
    pub startpoint: String,
    pub endpoint: String,
}

/// An equivalence that does not hold ([`EdaError::NotEquivalent`]).
#[derive(Debug, Clone, PartialEq)]
pub struct EquivFailure {
    pub netlist: PathBuf,
    pub top: String,
    pub unproven: u64,
    pub total: u64,
    /// The first unproven pair, e.g. `\y[3]_gold [5] \y[3]_gate [5]`.
    pub first: String,
    pub log_tail: String,
}

/// A gate-level replay that differs ([`EdaError::GateLevelMismatch`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GateLevelFailure {
    pub netlist: PathBuf,
    pub cells: String,
    pub mismatches: u64,
    pub cycle: u64,
    pub pulse: u64,
    pub signal: String,
    pub expected: String,
    pub actual: String,
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, EdaError>;

impl EdaError {
    /// An I/O error on `path` while doing `action` ("reading", "writing", ...).
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            action,
            path: path.into(),
            source,
        }
    }
}
