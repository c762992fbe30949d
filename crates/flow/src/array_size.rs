//! The array's sizing (`tofprobe size` on an `[array]` configuration, issue 27 point 4):
//! what an R × C sensor of the configured pixel costs and what its readout allows.
//!
//! - **Pixel**: the configured pixel's synthesised area (the size report's, per library),
//!   the pitch it implies at a stated placement utilisation and node, beside `[array]
//!   pitch_um`.
//! - **Shared**: the probe ROM as a memory — its bits, an area *estimate* for a ROM macro
//!   per technology ([`rom_macro_estimates`]), beside its size as synthesised logic (a
//!   depth-D prefix of the real ROM synthesised and scaled by L/D, [`rom_logic`]).
//! - **Readout**: bits per frame, the readout's duration and the frame rate, from the one
//!   readout contract ([`tofprobe_design::readout::Readout`]), and the comparison with
//!   reading every timestamp out (the paper's 17.5 MB per pixel per second, and its
//!   > 100 Gbit/s).
//!
//! Everything here is arithmetic on resolved figures except [`rom_logic`], which runs
//! yosys through the project's synthesis (cached).

use serde::{Deserialize, Serialize};
use tofprobe_design::readout::Readout;

/// Placement utilisation assumed when a cell area becomes a pitch (standard-cell rows at
/// 70 % is the usual starting density of the open flows).
pub const DEFAULT_UTILISATION: f64 = 0.7;

/// The paper's bandwidth argument: reading every timestamp of an array out needs more than
/// this (bits/s).
pub const PAPER_TIMESTAMP_LINE_BITS_PER_S: f64 = 100e9;

/// A ROM macro's area per bit on sky130 (µm²), an *estimate*: the densest open memory macro
/// for sky130 at hand is OpenRAM's 1024 × 32 single-port SRAM, 534,277 µm² for 32,768 bits
/// (16.3 µm² a bit, periphery included; vsdip/vsdsram_sky130). A mask ROM's one-transistor
/// cell is denser than a 6T SRAM cell, so this bounds a ROM macro from above.
pub const SKY130_MACRO_UM2_PER_BIT: f64 = 534_277.0 / 32_768.0;

/// One technology's ROM-macro estimate.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RomMacroEstimate {
    /// Technology (`sky130`, `osu018`, or the target node).
    pub technology: String,
    /// Its feature size (nm).
    pub node_nm: f64,
    /// Area per bit (µm²).
    pub um2_per_bit: f64,
    /// Area of the whole ROM (µm²).
    pub area_um2: f64,
    /// Where the figure comes from.
    pub basis: String,
}

/// The ROM-macro estimates for `bits` bits on sky130, osu018 (180 nm) and `node_nm`, scaled
/// from sky130 by (node / 130)² (the size report's first-order scaling).
pub fn rom_macro_estimates(bits: u64, node_nm: f64) -> Vec<RomMacroEstimate> {
    let est = |technology: &str, node: f64, basis: String| {
        let per = SKY130_MACRO_UM2_PER_BIT * tofprobe_eda::scaling::node_factor(node);
        RomMacroEstimate {
            technology: technology.into(),
            node_nm: node,
            um2_per_bit: per,
            area_um2: per * bits as f64,
            basis,
        }
    };
    let sky = "estimate: OpenRAM sky130 1024×32 SRAM macro density (534,277 µm² / 32,768 bits, \
               periphery included), an upper bound for a mask ROM"
        .to_string();
    let mut v = vec![
        est("sky130", 130.0, sky.clone()),
        est("osu018", 180.0, format!("{sky}, scaled by (180/130)²")),
    ];
    if (node_nm - 130.0).abs() > 1e-9 && (node_nm - 180.0).abs() > 1e-9 {
        v.push(est(
            &format!("{node_nm} nm"),
            node_nm,
            format!("{sky}, scaled by ({node_nm}/130)²"),
        ));
    }
    v
}

