//! The plain description of an array chip that its EDA measurements need: the pixel as
//! rendered, the probe ROM's words, the shape, the clock, the netlists to time and the
//! options sized. Built by the flow from a resolved design's chip; no configuration type.

use tofprobe_pixel::{PixelParams, Superpixel};
use tofprobe_rtlgen::ArraySpec;

/// One netlist of the array to time: its name (`whole R × C`, `row 1 × C`, `column R × 1`)
/// and the array it renders (its shape and readout).
#[derive(Debug, Clone, PartialEq)]
pub struct ArraySlice {
    /// What is timed, as reported.
    pub name: String,
    /// The array rendered for it (no fault, no tile).
    pub array: ArraySpec,
}

/// What the array's EDA measurements take.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrayEdaSpec {
    /// The chip's pixel, as rendered (its N, L, W).
    pub pixel: PixelParams,
    /// The chip's probe ROM: L words of ⌈2B/64⌉ u64s each (unused in Haar mode).
    pub rom: Vec<u64>,
    /// Rows of pixels.
    pub rows: usize,
    /// Columns of pixels.
    pub cols: usize,
    /// The pixel clock C·f_laser (MHz).
    pub clock_mhz: f64,
    /// The netlists to time ([`crate::array::timing::slices`] chooses their shapes).
    pub slices: Vec<ArraySlice>,
    /// `[array] double_buffer`.
    pub double_buffer: bool,
    /// `[array] superpixel = G > 1`: the front end, and a SPAD's pitch (µm).
    pub superpixel: Option<(Superpixel, f64)>,
    /// The node the pitch and the ROM macro are stated at (nm).
    pub node_nm: f64,
    /// Placement utilisation of the pitch (0 < u ≤ 1).
    pub utilisation: f64,
}
