//! Bit-true model of the one-bit frequency-probing dToF pixel, at two fidelities that agree
//! exactly: the [`TransactionModel`] (one call per laser pulse) and the [`CycleModel`] (one
//! call per clock edge on the RTL's pins), both implementing the [`contract`] verbatim.
//!
//! - [`params`]: the validated parameters ([`PixelParams`]) and their derived sizes;
//! - [`config`]: the `[pixel]` TOML section ([`PixelConfig`]) and its validation;
//! - [`datapath`]: the one datapath (zoom, hold, prefilter, accumulate) both models drive;
//! - [`detections`]: the drivers' one input, a pulse stream ([`Detections`]: compact codes
//!   with [`NO_DETECTION`], `Option`s, or any other shape), and [`valid_codes`]: a frame
//!   held as (`valid`, `tdc`) arrays read in place ([`ValidCodes`]);
//! - [`fold`]: the folded driver of a Fourier frame (phase sums of the periodic ROM), and
//!   [`driver`]: [`FrameDriver`], which runs it when it pays and the transaction driver
//!   otherwise; [`lanes`]: [`FoldLanes`], up to [`LANES`] folded pixels of an array in
//!   lockstep; [`segments`]: [`SegmentedModel`], one pixel's long run cut into [`LANES`]
//!   time segments in those lanes and repaired exactly (the frame driver's choice when it
//!   pays);
//! - [`schedule`]: the adder schedule, which register each adder touches in which slot;
//! - [`fault`]: deliberate faults the cycle model carries for the mutation tests;
//! - [`fixed`]: the fixed-width arithmetic of the datapath;
//! - [`sequencer`]: the reference pin sequence the testbench and vectors drive;
//! - [`directed`]: the directed schedule beside it (refusals, saturation, wrap-around);
//! - [`sizing`]: register widths, readout bytes and compression from a scene;
//! - [`random`]: the one generator of random valid parameters (the tests', `cosim --random`'s);
//! - [`spectrum`]: the bit-true spectrum of a scene for `tofprobe simulate`;
//! - [`superpixel`]: the averaging of G × G SPADs in front of the datapath ([`Superpixel`]);
//! - [`speed`]: the fidelities' speed (pulses and clock edges per second, `tofprobe bench
//!   pixel`) and the thread CPU clock benchmarks are judged on.

pub mod autobins;
pub mod chip;
pub mod config;
pub mod cycle;
pub mod datapath;
pub mod detections;
pub mod directed;
pub mod driver;
pub mod error;
pub mod fault;
pub mod fixed;
pub mod fold;
pub mod lanes;
pub mod params;
pub mod random;
pub mod readout;
pub mod schedule;
pub mod segments;
pub mod sequencer;
pub mod sizing;
pub mod spectrum;
pub mod speed;
pub mod superpixel;
pub mod transaction;
pub mod valid_codes;

/// The cycle-level contract between the models and the RTL (docs/pixel-contract.md).
///
#[doc = include_str!("../../../docs/pixel-contract.md")]
// The contract writes x[n] and Y[r] as in the paper; they are not links.
#[allow(rustdoc::broken_intra_doc_links)]
pub mod contract {}

pub use chip::{ChipSequencer, Strobes, Walk};
pub use config::{PixelConfig, PixelContext};
pub use cycle::{CycleModel, PinsIn, PinsOut, RegWrite};
pub use datapath::Datapath;
pub use detections::{Detections, NO_DETECTION, Window};
pub use directed::{DirectedOptions, Program, directed_program};
pub use driver::FrameDriver;
pub use error::PixelError;
pub use fault::Fault;
pub use fold::{FoldModel, fold_pays};
pub use lanes::{FoldLanes, LANES};
pub use params::{Mode, PixelParams, RegisterFile, Rounding};
pub use readout::{Readout, ReadoutCollector};
pub use schedule::{Operation, Schedule};
pub use segments::{SegmentedModel, segments_pay};
pub use sequencer::Sequencer;
pub use superpixel::Superpixel;
pub use transaction::TransactionModel;
pub use valid_codes::{TdcCode, ValidCodes};

/// Default prefilter fraction bits F (see `tests/numerics.rs` for the measurement that
/// chose it).
pub const DEFAULT_FRAC_BITS: u32 = 8;
