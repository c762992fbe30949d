//! The array's readout contract (docs/pixel-contract.md "Array"): how the R × C pixels'
//! registers leave the chip between frames, as pure functions the RTL (`templates/array.v`),
//! the array model (`tofprobe_array::chip`) and the sizing all follow.
//!
//! - **Order**: pixels one at a time, row-major ((0, 0), (0, 1), …, (rows−1, cols−1)); in a
//!   pixel its R register words 0..R−1 then its status word (index R, the refused count),
//!   as the pixel's own readout emits them; each word in `k = ceil(W / b)` beats of the
//!   `b = readout_bits`-bit port, least-significant beat first.
//! - **Width rule**: b ≤ W. A register word is sign-extended, the status word zero-extended,
//!   to k·b bits; when b does not divide W the top beat carries k·b − W extension bits (the
//!   stream is k·b bits per word, the payload W). A b > W is refused (the port carries one
//!   word per beat at most).
//! - **Rate**: one beat every `g` pixel-clock cycles (f_clk = C · f_laser): g = 1 unless
//!   `readout_bits_per_s` asks for less, g = ceil(b · f_clk / rate).
//! - **Timing**: a pixel's slot is S = (R+1)·k·g cycles; the readout phase D = P·S + 1
//!   cycles (P = rows·cols); the sequencer presents no pulse during it (as the pixel's
//!   reference sequencer does during its R+2 readout cycles), so a frame is N·C + D cycles
//!   and the frame rate f_clk / (N·C + D). With `double_buffer` the readout of a frame runs
//!   while the next accumulates: a frame is max(N·C + 1, D) cycles.
//! - **Bad input**: a `frame_rate_hz` the readout does not allow is refused, naming the key,
//!   the frame rate the readout does allow and the minimum bandwidth (or width) that would
//!   meet it.

use serde::{Deserialize, Serialize};
use tofprobe_pixel::PixelParams;

use crate::error::DesignError;

/// Registered fan-out stages between the chip's sequencer and every pixel's `pulse`,
/// `rom_word` and `readout` inputs: one at the root, one per row.
pub const BROADCAST_LATENCY: u64 = 2;

/// Cycles from the sequencer's readout strobe of a pixel (root, cycle s) to the first beat
/// of that pixel on the output port (visible in cycle s + 6): 2 broadcast stages, the
/// pixel's registered word 0 (1), the capture into the readout buffer (1), the registered
/// beat (1), seen the cycle after (1).
pub const FIRST_BEAT_LATENCY: u64 = 6;

/// Widest output port (bits per beat) the generator renders.
pub const MAX_READOUT_BITS: u32 = 63;
/// Longest readout phase, in pixel-clock cycles: 2^40 (three hours at 100 MHz). A slower
/// `readout_bits_per_s` is refused, so every count the RTL and the model keep of it fits
/// 64 bits with room.
pub const MAX_READOUT_CYCLES: u64 = 1 << 40;

/// The `[array]` readout keys as written (all optional).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReadoutKeys {
    /// b: bits per beat of the output port (default W: one word per beat).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readout_bits: Option<u32>,
    /// The output link's rate (bits/s; default b · f_clk, one beat per cycle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readout_bits_per_s: Option<f64>,
    /// A frame rate the sensor must reach (Hz; default: none, the rate the readout allows).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_rate_hz: Option<f64>,
    /// Double-buffered registers: accumulate the next frame while this one is read.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub double_buffer: bool,
}

/// Where a beat of a frame's readout stream comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Beat {
    /// Position of the pixel in the readout order (0..P).
    pub position: usize,
    /// Its row.
    pub row: usize,
    /// Its column.
    pub col: usize,
    /// The word: 0..R−1 a register, R the status word.
    pub word: usize,
    /// The beat of the word, 0 = least significant.
    pub part: usize,
}

/// The resolved readout of one array of one pixel design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readout {
    /// Rows of pixels.
    pub rows: usize,
    /// Columns of pixels.
    pub cols: usize,
    /// R: registers per pixel.
    pub registers: usize,
    /// W: register width.
    pub width: u32,
    /// b: bits per beat.
    pub bits: u32,
    /// k = ceil(W / b): beats per word.
    pub beats_per_word: usize,
    /// g: pixel-clock cycles per beat.
    pub beat_cycles: u64,
    /// N: pulses per frame.
    pub frame_pulses: u64,
    /// C: cycles per laser pulse.
    pub cycles_per_pulse: u64,
    /// f_clk = C · f_laser (Hz).
    pub clock_hz: f64,
    /// Whether the registers are double-buffered.
    pub double_buffer: bool,
}

