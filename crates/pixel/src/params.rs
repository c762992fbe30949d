//! `PixelParams`: the validated hardware parameters of one pixel (the contract's parameter
//! table), with the quantities derived from them. Both models and the RTL generator take
//! their sizes from here, so a configuration that passes [`PixelParams::validate`] is one
//! the hardware can build.

use serde::{Deserialize, Serialize};

use crate::error::PixelError;

/// What the register file computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// I/Q accumulation of the prefiltered depth with ROM (ΣΔ) signs: a DFT at B bins.
    #[default]
    Fourier,
    /// Haar wavelet coefficients of the held depth, signs from the pulse counter.
    Haar,
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Mode::Fourier => "fourier",
            Mode::Haar => "haar",
        })
    }
}

/// How the prefilter's arithmetic shift rounds (`[pixel] prefilter_rounding`,
/// docs/pixel-contract.md "Prefilter rounding").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Rounding {
    /// `diff >>> S`: rounds towards −∞, so x settles up to 2^S − 1 LSBs below a constant
    /// input (a −0.06-code bias at S = 5, F = 8). The committed default.
    #[default]
    Floor,
    /// `(diff + 2^(S−1)) >>> S`: round half up; the same widths, no bias.
    Nearest,
}

impl Rounding {
    /// The default: left out of the configuration hash, so the hashes of every pixel
    /// from before the knob stand.
    pub fn is_floor(&self) -> bool {
        *self == Rounding::Floor
    }

    /// The constant added before a shift by `shift`: 2^(S−1) for `Nearest` (S ≥ 1), else 0
    /// (floor, and S = 0, which is exact either way). The datapath and the template both
    /// take it from here.
    pub fn half(self, shift: u32) -> i64 {
        match self {
            Rounding::Nearest if shift > 0 => 1i64 << (shift - 1),
            _ => 0,
        }
    }
}

/// What the register file is built of (`[pixel] register_file`, docs/pixel-contract.md
/// "Register file"). Every kind holds the same values at every rising clock edge, so the
/// models and the vectors are the same for all of them; only the RTL and its area differ
/// (and, for latches, when between two edges a write becomes visible).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RegisterFile {
    /// Flops with a write-enable multiplexer per bit. The committed default.
    #[default]
    Flops,
    /// Flops without the multiplexer, each register's clock gated by its write enable
    /// (one clock-gating cell per register: the liberty's integrated clock gate, or a
    /// latch and an AND gate where it has none).
    ClockGated,
    /// Transparent latches, each register's latches enabled by the low phase of `clk`
    /// gated (one clock gate per register) by the write enable of the last edge, their
    /// input the value captured at that edge (one word per adder): a write shows half a
    /// cycle after the edge a flop would load at, and every edge sees the same values.
    Latch,
}

impl RegisterFile {
    /// The default: left out of the configuration hash.
    pub fn is_flops(&self) -> bool {
        *self == RegisterFile::Flops
    }
}

impl std::fmt::Display for RegisterFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RegisterFile::Flops => "flops",
            RegisterFile::ClockGated => "clock_gated",
            RegisterFile::Latch => "latch",
        })
    }
}

impl std::fmt::Display for Rounding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Rounding::Floor => "floor",
            Rounding::Nearest => "nearest",
        })
    }
}

/// Largest register width: the models hold registers in `i64` and the readout bus in `u64`.
pub const MAX_WIDTH: u32 = 63;
/// Largest TDC width the contract allows.
pub const MAX_TDC_BITS: u32 = 16;
/// Largest prefilter shift.
pub const MAX_SHIFT: u32 = 15;
/// Largest number of prefilter fraction bits.
pub const MAX_FRAC_BITS: u32 = 16;
/// Largest number of Fourier bins (R = 1024 registers): the generator renders every
/// configuration this crate accepts, and a register file beyond that is no pixel.
pub const MAX_BINS: usize = 512;
/// Largest finest Haar scale (R = 1023 registers), for the same reason.
pub const MAX_HAAR_SCALES: u32 = 9;
/// Largest number of clock cycles per laser pulse (a 16-bit cycle counter).
pub const MAX_CYCLES_PER_PULSE: usize = 1 << 16;
/// Largest probe ROM depth (a 32-bit ROM address).
pub const MAX_ROM_DEPTH: usize = 1 << 32;

