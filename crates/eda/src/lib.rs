//! Sizing reports for the tofprobe pixel: register widths and readout volume, synthesised
//! area on a standard-cell liberty (yosys), timing (OpenSTA) on every liberty and corner,
//! sky130 (timed PDK, or the area-only mapping) scaled to other nodes, sweeps over B and
//! W, their Markdown/JSON/SVG output, and sign-off: formal equivalence of netlist and RTL;
//! an array chip's measurements ([`array`](mod@array): its broadcast and readout timing, probe ROM,
//! area and options) from a plain spec the flow builds.

pub mod analysis;
pub mod array;
pub mod cells;
pub mod clock_gate;
pub mod corner_option;
pub mod corners;
pub mod equiv;
pub mod error;
pub mod fsutil;
pub mod generated;
pub mod latch;
pub mod lef;
pub mod liberty;
pub mod markdown;
pub mod memory;
pub mod paper_memory;
pub mod pdk;
pub mod plot;
pub mod scaling;
pub mod signoff;
pub mod size_report;
pub mod sky130;
pub mod split;
pub mod sta;
pub mod synth;
pub mod throughput;
pub mod tools;

pub use error::{EdaError, Result};
