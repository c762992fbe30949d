//! The readout's side of `tofprobe size` on an `[array]` configuration (issue 27 point 4):
//! bits per frame, the readout's duration and the frame rate, from the one readout
//! contract ([`tofprobe_design::readout::Readout`]), and the comparison with reading every
//! timestamp out (the paper's 17.5 MB per pixel per second, and its > 100 Gbit/s). Pure
//! arithmetic on resolved figures; the array's EDA measurements (pitch, the probe ROM,
//! area, timing) are `tofprobe_eda::array`'s.

use serde::{Deserialize, Serialize};
use tofprobe_design::readout::Readout;

/// The paper's bandwidth argument: reading every timestamp of an array out needs more than
/// this (bits/s).
pub const PAPER_TIMESTAMP_LINE_BITS_PER_S: f64 = 100e9;

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
}