/// The probe ROM synthesised as logic on one library: a depth-D prefix of the ROM, scaled
/// to the whole by L/D (ΣΔ bits are close to random, so logic grows with the bits).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RomLogic {
    /// Library name.
    pub library: String,
    /// D: entries synthesised.
    pub synthesised_depth: usize,
    /// Area of those D entries (µm²).
    pub synthesised_area_um2: f64,
    /// Cells of those D entries.
    pub synthesised_cells: u64,
    /// The whole ROM's area as logic, scaled by L/D (µm²).
    pub area_um2: f64,
}

/// The array's readout figures (from [`Readout`]).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ReadoutFigures {
    /// b: bits per beat of the output port.
    pub bits_per_beat: u32,
    /// k: beats per W-bit word.
    pub beats_per_word: usize,
    /// g: pixel-clock cycles per beat.
    pub cycles_per_beat: u64,
    /// The pixel clock f_clk = C·f_laser (Hz).
    pub clock_hz: f64,
    /// The port's rate while it streams (bits/s).
    pub port_bits_per_s: f64,
    /// Payload bits of a frame: P·(R+1)·W.
    pub payload_bits_per_frame: u64,
    /// Stream bits of a frame, extension bits included: P·(R+1)·k·b.
    pub stream_bits_per_frame: u64,
    /// D: the readout phase (cycles).
    pub readout_cycles: u64,
    /// The readout phase (s).
    pub readout_seconds: f64,
    /// N·C: one frame's accumulation (cycles).
    pub accumulate_cycles: u64,
    /// A frame's period (cycles): N·C + D, or max(N·C + 1, D) double-buffered.
    pub frame_cycles: u64,
    /// The frame rate the readout allows (Hz).
    pub frame_rate_hz: f64,
    /// Share of the laser's pulses the pixels see.
    pub duty: f64,
    /// Double-buffered registers.
    pub double_buffer: bool,
    /// The stream's mean rate over a frame period (bits/s).
    pub mean_bits_per_s: f64,
}

impl ReadoutFigures {
    /// The figures of a resolved readout.
    pub fn of(r: &Readout) -> Self {
        let frame_s = r.frame_cycles() as f64 / r.clock_hz;
        ReadoutFigures {
            bits_per_beat: r.bits,
            beats_per_word: r.beats_per_word,
            cycles_per_beat: r.beat_cycles,
            clock_hz: r.clock_hz,
            port_bits_per_s: r.port_bits_per_s(),
            payload_bits_per_frame: r.payload_bits_per_frame(),
            stream_bits_per_frame: r.stream_bits_per_frame(),
            readout_cycles: r.readout_cycles(),
            readout_seconds: r.readout_seconds(),
            accumulate_cycles: r.accumulate_cycles(),
            frame_cycles: r.frame_cycles(),
            frame_rate_hz: r.frame_rate_hz(),
            duty: r.duty(),
            double_buffer: r.double_buffer,
            mean_bits_per_s: r.stream_bits_per_frame() as f64 / frame_s,
        }
    }
}

/// Reading every timestamp out instead (the histogram-free readout the paper argues
/// against): one T-bit timestamp per laser pulse per pixel.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TimestampComparison {
    /// T: bits of one timestamp.
    pub timestamp_bits: u32,
    /// f_laser (Hz).
    pub laser_rate_hz: f64,
    /// One pixel's timestamps (bytes/s): f_laser·T/8 (the paper's 17.5 MB/s at 10 MHz and
    /// 14 bits).
    pub bytes_per_pixel_per_s: f64,
    /// The whole array's (bits/s).
    pub array_bits_per_s: f64,
    /// Whether that exceeds the paper's 100 Gbit/s line.
    pub exceeds_paper_line: bool,
    /// The array's readout stream over a frame period (bits/s), [`ReadoutFigures::mean_bits_per_s`].
    pub readout_bits_per_s: f64,
    /// Timestamps ÷ readout: how much less the registers send.
    pub reduction: f64,
}