/// The validated pixel parameters (letters as in docs/pixel-contract.md).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelParams {
    /// `fourier` or `haar`.
    pub mode: Mode,
    /// B: Fourier bins (ignored in Haar mode).
    pub bins: usize,
    /// U: finest Haar scale (ignored in Fourier mode).
    pub haar_scales: u32,
    /// A: adders.
    pub adders: usize,
    /// C: clock cycles per laser pulse.
    pub cycles_per_pulse: usize,
    /// T: TDC width in bits (unsigned code).
    pub tdc_bits: u32,
    /// Z: zoom, the timing-window start in TDC codes, subtracted from every code.
    pub zoom: u32,
    /// S: prefilter shift, α = 2^−S (Fourier).
    pub shift: u32,
    /// F: prefilter fraction bits (Fourier; Haar has no prefilter and uses 0).
    pub frac_bits: u32,
    /// W: register width in bits, two's complement, wrapping.
    pub width: u32,
    /// N: pulses per frame (Haar: a power of two).
    pub frame_pulses: u64,
    /// L: ROM depth in entries (Fourier; the ROM is addressed by pulse index mod L).
    pub rom_depth: usize,
    /// How the prefilter's shift rounds (Fourier; floor by default).
    #[serde(default, skip_serializing_if = "Rounding::is_floor")]
    pub prefilter_rounding: Rounding,
    /// G: fraction bits of x kept in the operand added to the registers (Fourier; `None`
    /// = F, the whole filter state). The operand is x >>> (F − G).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub register_frac_bits: Option<u32>,
    /// What the register file is built of (flops by default).
    #[serde(default, skip_serializing_if = "RegisterFile::is_flops")]
    pub register_file: RegisterFile,
}

impl Default for PixelParams {
    /// The committed default design (`rtl/`, scenes/default.toml resolved): the contract's
    /// default Fourier pixel with W = 39, N = 10^7 (1 s at 10 MHz) and the periodic
    /// L = 20,000 ΣΔ ROM.
    fn default() -> Self {
        PixelParams::fourier_default(39, 10_000_000, 20_000)
    }
}

impl PixelParams {
    /// The contract's default Fourier pixel: B = 16, A = 2, C = 16, T = 7, S = 5, F =
    /// [`crate::DEFAULT_FRAC_BITS`], with the given width, frame length and ROM depth.
    pub fn fourier_default(width: u32, frame_pulses: u64, rom_depth: usize) -> Self {
        PixelParams {
            mode: Mode::Fourier,
            bins: 16,
            haar_scales: 4,
            adders: 2,
            cycles_per_pulse: 16,
            tdc_bits: 7,
            zoom: 0,
            shift: 5,
            frac_bits: crate::DEFAULT_FRAC_BITS,
            width,
            frame_pulses,
            rom_depth,
            prefilter_rounding: Rounding::Floor,
            register_frac_bits: None,
            register_file: RegisterFile::Flops,
        }
    }

    /// R: registers, 2·B (Fourier) or 2^(U+1) − 1 (Haar).
    pub fn registers(&self) -> usize {
        match self.mode {
            Mode::Fourier => 2 * self.bins,
            Mode::Haar => (1usize << (self.haar_scales + 1)) - 1,
        }
    }

    /// P: register operations per pulse, R (Fourier) or U + 1 (Haar).
    pub fn ops_per_pulse(&self) -> usize {
        match self.mode {
            Mode::Fourier => self.registers(),
            Mode::Haar => self.haar_scales as usize + 1,
        }
    }

    /// K: schedule slots per pulse, ceil(P / A).
    pub fn slots(&self) -> usize {
        self.ops_per_pulse().div_ceil(self.adders.max(1))
    }

    /// Fraction bits actually used by the data path (0 in Haar mode).
    pub fn effective_frac_bits(&self) -> u32 {
        match self.mode {
            Mode::Fourier => self.frac_bits,
            Mode::Haar => 0,
        }
    }

    /// G: fraction bits of the operand added to the registers, F unless
    /// `register_frac_bits` keeps fewer (0 in Haar mode).
    pub fn register_frac_bits(&self) -> u32 {
        match self.mode {
            Mode::Fourier => self
                .register_frac_bits
                .map_or(self.frac_bits, |g| g.min(self.frac_bits)),
            Mode::Haar => 0,
        }
    }

