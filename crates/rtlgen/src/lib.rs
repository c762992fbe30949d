//! Verilog generation for the tofprobe pixel and the golden vectors that check it.
//!
//! `render` turns a validated [`PixelParams`] into the pixel, probe ROM and top modules
//! (askama templates in `templates/`); `vectors` runs the contract's reference sequencer
//! through a cycle-accurate reference model and writes what a simulator must reproduce.

pub mod error;
pub mod golden;
pub mod model;
pub mod params;
pub mod render;
pub mod sequencer;
pub mod stimulus;
pub mod vectors;
pub mod write;

pub use error::RtlError;
pub use model::{CycleModel, Fault, PinsIn, PinsOut};
pub use params::{Mode, PixelParams};
pub use render::{RenderOptions, RtlFile, render};
pub use sequencer::Sequencer;