impl Readout {
    /// The readout of a `rows` × `cols` array of `pixel` with the keys `keys`, the laser at
    /// `laser_rate_hz`. Errors name the `[array]` key, its value, the allowed range and a
    /// value that works.
    pub fn new(
        keys: &ReadoutKeys,
        rows: usize,
        cols: usize,
        pixel: &PixelParams,
        laser_rate_hz: f64,
    ) -> Result<Readout, String> {
        let w = pixel.width;
        let b = keys.readout_bits.unwrap_or(w.min(MAX_READOUT_BITS));
        if b == 0 || b > w {
            return Err(format!(
                "array.readout_bits = {b} is out of range: allowed 1..={w} (W = {w}, the register \
                 width: a beat carries at most one word; {w} sends one word per beat)"
            ));
        }
        let c = pixel.cycles_per_pulse as u64;
        if keys.double_buffer && pixel.cycles_per_pulse <= pixel.slots() {
            return Err(format!(
                "array.double_buffer = true needs pixel.cycles_per_pulse > {k} (the slots per \
                 pulse; it is {c}): the swap edge must follow the last pulse's last register \
                 write; cycles_per_pulse = {} works",
                pixel.slots() + 1,
                k = pixel.slots()
            ));
        }
        let clock_hz = c as f64 * laser_rate_hz;
        let port = f64::from(b) * clock_hz;
        // The longest readout phase allowed bounds the cycles a beat may take: P·(R+1)·k·g
        // + 1 cycles must stay within MAX_READOUT_CYCLES (a 5e-324 bits/s link once
        // wrapped the count past 2^64 into the rendered RTL).
        let beats = ((rows * cols) as u64)
            .saturating_mul((pixel.registers() + 1) as u64)
            .saturating_mul(u64::from(w.div_ceil(b)));
        let g_max = (MAX_READOUT_CYCLES - 1) / beats.max(1);
        let beat_cycles = match keys.readout_bits_per_s {
            None => 1,
            Some(rate)
                if rate.is_finite()
                    && rate > 0.0
                    && rate <= port * (1.0 + 1e-12)
                    && port / rate <= g_max as f64 =>
            {
                ((port / rate) * (1.0 - 1e-12)).ceil().max(1.0) as u64
            }
            Some(rate) if rate.is_finite() && rate > 0.0 && rate <= port * (1.0 + 1e-12) => {
                return Err(format!(
                    "array.readout_bits_per_s = {} is out of range: a frame's readout would take \
                     more than 2^40 cycles ({} beats of {b} bits, each ≥ {} cycles); allowed \
                     {:.6e} <= rate <= {port:.6e} bits/s",
                    tofprobe_io::text::number(rate),
                    beats,
                    tofprobe_io::text::number((port / rate).ceil()),
                    port / g_max.max(1) as f64
                ));
            }
            Some(rate) => {
                let need = (rate / clock_hz).ceil();
                let given = tofprobe_io::text::number(rate);
                return Err(format!(
                    "array.readout_bits_per_s = {given} is out of range: allowed 0 < rate <= \
                     readout_bits × C × f_laser = {b} × {c} × {laser_rate_hz} = {port:.6e} bits/s \
                     (one beat per pixel-clock cycle){}",
                    if need.is_finite() && need <= f64::from(w) && rate > 0.0 {
                        format!("; readout_bits = {need} reaches it")
                    } else {
                        String::new()
                    }
                ));
            }
        };
        let r = Readout {
            rows,
            cols,
            registers: pixel.registers(),
            width: w,
            bits: b,
            beats_per_word: w.div_ceil(b) as usize,
            beat_cycles,
            frame_pulses: pixel.frame_pulses,
            cycles_per_pulse: c,
            clock_hz,
            double_buffer: keys.double_buffer,
        };
        if let Some(fr) = keys.frame_rate_hz {
            r.check_frame_rate(fr)?;
        }
        Ok(r)
    }

