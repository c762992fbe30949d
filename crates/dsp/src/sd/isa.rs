//! Which instruction set the full-band lane kernel ([`super::pairs`]) runs on, chosen at
//! run time. The build targets the x86-64 baseline (SSE2, sixteen 128-bit registers), so
//! the binary runs on any x86-64; where the CPU has AVX2 the same kernel is compiled a
//! second time with `#[target_feature(enable = "avx2")]` and twice the lanes (sixteen
//! 256-bit registers hold what sixteen 128-bit ones held at half the width).
//!
//! Determinism: the AVX2 copy is the same Rust source with the same operations in the same
//! order per lane; FMA is deliberately *not* enabled (rustc never contracts a·b + c on its
//! own, and without the `fma` feature it cannot), and the lanes never mix except in the
//! I/Q rotation, whose pairs stay within a group at either width. So both paths give the
//! same bits and sums on every machine (crates/dsp/tests/fullband_isa.rs proves it).

use super::pairs::LanePrecision;
use crate::error::DspError;

/// The instruction path of the full-band lane kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KernelPath {
    /// The build's own target (x86-64 baseline: SSE2), on any CPU.
    Baseline,
    /// AVX2 (256-bit registers, twice the lanes), only where the CPU has it.
    Avx2,
}

impl KernelPath {
    /// The fastest path this CPU runs.
    pub fn detect() -> Self {
        if KernelPath::Avx2.available() {
            KernelPath::Avx2
        } else {
            KernelPath::Baseline
        }
    }

    /// Whether this CPU can run the path.
    pub fn available(self) -> bool {
        match self {
            KernelPath::Baseline => true,
            KernelPath::Avx2 => avx2(),
        }
    }

    /// Name as printed and parsed ("baseline", "avx2").
    pub fn name(self) -> &'static str {
        match self {
            KernelPath::Baseline => "baseline",
            KernelPath::Avx2 => "avx2",
        }
    }

    /// The path named `name` ("auto": [`KernelPath::detect`]), refused with the allowed
    /// values if unknown or if this CPU cannot run it.
    pub fn parse(name: &str) -> Result<Self, DspError> {
        let path = match name {
            "auto" => return Ok(KernelPath::detect()),
            "baseline" => KernelPath::Baseline,
            "avx2" => KernelPath::Avx2,
            _ => {
                return Err(DspError::out_of_range(
                    "kernel path",
                    format!("{name:?}"),
                    "\"auto\", \"baseline\" or \"avx2\"",
                ));
            }
        };
        path.require()
    }

    /// `self` if this CPU runs it, else an error naming the path and what would work.
    pub fn require(self) -> Result<Self, DspError> {
        if self.available() {
            Ok(self)
        } else {
            Err(DspError::out_of_range(
                "kernel path",
                self.name(),
                "a path this CPU runs: \"baseline\" (it lacks AVX2)",
            ))
        }
    }

    /// Lanes (streams) per interleaved group for a precision on this path.
    pub fn lanes(self, precision: LanePrecision) -> usize {
        match (self, precision) {
            (KernelPath::Baseline, p) => p.lanes(),
            (KernelPath::Avx2, LanePrecision::F64) => super::pairs::LANES_F64_AVX2,
            (KernelPath::Avx2, LanePrecision::F32) => super::pairs::LANES_F32_AVX2,
        }
    }

    /// What the path is, for printing ("avx2 (8 f64 lanes per group)").
    pub fn describe(self, precision: LanePrecision) -> String {
        format!(
            "{} ({} {} lanes per group)",
            self.name(),
            self.lanes(precision),
            precision.name()
        )
    }
}

#[cfg(target_arch = "x86_64")]
fn avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}

#[cfg(not(target_arch = "x86_64"))]
fn avx2() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_refused() {
        for p in [KernelPath::Baseline, KernelPath::Avx2] {
            if p.available() {
                assert_eq!(KernelPath::parse(p.name()).unwrap(), p);
            } else {
                let e = KernelPath::parse(p.name()).unwrap_err().to_string();
                assert!(e.contains("avx2") && e.contains("baseline"), "{e}");
            }
        }
        assert_eq!(KernelPath::parse("auto").unwrap(), KernelPath::detect());
        let e = KernelPath::parse("avx512").unwrap_err().to_string();
        assert!(e.contains("kernel path") && e.contains("\"avx512\""), "{e}");
        assert!(e.contains("\"auto\", \"baseline\" or \"avx2\""), "{e}");
    }
}
