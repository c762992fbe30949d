//! The array's EDA measurements (`tofprobe size` on an `[array]` configuration): the
//! broadcast and readout paths timed by OpenSTA ([`timing`]), the probe ROM as a memory
//! and as synthesised logic ([`rom`]), the pixel's pitch and the array's area ([`area`]),
//! the double buffer's estimate and the superpixel's front end synthesised ([`options`]),
//! all from one plain description of the chip, [`ArrayEdaSpec`] ([`spec`]), and run
//! together by [`measure::measure`]. The flow builds the spec from a resolved design
//! (`tofprobe_flow::array::report`), calls [`measure::measure`] and writes the report;
//! nothing here knows the configuration.

pub mod area;
pub mod measure;
pub mod options;
pub mod rom;
pub mod spec;
pub mod timing;

pub use measure::{ArrayMeasurements, measure};
pub use spec::{ArrayEdaSpec, ArraySlice};
