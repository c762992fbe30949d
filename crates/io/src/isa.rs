//! The workspace's one instruction-set selection: which copy of the vector kernels runs
//! (the photon Monte Carlo, `tofprobe_scene`'s batch; the pixel's lanes,
//! `tofprobe_pixel::lanes`; the full-band ΣΔ kernel, `tofprobe_dsp::sd::simd`).
//!
//! The build targets the x86-64 baseline (SSE2), so one binary runs on any x86-64 CPU; the
//! kernels are compiled again for AVX2 and for AVX-512 and chosen here at run time:
//!
//! 1. a scoped override ([`with_isa`]: `tofprobe bench … --isa`, and each benchmark row),
//! 2. else the environment variable [`ENV`] (`TOFPROBE_ISA = scalar | avx2 | avx512`),
//! 3. else the fastest the CPU has ([`Isa::detect`]).
//!
//! An ISA the CPU lacks is refused, naming what it lacks, never run. Every copy computes
//! the same bits (each kernel's crate tests its copies against the scalar one), so the
//! choice moves only the speed.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, OnceLock};

/// The environment variable that forces an ISA.
pub const ENV: &str = "TOFPROBE_ISA";

/// An instruction-set path of the vector kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Isa {
    /// The build's own target (x86-64 baseline: SSE2; any CPU, any architecture).
    Scalar,
    /// AVX2 (256-bit registers).
    Avx2,
    /// AVX-512 F, VL, DQ with AVX2 and FMA (512-bit registers, 32 of them).
    Avx512,
}

/// An ISA name that is not one, or an ISA this CPU cannot run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IsaError {
    /// Where the name came from (`TOFPROBE_ISA`, `--isa`).
    pub origin: String,
    /// The value given.
    pub value: String,
    /// What is wrong, with the values that would work.
    pub reason: String,
}

impl std::fmt::Display for IsaError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {:?}: {}", self.origin, self.value, self.reason)
    }
}

impl std::error::Error for IsaError {}

impl Isa {
    /// Every ISA, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Scalar, Isa::Avx2, Isa::Avx512];

    /// The name as printed and parsed.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The CPU features the path needs, as printed.
    pub fn features(self) -> &'static str {
        match self {
            Isa::Scalar => "x86-64 baseline (SSE2)",
            Isa::Avx2 => "AVX2",
            Isa::Avx512 => "AVX-512 F, VL and DQ, AVX2 and FMA",
        }
    }

    /// Whether this CPU runs the path.
    pub fn available(self) -> bool {
        match self {
            Isa::Scalar => true,
            Isa::Avx2 => cpu::avx2(),
            Isa::Avx512 => cpu::avx512(),
        }
    }

    /// The fastest path this CPU runs.
    pub fn detect() -> Isa {
        *Self::ALL
            .iter()
            .rev()
            .find(|i| i.available())
            .unwrap_or(&Isa::Scalar)
    }

    /// The paths this CPU runs, narrowest first.
    pub fn supported() -> Vec<Isa> {
        Self::ALL.into_iter().filter(|i| i.available()).collect()
    }

    /// The vector paths a bit-identity test holds to the scalar one: those this CPU runs,
    /// each it lacks named on stdout as skipped (so a run on an AVX2-only CPU says what it
    /// did not check).
    pub fn vector_paths_to_test() -> Vec<Isa> {
        Self::ALL[1..]
            .iter()
            .copied()
            .filter(|isa| {
                let here = isa.available();
                if !here {
                    println!(
                        "skipped: this CPU lacks {} ({})",
                        isa.name(),
                        isa.features()
                    );
                }
                here
            })
            .collect()
    }

    /// The ISA named `value` (read from `origin`, for the message), refused if the name is
    /// unknown (naming the allowed ones) or the CPU lacks it (naming what it lacks and
    /// what it runs).
    pub fn parse(value: &str, origin: &str) -> Result<Isa, IsaError> {
        let refuse = |reason: String| IsaError {
            origin: origin.to_string(),
            value: value.to_string(),
            reason,
        };
        let Some(isa) = Self::ALL.into_iter().find(|i| i.name() == value) else {
            return Err(refuse(format!(
                "not an ISA; allowed: {}",
                names(&Self::ALL)
            )));
        };
        if !isa.available() {
            return Err(refuse(format!(
                "this CPU lacks {} (it runs {})",
                isa.features(),
                names(&Self::supported())
            )));
        }
        Ok(isa)
    }

    /// The ISA the kernels run now: the scoped override, else [`ENV`], else
    /// [`Isa::detect`]. Panics with [`from_env`]'s message if [`ENV`] holds a value it
    /// refuses (the front ends call [`from_env`] first and print it as an error).
    pub fn current() -> Isa {
        match FORCED.load(Ordering::Acquire) {
            1 => Isa::Scalar,
            2 => Isa::Avx2,
            3 => Isa::Avx512,
            _ => match env_choice() {
                Ok(Some(i)) => *i,
                Ok(None) => Isa::detect(),
                Err(e) => panic!("{e}"),
            },
        }
    }
}

