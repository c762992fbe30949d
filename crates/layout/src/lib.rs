//! From netlist to layout: the generated pixel synthesised with the project's own
//! delay-driven script (`tofprobe_eda::analysis`, the synthesis `tofprobe size` caches),
//! placed at a stated density (graywolf, through qflow; lower densities retried when
//! routing fails), given its power stripes, routed (qrouter), checked (magic DRC, netgen
//! LVS against the synthesised netlist), written as GDS and LEF (magic), timed after
//! routing (OpenSTA with the routed wires as SPEF, setup and hold), drawn (klayout), and
//! its area turned into bins per pitch. See docs/layout.md.

pub mod bins;
pub mod def;
pub mod error;
pub mod flow;
pub mod picture;
pub mod qflow;
pub mod repair;
pub mod report;
pub mod spef;
pub mod sta;
pub mod tech;
pub mod tools;

pub use error::{LayoutError, Result};
pub use flow::{LayoutRequest, LayoutRun, run};
pub use report::LayoutReport;
pub use tech::Tech;
