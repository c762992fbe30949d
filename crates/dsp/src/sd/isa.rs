//! Which instruction set the full-band lane kernel ([`super::pairs`]) runs on, chosen at
//! run time. The build targets the x86-64 baseline (SSE2, sixteen 128-bit registers), so
//! the binary runs on any x86-64; where the CPU has AVX2 the same kernel is compiled a
//! second time with `#[target_feature(enable = "avx2")]` and twice the lanes (sixteen
//! 256-bit registers hold what sixteen 128-bit ones held at half the width), and where it
//! has AVX-512 (F and VL) and FMA a third time with four times the f64 lanes (thirty-two
//! 512-bit registers: nothing spills; f32 lanes on that path run the AVX2 copy, faster
//! for them).
//!
//! Determinism: every copy is the same Rust source with the same operations in the same
//! order per lane; rustc never contracts a·b + c on its own, the AVX2 copy cannot (no
//! `fma` feature), and the AVX-512 copy fuses only the exact σ·b + v with σ = ±1
//! ([`super::pairs_kernel`]). The lanes never mix except in the I/Q rotation, whose pairs
//! stay within a group at every width. So all paths give the same bits and sums on every
//! machine (crates/dsp/tests/it/fullband_isa.rs proves it for each path the CPU runs).

use super::lane::LanePrecision;
use crate::error::DspError;

/// The instruction path of the full-band lane kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KernelPath {
    /// The build's own target (x86-64 baseline: SSE2), on any CPU.
    Baseline,
    /// AVX2 (256-bit registers, twice the lanes), only where the CPU has it.
    Avx2,
    /// AVX-512 F + VL with FMA (32 × 512-bit registers, four times the lanes), only where
    /// the CPU has them all.
    Avx512,
}

impl KernelPath {
    /// The fastest path this CPU runs.
    pub fn detect() -> Self {
        if KernelPath::Avx512.available() {
            KernelPath::Avx512
        } else if KernelPath::Avx2.available() {
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
            KernelPath::Avx512 => avx512(),
        }
    }

    /// Every path, narrowest first.
    pub const ALL: [KernelPath; 3] = [KernelPath::Baseline, KernelPath::Avx2, KernelPath::Avx512];

    /// The paths this CPU runs, narrowest first.
    pub fn supported() -> Vec<KernelPath> {
        Self::ALL.into_iter().filter(|p| p.available()).collect()
    }

    /// Name as printed and parsed ("baseline", "avx2", "avx512").
    pub fn name(self) -> &'static str {
        match self {
            KernelPath::Baseline => "baseline",
            KernelPath::Avx2 => "avx2",
            KernelPath::Avx512 => "avx512",
        }
    }

    /// The path named `name` ("auto": [`KernelPath::detect`]), refused with the allowed
    /// values if unknown or if this CPU cannot run it.
    pub fn parse(name: &str) -> Result<Self, DspError> {
        let path = match name {
            "auto" => return Ok(KernelPath::detect()),
            "baseline" => KernelPath::Baseline,
            "avx2" => KernelPath::Avx2,
            "avx512" => KernelPath::Avx512,
            _ => {
                return Err(DspError::out_of_range(
                    "kernel path",
                    format!("{name:?}"),
                    "\"auto\", \"baseline\", \"avx2\" or \"avx512\"",
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
            let runs: Vec<String> = Self::supported()
                .iter()
                .map(|p| format!("\"{}\"", p.name()))
                .collect();
            Err(DspError::out_of_range(
                "kernel path",
                self.name(),
                format!(
                    "a path this CPU runs: {} (it lacks {})",
                    runs.join(" or "),
                    self.features()
                ),
            ))
        }
    }

    /// Lanes (streams) per interleaved group for a precision on this path.
    pub fn lanes(self, precision: LanePrecision) -> usize {
        match (self, precision) {
            (KernelPath::Baseline, p) => p.lanes(),
            (KernelPath::Avx2, LanePrecision::F64) => super::lane::LANES_F64_AVX2,
            (KernelPath::Avx2, LanePrecision::F32) => super::lane::LANES_F32_AVX2,
            (KernelPath::Avx512, LanePrecision::F64) => super::lane::LANES_F64_AVX512,
            (KernelPath::Avx512, LanePrecision::F32) => super::lane::LANES_F32_AVX512,
        }
    }

    /// The CPU features the path needs, as printed.
    pub fn features(self) -> &'static str {
        match self {
            KernelPath::Baseline => "x86-64 (SSE2)",
            KernelPath::Avx2 => "AVX2",
            KernelPath::Avx512 => "AVX-512 F and VL, AVX2 and FMA",
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

/// What `step_span_avx512` is compiled for (crates/dsp/src/sd/pairs_kernel.rs).
#[cfg(target_arch = "x86_64")]
fn avx512() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
}

#[cfg(not(target_arch = "x86_64"))]
fn avx512() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_refused() {
        for p in KernelPath::ALL {
            if p.available() {
                assert_eq!(KernelPath::parse(p.name()).unwrap(), p);
            } else {
                let e = KernelPath::parse(p.name()).unwrap_err().to_string();
                assert!(e.contains(p.name()) && e.contains("\"baseline\""), "{e}");
                assert!(e.contains(p.features()), "{e}");
            }
        }
        assert_eq!(KernelPath::parse("auto").unwrap(), KernelPath::detect());
        assert_eq!(KernelPath::supported().last(), Some(&KernelPath::detect()));
        let e = KernelPath::parse("avx1024").unwrap_err().to_string();
        assert!(
            e.contains("kernel path") && e.contains("\"avx1024\""),
            "{e}"
        );
        assert!(
            e.contains("\"auto\", \"baseline\", \"avx2\" or \"avx512\""),
            "{e}"
        );
    }
}
