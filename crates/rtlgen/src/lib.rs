//! Verilog generation for the tofprobe pixel and the golden vectors that check it.
//!
//! `render` turns a validated `tofprobe_pixel::PixelParams` into the pixel, probe ROM and
//! top modules (askama templates in `templates/`), with the pixel crate's adder schedule
//! as case tables; `vectors` runs the pixel crate's reference sequencer through its
//! cycle-accurate model and writes what a simulator must reproduce; `core` renders the
//! FuseSoC core that packages the RTL for users' tools.

pub mod array;
pub mod array_fault;
pub mod array_vectors;
pub mod core;
pub mod error;
pub mod golden;
pub mod kit;
pub mod naming;
pub mod render;
pub mod stimulus;
pub mod superpixel;
pub mod vectors;
pub mod write;

pub use array::{ArrayFault, ArraySpec, render_array};
pub use error::RtlError;
pub use naming::{DEFAULT_MODULE_PREFIX, config_hash, module_names};
pub use render::{RenderOptions, RtlFile, render};