impl TimestampComparison {
    /// The comparison for `pixels` pixels of `timestamp_bits`-bit timestamps at
    /// `laser_rate_hz`, against the readout `r`.
    pub fn of(pixels: u64, timestamp_bits: u32, laser_rate_hz: f64, r: &ReadoutFigures) -> Self {
        let per_pixel_bits = laser_rate_hz * f64::from(timestamp_bits);
        let array = per_pixel_bits * pixels as f64;
        TimestampComparison {
            timestamp_bits,
            laser_rate_hz,
            bytes_per_pixel_per_s: per_pixel_bits / 8.0,
            array_bits_per_s: array,
            exceeds_paper_line: array > PAPER_TIMESTAMP_LINE_BITS_PER_S,
            readout_bits_per_s: r.mean_bits_per_s,
            reduction: array / r.mean_bits_per_s,
        }
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
    fn the_paper_s_timestamp_figures() {
        // 10 MHz × 14 bits = 140 Mbit/s = 17.5 MB/s per pixel (the paper's figure); a
        // 64 × 64 array: 4096 × 140 Mbit/s = 573.44 Gbit/s > 100 Gbit/s.
        let r = ReadoutFigures {
            bits_per_beat: 39,
            beats_per_word: 1,
            cycles_per_beat: 1,
            clock_hz: 160e6,
            port_bits_per_s: 39.0 * 160e6,
            payload_bits_per_frame: 4096 * 33 * 39,
            stream_bits_per_frame: 4096 * 33 * 39,
            readout_cycles: 4096 * 33 + 1,
            readout_seconds: (4096.0 * 33.0 + 1.0) / 160e6,
            accumulate_cycles: 160_000_000,
            frame_cycles: 160_000_000 + 4096 * 33 + 1,
            frame_rate_hz: 160e6 / (160_000_000.0 + 4096.0 * 33.0 + 1.0),
            duty: 0.99,
            double_buffer: false,
            mean_bits_per_s: 4096.0 * 33.0 * 39.0 * 160e6 / (160_000_000.0 + 135_169.0),
        };
        let t = TimestampComparison::of(4096, 14, 10e6, &r);
        assert_eq!(t.bytes_per_pixel_per_s, 17.5e6);
        assert!((t.array_bits_per_s - 573.44e9).abs() < 1.0);
        assert!(t.exceeds_paper_line);
        // 5.27 Mbit per frame at ≈ 1 frame/s: ≈ 1.1·10^5 × less.
        assert!((t.reduction - 573.44e9 / r.mean_bits_per_s).abs() < 1e-6);
        assert!(t.reduction > 1e5 && t.reduction < 1.2e5, "{}", t.reduction);
        // One pixel stays far below the line.
        assert!(!TimestampComparison::of(1, 14, 10e6, &r).exceeds_paper_line);
    }

    #[test]
    fn rom_macro_and_pitch_scale_with_the_node_squared() {
        let e = rom_macro_estimates(640_000, 40.0);
        assert_eq!(e.len(), 3);
        // 16.305 µm²/bit × 640 kbit = 10.44 mm² on sky130.
        assert!((e[0].um2_per_bit - 16.3048).abs() < 1e-3, "{e:?}");
        assert!((e[0].area_um2 - 640_000.0 * 534_277.0 / 32_768.0).abs() < 1e-6);
        assert!((e[1].area_um2 / e[0].area_um2 - (180.0f64 / 130.0).powi(2)).abs() < 1e-12);
        assert!((e[2].area_um2 / e[0].area_um2 - (40.0f64 / 130.0).powi(2)).abs() < 1e-12);
        assert_eq!(rom_macro_estimates(1, 130.0).len(), 2);
        // 10,000 µm² at 70 % → 119.5 µm at 130 nm; at 40 nm × 40/130: 36.8 µm.
        let p = PixelPitch::of("sky130", 130.0, 10_000.0, 0.7, 130.0);
        assert!((p.pitch_um - (10_000.0f64 / 0.7).sqrt()).abs() < 1e-9);
        let q = PixelPitch::of("sky130", 130.0, 10_000.0, 0.7, 40.0);
        assert!((q.pitch_um / p.pitch_um - 40.0 / 130.0).abs() < 1e-12);
        let t = ArrayTotal::of("x", 4, 100.0, 50.0, Some(50.0));
        assert_eq!(t.total_um2, 500.0);
        assert_eq!(t.pixel_share, 0.8);
    }
}
