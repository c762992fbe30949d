//! The ΣΔ SIMD engine: the bitstream generator's interleaved modulators ([`lanes`]) and the
//! full-band probe kernel ([`pairs`], its inner loop in `kernel`), with what they share
//! here: the lanes' arithmetic ([`LanePrecision`] and the `Lane` float) and how many make
//! a group on each instruction path. The path is the workspace's one ISA selection,
//! [`Isa`] (`tofprobe_io::isa`: detected, `TOFPROBE_ISA`, or a benchmark's `--isa`): the
//! build targets the x86-64 baseline (SSE2), the kernel is compiled again for AVX2 (twice
//! the lanes) and for AVX-512 with FMA (four times the f64 lanes; f32 lanes there run the
//! AVX2 copy, faster for them).
//!
//! Determinism: every copy is the same Rust source with the same operations in the same
//! order per lane; rustc never contracts a·b + c on its own, the AVX2 copy cannot (no
//! `fma` feature), and the AVX-512 copy fuses only the exact σ·b + v with σ = ±1 (see
//! `kernel`). The lanes never mix except in the I/Q rotation, whose pairs stay within a
//! group at every width. So all paths give the same bits and sums on every machine
//! (crates/dsp/tests/it/fullband_isa.rs proves it for each path the CPU runs).
//!
//! Layering inside: `kernel` and [`pairs`] use this module's items, [`pairs`] composes
//! `kernel`; [`lanes`] stands alone; nothing here imports the modulator that uses
//! [`lanes`].

mod kernel;
pub mod lanes;
pub mod pairs;

pub use tofprobe_io::isa::Isa;

use crate::error::DspError;

/// `isa` if this CPU runs it, else an error naming the path, what the CPU lacks and the
/// paths it runs.
pub fn require(isa: Isa) -> Result<Isa, DspError> {
    Isa::parse(isa.name(), "kernel path")
        .map_err(|e| DspError::out_of_range("kernel path", isa.name(), e.reason))
}

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitXor, Mul};

/// Lanes (streams) per f64 group: two SSE2 registers. More lanes spill (measured: 4 lanes
/// 7.1·10⁸ steps per CPU-second, 8 lanes 6.0·10⁸).
pub const LANES_F64: usize = 4;
/// Lanes per f32 group: four SSE2 registers (8 lanes 1.1·10⁹, 16 lanes 1.3·10⁹, 32 spill).
pub const LANES_F32: usize = 16;
/// Lanes per f64 group on the AVX2 path ([`Isa::Avx2`]): two 256-bit registers,
/// the register footprint of the baseline's four lanes (measured in one session, 401 bins
/// of N = 2·10⁶: 8 lanes 1.0–1.09·10⁹ steps per CPU-second, 12 lanes 0.93–1.0·10⁹, the
/// baseline's 4 lanes 0.59–0.65·10⁹).
pub const LANES_F64_AVX2: usize = 8;
/// Lanes per f32 group on the AVX2 path: four 256-bit registers (same run: 32 lanes
/// 2.2–2.4·10⁹, 16 lanes 0.94–1.0·10⁹, the baseline's 16 lanes 0.73–0.77·10⁹).
pub const LANES_F32_AVX2: usize = 32;
/// Lanes per f64 group on the AVX-512 path ([`Isa::Avx512`]): two 512-bit
/// registers, the I and the Q halves (measured in one session, 801 bins of N = 2·10⁶,
/// steps per CPU-second: 16 lanes 2.5–2.8·10⁹, 8 lanes 1.2–2.1·10⁹, 32 lanes 1.1–1.4·10⁹).
pub const LANES_F64_AVX512: usize = 16;
/// Lanes per f32 group on the AVX-512 path: f32 lanes run the AVX2 copy there (its 32
/// lanes measured 2.4–3.7·10⁹ steps per CPU-second against the AVX-512 copy's 1.6·10⁹ at
/// 32 lanes and 2.0·10⁹ at 64, 4000 bins, one thread, same session).
pub const LANES_F32_AVX512: usize = LANES_F32_AVX2;

