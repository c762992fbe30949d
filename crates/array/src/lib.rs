//! The sensor: an R × C array of the one pixel. [`model`] runs the pixel's datapath (the
//! transaction driver of `tofprobe-pixel`, nothing of its own) on every pixel's own photon
//! stream, in parallel on the caller's rayon pool, with memory linear in R·C·2B and
//! independent of N; a tile of the array is a unit of work whose registers do not depend on
//! the tiling, the threads or the process ([`model::run_tile`], [`model::merge`]).
//! [`maps`] turns the registers into vibration maps (amplitude and phase per bin through
//! `pixel::spectrum::phasors`, the dominant bin, the deflection shape, the modal assurance
//! criterion), [`plot`] draws them, [`uff`] writes them for modal-analysis tools and
//! [`output`] writes the whole set; [`shard`] splits a run into tile sets across processes
//! or machines and merges them back into the same set.

mod error;
pub mod events;
mod frame;
pub mod maps;
pub mod model;
pub mod output;
pub mod plot;
pub mod rtl_driver;
pub mod rtl_model;
pub mod set_plan;
pub mod shadow;
pub mod shard;
pub mod statistical;
mod tile_set;
pub mod uff;

pub use error::ArrayError;
pub use model::{ArrayFrame, Tile, run_array, run_tile, run_tile_watched};

/// The configuration's name in the set: its file name (`plate.toml`), or the embedded
/// default's name; never the path as typed, so the set's bytes do not depend on where the
/// configuration lies or how its path was spelled.
pub fn configuration_name(design: &tofprobe_design::ResolvedDesign) -> String {
    std::path::Path::new(&design.origin)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| design.origin.clone())
}
