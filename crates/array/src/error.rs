//! `ArrayError`: the design does not resolve into an array, a tile lies outside it, the
//! pixel refuses its stream, or an output cannot be written.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the array crate.
#[derive(Debug, Error)]
pub enum ArrayError {
    /// The design (or a pixel's source) cannot be built.
    #[error(transparent)]
    Design(Box<tofprobe_design::DesignError>),
    /// The pixel datapath refused (a ROM that does not fit, …).
    #[error("array pixel ({row}, {col}): {source}")]
    Pixel {
        row: usize,
        col: usize,
        source: tofprobe_pixel::PixelError,
    },
    /// A tile, merge or map request that does not fit the array.
    #[error("{0}")]
    Shape(String),
    /// A tile set that cannot be merged (not one, or not of the same run as the others).
    #[error("tile set {}: {message}", path.display())]
    TileSet { path: PathBuf, message: String },
    /// The host stopped the run (`tofprobe_io::watch::Watch::stop`: Ctrl-C in Python).
    #[error("stopped before the end (interrupted)")]
    Stopped,
    /// A command-line option of an array command out of range (`--shard`, `--max-out-gib`).
    #[error("--{option} = {value} is out of range: allowed {allowed}")]
    Option {
        option: String,
        value: String,
        allowed: String,
    },
    /// An output file that cannot be written.
    #[error("cannot write {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
}

impl From<tofprobe_design::DesignError> for ArrayError {
    fn from(e: tofprobe_design::DesignError) -> Self {
        ArrayError::Design(Box::new(e))
    }
}