    /// P: pixels.
    pub fn pixels(&self) -> usize {
        self.rows * self.cols
    }

    /// Words per pixel: R registers and the status word.
    pub fn words_per_pixel(&self) -> usize {
        self.registers + 1
    }

    /// S = (R+1)·k·g: cycles between two pixels' readout strobes.
    pub fn slot_cycles(&self) -> u64 {
        (self.words_per_pixel() * self.beats_per_word) as u64 * self.beat_cycles
    }

    /// D = P·S + 1: the readout phase in cycles (no pulse is presented during it).
    pub fn readout_cycles(&self) -> u64 {
        Self::phase(self.pixels() as u64, self.slot_cycles())
    }

    fn phase(p: u64, s: u64) -> u64 {
        p.saturating_mul(s).saturating_add(1)
    }

    /// The readout phase in seconds.
    pub fn readout_seconds(&self) -> f64 {
        self.readout_cycles() as f64 / self.clock_hz
    }

    /// Beats of one frame's stream: P·(R+1)·k.
    pub fn beats_per_frame(&self) -> u64 {
        (self.pixels() * self.words_per_pixel() * self.beats_per_word) as u64
    }

    /// Bits of one frame's stream, with the extension bits: P·(R+1)·k·b.
    pub fn stream_bits_per_frame(&self) -> u64 {
        self.beats_per_frame() * u64::from(self.bits)
    }

    /// Payload bits of one frame: P·(R+1)·W.
    pub fn payload_bits_per_frame(&self) -> u64 {
        (self.pixels() * self.words_per_pixel()) as u64 * u64::from(self.width)
    }

    /// The port's rate while it streams: b · f_clk / g bits/s.
    pub fn port_bits_per_s(&self) -> f64 {
        f64::from(self.bits) * self.clock_hz / self.beat_cycles as f64
    }

    /// The accumulation of one frame: N·C cycles.
    pub fn accumulate_cycles(&self) -> u64 {
        self.frame_pulses.saturating_mul(self.cycles_per_pulse)
    }

    /// A frame's period in cycles: N·C + D, or max(N·C + 1, D) double-buffered.
    pub fn frame_cycles(&self) -> u64 {
        Self::period(
            self.accumulate_cycles(),
            self.readout_cycles(),
            self.double_buffer,
        )
    }

    fn period(acc: u64, d: u64, double_buffer: bool) -> u64 {
        if double_buffer {
            acc.saturating_add(1).max(d)
        } else {
            acc.saturating_add(d)
        }
    }

    /// The frame rate the readout allows (Hz): f_clk / frame cycles.
    pub fn frame_rate_hz(&self) -> f64 {
        self.clock_hz / self.frame_cycles() as f64
    }

    /// The share of the laser's pulses the pixels see: N·C / frame cycles.
    pub fn duty(&self) -> f64 {
        self.accumulate_cycles() as f64 / self.frame_cycles() as f64
    }

    /// The pixel at position `q` of the readout order (row-major).
    pub fn order(&self, q: usize) -> (usize, usize) {
        (q / self.cols, q % self.cols)
    }

