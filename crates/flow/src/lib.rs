//! The hardware flow of a resolved design (`tofprobe_design::ResolvedDesign`): the RTL of
//! the chip rendered with its FuseSoC core ([`rtl`]), the size report's request
//! ([`sizing`]), gate-level sign-off and equivalence on every library found ([`signoff`]),
//! and the main flow ([`flow`]: model → RTL → vectors → co-simulation → report); an
//! `[array]` design's steps are the module folder [`array`](mod@array). The
//! measurements it reports on (spectrum, transients, options) come from
//! `tofprobe-experiments`; the EDA tools are driven by `tofprobe-eda` and `tofprobe-cosim`.

pub mod adders;
pub mod array;
pub mod command;
pub mod error;
pub mod flow;
pub mod flowset;
pub mod rtl;
pub mod signoff;
pub mod sizing;

pub use error::FlowError;