    /// Width of the prefilter state x: T+1+F (Fourier) or T+1 (Haar, no prefilter).
    pub fn prefilter_bits(&self) -> u32 {
        self.tdc_bits + 1 + self.effective_frac_bits()
    }

    /// Width of the operand added to the registers: T+1+G (Fourier x >>> (F − G)) or T+1
    /// (Haar held).
    pub fn operand_bits(&self) -> u32 {
        self.tdc_bits + 1 + self.register_frac_bits()
    }

    /// Width of the `rd_index` output: ceil(log2(R + 2)) (indices 0..R, R = status word).
    pub fn rd_index_bits(&self) -> u32 {
        ceil_log2(self.registers() as u64 + 2)
    }

    /// log2 N for Haar frames (N a power of two); for other N, floor(log2 N).
    pub fn log2_frame(&self) -> u32 {
        63 - self.frame_pulses.max(1).leading_zeros()
    }

    /// Largest value of the saturating `refused` counter, 2^W − 1.
    pub fn refused_max(&self) -> u64 {
        (1u64 << self.width) - 1
    }

    /// Checks every constraint of the contract's parameter table. The error names the
    /// first violated one with the nearest value that would work.
    pub fn validate(&self) -> Result<(), PixelError> {
        let t = self.tdc_bits;
        if !(1..=MAX_TDC_BITS).contains(&t) {
            return Err(PixelError::invalid(
                "tdc_bits",
                t,
                format!("the TDC width must be 1..={MAX_TDC_BITS} bits"),
                t.clamp(1, MAX_TDC_BITS),
            ));
        }
        if u64::from(self.zoom) >= 1u64 << t {
            return Err(PixelError::invalid(
                "zoom",
                self.zoom,
                format!(
                    "the window start must be a {t}-bit code, 0..={}",
                    (1u64 << t) - 1
                ),
                (1u64 << t) - 1,
            ));
        }
        if self.frame_pulses == 0 {
            return Err(PixelError::invalid(
                "frame_pulses",
                0,
                "a frame needs at least one pulse",
                1,
            ));
        }
        match self.mode {
            Mode::Fourier => {
                if self.bins == 0 || self.bins > MAX_BINS {
                    return Err(PixelError::invalid(
                        "bins",
                        self.bins,
                        format!("Fourier mode needs 1..={MAX_BINS} bins"),
                        self.bins.clamp(1, MAX_BINS),
                    ));
                }
                if self.shift > MAX_SHIFT {
                    return Err(PixelError::invalid(
                        "shift",
                        self.shift,
                        format!("the prefilter shift must be 0..={MAX_SHIFT}"),
                        MAX_SHIFT,
                    ));
                }
                if self.frac_bits > MAX_FRAC_BITS {
                    return Err(PixelError::invalid(
                        "frac_bits",
                        self.frac_bits,
                        format!("the prefilter fraction bits must be 0..={MAX_FRAC_BITS}"),
                        MAX_FRAC_BITS,
                    ));
                }
                if let Some(g) = self.register_frac_bits
                    && g > self.frac_bits
                {
                    return Err(PixelError::invalid(
                        "register_frac_bits",
                        g,
                        format!(
                            "the registers keep at most the prefilter's F = {} fraction bits: 0..={}",
                            self.frac_bits, self.frac_bits
                        ),
                        self.frac_bits,
                    ));
                }
                if self.rom_depth == 0 || self.rom_depth > MAX_ROM_DEPTH {
                    return Err(PixelError::invalid(
                        "rom_depth",
                        self.rom_depth,
                        format!(
                            "Fourier mode reads one ROM entry per pulse: 1..={MAX_ROM_DEPTH} entries (a 32-bit address)"
                        ),
                        self.rom_depth.clamp(1, MAX_ROM_DEPTH),
                    ));
                }
            }
            Mode::Haar => {
                let n = self.frame_pulses;
                if n < 2 || !n.is_power_of_two() {
                    let up = n.max(2).checked_next_power_of_two().unwrap_or(1 << 63);
                    let down = if n < 2 {
                        2
                    } else {
                        1u64 << (63 - n.leading_zeros())
                    };
                    let nearest = if n < 2 || up - n >= n - down {
                        down
                    } else {
                        up
                    };
                    return Err(PixelError::invalid(
                        "frame_pulses",
                        n,
                        "Haar mode derives its signs from the pulse counter, so N must be a power of two ≥ 2",
                        nearest,
                    ));
                }
                let l = self.log2_frame();
                if self.haar_scales > l - 1 {
                    return Err(PixelError::invalid(
                        "haar_scales",
                        self.haar_scales,
                        format!("the finest scale U must be 0..=log2(N) − 1 = {}", l - 1),
                        l - 1,
                    ));
                }
                if self.haar_scales > MAX_HAAR_SCALES {
                    return Err(PixelError::invalid(
                        "haar_scales",
                        self.haar_scales,
                        format!(
                            "at most {} registers (U ≤ {MAX_HAAR_SCALES})",
                            (1u32 << (MAX_HAAR_SCALES + 1)) - 1
                        ),
                        MAX_HAAR_SCALES,
                    ));
                }
            }
        }
        let p = self.ops_per_pulse();
        if self.adders == 0 || self.adders > p {
            return Err(PixelError::invalid(
                "adders",
                self.adders,
                format!("1 ≤ A ≤ P = {p} operations per pulse"),
                self.adders.clamp(1, p),
            ));
        }
        let k = self.slots();
        if self.cycles_per_pulse < k {
            return Err(PixelError::invalid(
                "cycles_per_pulse",
                self.cycles_per_pulse,
                format!(
                    "{p} operations on {} adder(s) need K = {k} schedule slots per pulse, so C ≥ {k}",
                    self.adders
                ),
                k,
            ));
        }
        if self.cycles_per_pulse > MAX_CYCLES_PER_PULSE {
            return Err(PixelError::invalid(
                "cycles_per_pulse",
                self.cycles_per_pulse,
                format!("C ≤ {MAX_CYCLES_PER_PULSE} (a 16-bit cycle counter)"),
                MAX_CYCLES_PER_PULSE,
            ));
        }
        let ob = self.operand_bits();
        if self.width < ob || self.width > MAX_WIDTH {
            return Err(PixelError::invalid(
                "width",
                self.width,
                format!(
                    "W must hold one operand (T+1{} = {ob} bits) and be at most {MAX_WIDTH}",
                    match self.mode {
                        Mode::Fourier if self.register_frac_bits() < self.frac_bits => "+G",
                        Mode::Fourier => "+F",
                        Mode::Haar => "",
                    }
                ),
                self.width.clamp(ob, MAX_WIDTH),
            ));
        }
        Ok(())
    }
}

