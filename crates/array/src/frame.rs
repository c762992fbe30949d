//! The array model's outputs: a tile's registers and detections, and the whole frame's
//! (in a module of their own: every level's model — bit-true `model`, `statistical` —
//! returns them, and neither model imports the other).

use std::ops::Range;

use serde::{Deserialize, Serialize};

/// The registers of a rectangle of pixels after one frame.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tile {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    /// Registers per pixel (2B Fourier, 2^(U+1) − 1 Haar).
    pub registers_per_pixel: usize,
    /// Row-major over the tile, `registers_per_pixel` words per pixel (sign-extended).
    pub registers: Vec<i64>,
    /// Detections of each pixel's frame, row-major over the tile.
    pub detections: Vec<u64>,
}

/// The whole array's registers after one frame.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ArrayFrame {
    pub rows: usize,
    pub cols: usize,
    pub registers_per_pixel: usize,
    /// [R, C, registers] row-major.
    pub registers: Vec<i64>,
    /// [R, C] detections per pixel.
    pub detections: Vec<u64>,
}

impl ArrayFrame {
    /// Pixel (r, c)'s register words.
    pub fn pixel(&self, r: usize, c: usize) -> &[i64] {
        let k = self.registers_per_pixel;
        let i = (r * self.cols + c) * k;
        &self.registers[i..i + k]
    }
}
