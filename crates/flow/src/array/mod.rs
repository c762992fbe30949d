//! The hardware flow of an `[array]` design, one file a step: its RTL ([`render`]:
//! `tofprobe_rtlgen::render_array`, R × C of the one pixel, the broadcast ROM and
//! sequencer, the readout of `tofprobe_design::readout`, with its FuseSoC core and its
//! verification kit); its golden vectors ([`vectors`]: the array model
//! `tofprobe_array::rtl_model` run (by `tofprobe_array::rtl_driver`) on the array scene, the files written by
//! `tofprobe_rtlgen::array_vectors`); its co-simulation at the array's ports ([`cosim`]:
//! the model against Verilator or Icarus, the first mismatch named by pixel (r, c),
//! register, cycle and pulse) and the layouts' cold-build benchmark ([`cosim_bench`]); the
//! flow's report ([`run`]: the verdict, the per-pixel digests' count, the readout's figures
//! at the configured frame and the comparison with reading every timestamp out); and the
//! array section of `tofprobe size` ([`report`], [`markdown`], [`size`]: the spec handed to
//! `tofprobe_eda::array`, which measures, and the readout's arithmetic).

pub mod cosim;
pub mod cosim_bench;
pub mod markdown;
pub mod render;
pub mod report;
pub mod run;
pub mod size;
pub mod vectors;

pub use cosim::{ARRAY_PORTS, ArrayCosimOptions, ArrayCosimReport, ArraySimulator, cosim_array};
pub use render::{ArrayKit, render_array_design, render_array_to};
pub use run::{array_short_frame, readout_section, run_array_flow};
pub use vectors::{ArrayVectors, write_array_vectors};

use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose};

use crate::error::FlowError;

/// The array chip of `design` for the overrides `o` (refused for a design without
/// `[array]`); a superpixel array (G > 1) renders and co-simulates its SPAD inputs, each
/// pixel behind one averaging front end.
pub(crate) fn chip(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    purpose: RomPurpose,
) -> Result<Chip, FlowError> {
    Ok(Chip::array_of(design, o, purpose)?)
}