/// ceil(log2(v)) for v ≥ 1 (0 for v = 1).
pub fn ceil_log2(v: u64) -> u32 {
    if v <= 1 {
        0
    } else {
        64 - (v - 1).leading_zeros()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Derived sizes of the default pixels, from the contract's formulas by hand.
    #[test]
    fn derived_quantities_of_the_default_pixels() {
        let p = PixelParams::fourier_default(39, 10_000_000, 10_000_000);
        p.validate().unwrap();
        // R = 2·16, P = R, K = ceil(32/2), T+1+F = 7+1+8, ceil(log2(34)) = 6.
        assert_eq!((p.registers(), p.ops_per_pulse(), p.slots()), (32, 32, 16));
        assert_eq!((p.operand_bits(), p.rd_index_bits()), (16, 6));
        let mut h = p.clone();
        h.mode = Mode::Haar;
        h.frame_pulses = 1 << 20;
        h.validate().unwrap();
        // R = 2^5 − 1, P = U + 1 = 5, K = ceil(5/2) = 3, operand T+1 = 8, ceil(log2 33) = 6.
        assert_eq!((h.registers(), h.ops_per_pulse(), h.slots()), (31, 5, 3));
        assert_eq!(
            (h.operand_bits(), h.rd_index_bits(), h.log2_frame()),
            (8, 6, 20)
        );
        assert_eq!(h.refused_max(), (1 << 39) - 1);
        assert_eq!(
            [1, 2, 3, 4, 5, 33, 34, 64, 65].map(ceil_log2),
            [0, 1, 2, 2, 3, 6, 6, 6, 7]
        );
    }
}