/// `"scalar", "avx2"` for printing.
fn names(isas: &[Isa]) -> String {
    let v: Vec<String> = isas.iter().map(|i| format!("\"{}\"", i.name())).collect();
    v.join(", ")
}

/// [`ENV`] as read once per process.
fn env_choice() -> &'static Result<Option<Isa>, IsaError> {
    static CHOICE: OnceLock<Result<Option<Isa>, IsaError>> = OnceLock::new();
    CHOICE.get_or_init(|| match std::env::var(ENV) {
        Ok(v) if !v.is_empty() => Isa::parse(&v, ENV).map(Some),
        _ => Ok(None),
    })
}

/// The ISA forced by [`ENV`] (`None`: unset or empty), or the refusal of its value.
pub fn from_env() -> Result<Option<Isa>, IsaError> {
    env_choice().clone()
}

/// The ISAs a benchmark measures: `forced` (`--isa`) if given, else the one [`ENV`]
/// forces, else every ISA this CPU runs, narrowest first.
pub fn to_measure(forced: Option<Isa>) -> Result<Vec<Isa>, IsaError> {
    Ok(match forced.or(from_env()?) {
        Some(i) => vec![i],
        None => Isa::supported(),
    })
}

/// 0: no override; else 1 + the index in [`Isa::ALL`].
static FORCED: AtomicU8 = AtomicU8::new(0);
/// Serialises the scoped overrides (one at a time in a process).
static SCOPE: Mutex<()> = Mutex::new(());

/// Runs `f` with every kernel on `isa` (which the caller has checked the CPU runs: see
/// [`Isa::parse`]; a kernel asked for a path the CPU lacks runs the scalar copy), then
/// restores the previous choice. One override at a time: a second caller waits.
pub fn with_isa<R>(isa: Isa, f: impl FnOnce() -> R) -> R {
    let _one = SCOPE.lock().unwrap_or_else(|p| p.into_inner());
    struct Restore(u8);
    impl Drop for Restore {
        fn drop(&mut self) {
            FORCED.store(self.0, Ordering::Release);
        }
    }
    let code = 1 + Isa::ALL.iter().position(|&i| i == isa).unwrap_or(0) as u8;
    let _restore = Restore(FORCED.swap(code, Ordering::AcqRel));
    f()
}

#[cfg(target_arch = "x86_64")]
mod cpu {
    pub fn avx2() -> bool {
        std::arch::is_x86_feature_detected!("avx2")
    }

    /// What every AVX-512 copy is compiled for (the union of the kernels' features).
    pub fn avx512() -> bool {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod cpu {
    pub fn avx2() -> bool {
        false
    }
    pub fn avx512() -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_and_missing_isas_are_refused() {
        for isa in Isa::ALL {
            if isa.available() {
                assert_eq!(Isa::parse(isa.name(), ENV), Ok(isa));
            } else {
                let e = Isa::parse(isa.name(), ENV).unwrap_err().to_string();
                assert!(e.contains(ENV) && e.contains(isa.features()), "{e}");
                assert!(e.contains("\"scalar\""), "{e}");
            }
        }
        let e = Isa::parse("avx1024", "--isa").unwrap_err().to_string();
        assert_eq!(
            e,
            "--isa = \"avx1024\": not an ISA; allowed: \"scalar\", \"avx2\", \"avx512\""
        );
        assert_eq!(Isa::supported().last(), Some(&Isa::detect()));
        assert_eq!(Isa::supported()[0], Isa::Scalar);
    }

    #[test]
    fn a_scoped_override_holds_inside_and_is_restored_after() {
        let before = Isa::current();
        for isa in Isa::supported() {
            assert_eq!(with_isa(isa, Isa::current), isa);
            assert_eq!(Isa::current(), before);
        }
        let r = std::panic::catch_unwind(|| with_isa(Isa::Scalar, || panic!("inside")));
        assert!(r.is_err());
        assert_eq!(Isa::current(), before, "restored after a panic");
    }
}
