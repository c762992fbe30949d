//! The array's deliberate faults (the mutation tests' mutants of `templates/array.v` and
//! `templates/superpixel.v`): rendered by [`crate::array`] and [`crate::superpixel`].

use tofprobe_pixel::Fault;

/// A deliberate fault of the array, for the mutation tests only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArrayFault {
    /// The row's broadcast (`pulse`, `rom_word`) passes one extra register: a cycle late.
    RowLate {
        /// The late row.
        row: usize,
    },
    /// The pixel's `tdc` input is wired to the next pixel's (row-major, wrapping) and that
    /// one's to this one's: two TDCs crossed.
    NeighbourTdc {
        /// The pixel's row.
        row: usize,
        /// Its column.
        col: usize,
    },
    /// The readout order swaps its first two pixels.
    OrderSwap,
    /// The row's read select, once set, never clears: it stays on the column buses.
    RowStuck {
        /// The stuck row.
        row: usize,
    },
    /// Double-buffered arrays only: the swap strobe passes one extra register, so every
    /// pixel's shadow copy is taken a cycle late (after the first readout has begun and
    /// together with the next frame's first pulse).
    SwapLate,
    /// Superpixel arrays only (G > 1): a pixel is valid only when every SPAD is (the AND
    /// of the SPADs' `valid`, not the OR).
    SuperpixelAnd,
    /// Superpixel arrays only: SPADs 0 and 1 of every superpixel have their codes crossed
    /// (each averaged with the other's `valid`).
    SpadSwap,
    /// Superpixel arrays only: the reciprocal table's entry for one valid SPAD is one too
    /// small (2^k − 1: a lone SPAD's code comes out one less). With every SPAD valid on
    /// every pulse it never shows.
    ReciprocalEntry,
    /// The pixel's own fault ([`Fault`], rendered into `templates/pixel.v`) in every pixel
    /// of the array: the pixel's mutants under the array's stimulus.
    Pixel(Fault),
}

impl ArrayFault {
    /// The name used in headers and reports.
    pub fn name(self) -> &'static str {
        match self {
            ArrayFault::RowLate { .. } => "row_late",
            ArrayFault::NeighbourTdc { .. } => "neighbour_tdc",
            ArrayFault::OrderSwap => "order_swap",
            ArrayFault::RowStuck { .. } => "row_stuck",
            ArrayFault::SwapLate => "swap_late",
            ArrayFault::SuperpixelAnd => "superpixel_and",
            ArrayFault::SpadSwap => "spad_swap",
            ArrayFault::ReciprocalEntry => "reciprocal_entry",
            ArrayFault::Pixel(f) => f.name(),
        }
    }

    /// The pixel's fault, when this is one ([`ArrayFault::Pixel`]).
    pub fn pixel(self) -> Option<Fault> {
        match self {
            ArrayFault::Pixel(f) => Some(f),
            _ => None,
        }
    }

    /// A fault of the superpixel front end (`templates/superpixel.v`), not of the array.
    pub fn in_superpixel(self) -> bool {
        matches!(
            self,
            ArrayFault::SuperpixelAnd | ArrayFault::SpadSwap | ArrayFault::ReciprocalEntry
        )
    }
}
