//! The benchmarks' computations. Each module measures one hot path beside its reference in
//! the same run (so that the ratio holds on a busy machine) and returns a report of plain
//! numbers, serialisable as `--json` with keys that name the figure and its unit. Nothing
//! here prints or exits: `tofprobe bench <target>` parses the options, calls `measure` and
//! prints the report.
//!
//! Parallel parts run on the caller's current rayon pool (`rayon::current_num_threads()`
//! is the thread count reported): a host that must not oversubscribe its cores installs
//! its own pool around the call.

pub mod array;
pub mod array_levels;
/// CPU time: `tofprobe_io::cpu` (the flow's EDA benchmarks read it too).
pub use tofprobe_io::cpu;
pub mod dsp;
mod error;
pub mod fullband;
mod fullband_svg;
pub mod isa;
pub mod lane_rates;
pub mod pixel;
pub mod scene;
pub mod sd;

pub use error::BenchError;
