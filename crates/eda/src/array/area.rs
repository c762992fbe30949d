//! The pixel's pitch and the array's area: the configured pixel's synthesised area (the
//! size report's, per library), the pitch it implies at a stated placement utilisation and
//! node, and the array's total (pixels, ROM macro, the array's own logic).

use serde::{Deserialize, Serialize};

/// Placement utilisation assumed when a cell area becomes a pitch (standard-cell rows at
/// 70 % is the usual starting density of the open flows).
pub const DEFAULT_UTILISATION: f64 = 0.7;

/// Node (nm) of a library known by name (sky130: 130, osu018: 180).
pub fn library_node_nm(library: &str) -> Option<f64> {
    let l = library.to_ascii_lowercase();
    if l.contains("sky130") {
        Some(130.0)
    } else if l.contains("osu018") {
        Some(180.0)
    } else {
        None
    }
}

/// The pixel's area on one library and the pitch it implies.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PixelPitch {
    /// Library name.
    pub library: String,
    /// Its node (nm): 130 for sky130, 180 for osu018.
    pub library_node_nm: f64,
    /// The pixel's cell area there (µm²).
    pub cell_area_um2: f64,
    /// Utilisation assumed.
    pub utilisation: f64,
    /// Node the pitch is stated at (nm).
    pub node_nm: f64,
    /// √(area / utilisation · (node / library node)²) (µm).
    pub pitch_um: f64,
}

impl PixelPitch {
    /// The pitch of `cell_area_um2` (at `library_node_nm`) at `utilisation`, scaled to `node_nm`.
    pub fn of(
        library: &str,
        library_node_nm: f64,
        cell_area_um2: f64,
        utilisation: f64,
        node_nm: f64,
    ) -> Self {
        let scaled = cell_area_um2 * (node_nm / library_node_nm).powi(2);
        PixelPitch {
            library: library.into(),
            library_node_nm,
            cell_area_um2,
            utilisation,
            node_nm,
            pitch_um: (scaled / utilisation).sqrt(),
        }
    }
}

/// One library's array total.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ArrayTotal {
    /// Library name.
    pub library: String,
    /// P × the pixel's cell area (µm²).
    pub pixels_um2: f64,
    /// The ROM as a macro (the estimate on this library's technology, µm²).
    pub rom_macro_um2: f64,
    /// The chip's shared logic besides the ROM (sequencer, broadcast, readout; µm²), when
    /// synthesised.
    pub shared_logic_um2: Option<f64>,
    /// Sum of the above (µm²).
    pub total_um2: f64,
    /// The pixels' share of the total.
    pub pixel_share: f64,
}

impl ArrayTotal {
    /// The total of `pixels` pixels of `pixel_um2`, a ROM macro and the shared logic.
    pub fn of(
        library: &str,
        pixels: u64,
        pixel_um2: f64,
        rom_macro_um2: f64,
        shared_logic_um2: Option<f64>,
    ) -> Self {
        let px = pixels as f64 * pixel_um2;
        let total = px + rom_macro_um2 + shared_logic_um2.unwrap_or(0.0);
        ArrayTotal {
            library: library.into(),
            pixels_um2: px,
            rom_macro_um2,
            shared_logic_um2,
            total_um2: total,
            pixel_share: px / total,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pitch_scales_with_the_node_and_the_total_adds_up() {
        // 10,000 µm² at 70 % → 119.5 µm at 130 nm; at 40 nm × 40/130: 36.8 µm.
        let p = PixelPitch::of("sky130", 130.0, 10_000.0, 0.7, 130.0);
        assert!((p.pitch_um - (10_000.0f64 / 0.7).sqrt()).abs() < 1e-9);
        let q = PixelPitch::of("sky130", 130.0, 10_000.0, 0.7, 40.0);
        assert!((q.pitch_um / p.pitch_um - 40.0 / 130.0).abs() < 1e-12);
        let t = ArrayTotal::of("x", 4, 100.0, 50.0, Some(50.0));
        assert_eq!(t.total_um2, 500.0);
        assert_eq!(t.pixel_share, 0.8);
        assert_eq!(library_node_nm("sky130_fd_sc_hd__tt"), Some(130.0));
        assert_eq!(library_node_nm("osu018_stdcells"), Some(180.0));
        assert_eq!(library_node_nm("other"), None);
    }
}