    /// The readout order: every pixel once.
    pub fn order_iter(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.pixels()).map(|q| self.order(q))
    }

    /// The beat `index` (0..beats_per_frame) of a frame's stream.
    pub fn beat(&self, index: u64) -> Beat {
        let k = self.beats_per_word as u64;
        let per_pixel = self.words_per_pixel() as u64 * k;
        let q = (index / per_pixel) as usize;
        let within = index % per_pixel;
        let (row, col) = self.order(q);
        Beat {
            position: q,
            row,
            col,
            word: (within / k) as usize,
            part: (within % k) as usize,
        }
    }

    /// The cycle, counted from the readout phase's first cycle, in which beat (q, j, m) is
    /// on the port: q·S + (j·k + m)·g + [`FIRST_BEAT_LATENCY`].
    pub fn beat_offset(&self, q: usize, word: usize, part: usize) -> u64 {
        q as u64 * self.slot_cycles()
            + ((word * self.beats_per_word + part) as u64) * self.beat_cycles
            + FIRST_BEAT_LATENCY
    }

    /// The k beats of a raw W-bit word `raw` (word `word` of a pixel: a register is
    /// sign-extended, the status word zero-extended, to k·b bits), least significant first.
    pub fn beats_of(&self, word: usize, raw: u64) -> Vec<u64> {
        let w = self.width;
        let raw = raw & mask(w);
        let signed = word < self.registers && (raw >> (w - 1)) & 1 == 1;
        let b = self.bits;
        (0..self.beats_per_word)
            .map(|m| {
                let lo = m as u32 * b;
                let mut v = if lo < w { raw >> lo } else { 0 };
                if signed {
                    // Bits at or above W (relative to lo) are ones.
                    let keep = w.saturating_sub(lo);
                    if keep < b {
                        v |= mask(b) & !mask(keep);
                    }
                }
                v & mask(b)
            })
            .collect()
    }

    /// The raw W-bit word from its k beats (the inverse of [`Self::beats_of`]).
    pub fn word_of(&self, beats: &[u64]) -> u64 {
        let mut v = 0u64;
        for (m, &x) in beats.iter().enumerate() {
            let lo = m as u32 * self.bits;
            if lo < 64 {
                v |= (x & mask(self.bits)) << lo;
            }
        }
        v & mask(self.width)
    }

    /// Refuses a `frame_rate_hz` the readout does not allow, naming the rate it allows and
    /// the minimum bandwidth (the `readout_bits_per_s`, or the `readout_bits`) that meets it.
    pub fn check_frame_rate(&self, fr: f64) -> Result<(), String> {
        if !(fr.is_finite() && fr > 0.0) {
            return Err(format!(
                "array.frame_rate_hz = {fr} is out of range: allowed > 0 (at most {:.6} Hz \
                 with this readout)",
                self.frame_rate_hz()
            ));
        }
        let budget = (self.clock_hz / fr).floor() as u64;
        if self.frame_cycles() <= budget {
            return Ok(());
        }
        let acc = self.accumulate_cycles();
        let words = (self.pixels() * self.words_per_pixel()) as u64;
        let p = self.pixels() as u64;
        let fits = |k: u64, g: u64| {
            Self::period(acc, Self::phase(p, words / p * k * g), self.double_buffer) <= budget
        };
        let k = self.beats_per_word as u64;
        let what = if fits(k, 1) {
            // The width is enough at one beat per cycle: the link's rate is what limits.
            let g_max = (1..=self.beat_cycles)
                .rev()
                .find(|&g| fits(k, g))
                .unwrap_or(1);
            format!(
                "the minimum bandwidth is array.readout_bits_per_s >= {:.6e} bits/s \
                 (one {}-bit beat every {g_max} cycles)",
                f64::from(self.bits) * self.clock_hz / g_max as f64,
                self.bits
            )
        } else if let Some(k_ok) = (1..k).rev().find(|&k2| fits(k2, 1)) {
            format!(
                "the minimum bandwidth is array.readout_bits >= {} at one beat per cycle \
                 ({:.6e} bits/s)",
                self.width.div_ceil(k_ok as u32),
                f64::from(self.width.div_ceil(k_ok as u32)) * self.clock_hz
            )
        } else {
            format!(
                "even array.readout_bits = {} at one beat per cycle does not fit: fewer \
                 pixels, registers or pulses per frame, or a lower frame rate",
                self.width
            )
        };
        Err(format!(
            "array.frame_rate_hz = {fr} is not reached: a frame is {} cycles of {:.6e} Hz \
             ({} accumulating, {} reading {} × {} pixels × {} words × {} beats{}), so the \
             readout allows at most {:.6} Hz; {what}",
            self.frame_cycles(),
            self.clock_hz,
            acc,
            self.readout_cycles(),
            self.rows,
            self.cols,
            self.words_per_pixel(),
            self.beats_per_word,
            if self.double_buffer {
                ", double-buffered"
            } else {
                ""
            },
            self.frame_rate_hz()
        ))
    }
}

fn mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// Resolves the readout keys of an array for `pixel` (the message names the document).
pub fn resolve_readout(
    keys: &ReadoutKeys,
    rows: usize,
    cols: usize,
    pixel: &PixelParams,
    laser_rate_hz: f64,
    origin: &str,
) -> Result<Readout, DesignError> {
    Readout::new(keys, rows, cols, pixel, laser_rate_hz).map_err(|m| DesignError::array(origin, m))
}
