//! Sizing reports for the tofprobe pixel: register widths and readout volume, synthesised
//! area on a standard-cell liberty (yosys), timing (OpenSTA), the sky130 area-only
//! mapping scaled to other nodes, sweeps over B and W, and their Markdown/JSON/SVG output.

pub mod analysis;
pub mod error;
pub mod fsutil;
pub mod generated;
pub mod liberty;
pub mod markdown;
pub mod memory;
pub mod plot;
pub mod report;
pub mod scaling;
pub mod scalogram;
pub mod sky130;
pub mod split;
pub mod sta;
pub mod synth;
pub mod throughput;
pub mod tools;

pub use error::{ReportError, Result};
