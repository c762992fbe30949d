//! From netlist to layout: the generated pixel synthesised with the project's own
//! delay-driven script (`tofprobe_eda::analysis`, the synthesis `tofprobe size` caches),
//! placed at a stated density (graywolf, through qflow; lower densities retried when
//! routing fails), given its power stripes, routed (qrouter) on the die's tracks, its die
//! grown around them (`die`), checked (magic DRC, netgen LVS against the synthesised
//! netlist, every shape inside the die, the laid-out netlist proven equivalent to the RTL),
//! written as GDS and LEF (magic), timed after routing (OpenSTA with the routed wires as
//! SPEF, setup and hold over every path group, the option for a missed corner), drawn
//! (klayout), its area turned into bins per pitch, and judged (`verdict`). See
//! docs/layout.md.

pub mod boundary;
pub mod corners;
pub mod def;
pub mod die;
pub mod error;
pub mod flow;
pub mod gds;
pub mod netlist;
pub mod options;
pub mod picture;
pub mod pitch_bins;
pub mod qflow;
pub mod readers;
pub mod repair;
pub mod report;
pub mod spef;
pub mod sta;
pub mod tech;
pub mod tools;

pub use error::{LayoutError, Result};
pub use flow::{LayoutRequest, LayoutRun, run};
pub use report::{LayoutReport, verdict};
pub use tech::Tech;

/// A step of the layout flow and its wall time (the report lists them; the flow and the
/// repair time theirs).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Step {
    /// The step.
    pub step: String,
    /// Wall time (s).
    pub seconds: f64,
}