/// Arithmetic of the modulator lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LanePrecision {
    /// f64, bit-exact with the scalar reference modulator.
    #[default]
    F64,
    /// f32 lanes (f64 across anchor spans): faster, different but equally valid bits.
    F32,
}

impl LanePrecision {
    /// Name as printed and parsed ("f64", "f32").
    pub fn name(self) -> &'static str {
        match self {
            LanePrecision::F64 => "f64",
            LanePrecision::F32 => "f32",
        }
    }

    /// Lanes per interleaved group on the baseline path ([`Self::lanes_on`] for any).
    pub fn lanes(self) -> usize {
        match self {
            LanePrecision::F64 => LANES_F64,
            LanePrecision::F32 => LANES_F32,
        }
    }

    /// Lanes (streams) per interleaved group on `isa`.
    pub fn lanes_on(self, isa: Isa) -> usize {
        match (isa, self) {
            (Isa::Scalar, p) => p.lanes(),
            (Isa::Avx2, LanePrecision::F64) => LANES_F64_AVX2,
            (Isa::Avx2, LanePrecision::F32) => LANES_F32_AVX2,
            (Isa::Avx512, LanePrecision::F64) => LANES_F64_AVX512,
            (Isa::Avx512, LanePrecision::F32) => LANES_F32_AVX512,
        }
    }

    /// The path as printed ("avx2 (8 f64 lanes per group)").
    pub fn describe(self, isa: Isa) -> String {
        format!(
            "{} ({} {} lanes per group)",
            isa.name(),
            self.lanes_on(isa),
            self.name()
        )
    }
}

/// A float the lanes compute in: arithmetic plus its sign bit.
pub(crate) trait Lane:
    Copy + Default + Debug + Send + Sync + Add<Output = Self> + Mul<Output = Self>
{
    type Bits: Copy + Default + BitAnd<Output = Self::Bits> + BitXor<Output = Self::Bits> + Eq;
    const SIGN: Self::Bits;
    /// Whether the accumulator is flushed into an f64 total at every anchor (f32), or is
    /// itself the f64 sequential sum (f64: bit-exact with sample-by-sample accumulation).
    const FLUSH: bool;
    /// Whether the AVX-512 copy of the kernel runs these lanes (f64); f32 lanes on the
    /// AVX-512 path run the AVX2 copy, faster for them ([`LANES_F32_AVX512`]).
    const AVX512: bool;
    fn bits(self) -> Self::Bits;
    fn from_bits(b: Self::Bits) -> Self;
    fn of(v: f64) -> Self;
    fn wide(self) -> f64;
    /// self·a + b rounded once (used only with self = ±1, where it equals ±a + b).
    fn mul_add(self, a: Self, b: Self) -> Self;
}

impl Lane for f64 {
    type Bits = u64;
    const SIGN: u64 = 1 << 63;
    const FLUSH: bool = false;
    const AVX512: bool = true;
    #[inline(always)]
    fn bits(self) -> u64 {
        self.to_bits()
    }
    #[inline(always)]
    fn from_bits(b: u64) -> Self {
        f64::from_bits(b)
    }
    #[inline(always)]
    fn of(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn wide(self) -> f64 {
        self
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
}

impl Lane for f32 {
    type Bits = u32;
    const SIGN: u32 = 1 << 31;
    const FLUSH: bool = true;
    const AVX512: bool = false;
    #[inline(always)]
    fn bits(self) -> u32 {
        self.to_bits()
    }
    #[inline(always)]
    fn from_bits(b: u32) -> Self {
        f32::from_bits(b)
    }
    #[inline(always)]
    fn of(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn wide(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn mul_add(self, a: f32, b: f32) -> f32 {
        f32::mul_add(self, a, b)
    }
}
