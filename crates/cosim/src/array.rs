//! Co-simulation of the array RTL (`templates/array.v`) at its ports: the Verilator
//! harness `testbench/array_harness.cpp` (built once per RTL, cached by content hash like
//! the pixel's: every run of one design shares the build, whatever vectors it replays) and
//! the Icarus testbench `testbench/array_tb.v`, both replaying the array's golden vectors
//! (`tofprobe_array::rtl_vectors`) and reporting mismatches in the harness protocol.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use tofprobe_io::fnv1a64;

use crate::error::CosimError;
use crate::harness::{RunOutcome, parse_output};
use crate::tools::require;
use crate::verilator::{
    BuildProfile, HarnessBuild, VERILATOR_FLAGS, build_key, cache_root, cached_entry, verilate,
};

/// The largest array (R × C pixels) co-simulated whole: 64 × 64, the paper's scale, whose
/// Verilator build and short-frame run stay within minutes on two cores; a larger array
/// (the RTL renders at any size) is co-simulated as a tile of it (`cosim --tile`).
pub const MAX_COSIM_PIXELS: usize = 64 * 64;

/// The array harness, embedded so the binary works outside the source tree.
pub const ARRAY_HARNESS_CPP: &str = include_str!("../../../testbench/array_harness.cpp");

/// The array testbench for Icarus (the one an array set's verification kit carries).
pub use tofprobe_rtlgen::kit::ARRAY_TB_V;

/// The RTL of an array set: its `.v` files but the verification kit's testbench
/// (`tofprobe_rtlgen::kit::KIT_TESTBENCH`), which the simulators get from here.
fn sources(rtl_dir: &Path) -> Result<Vec<std::path::PathBuf>, CosimError> {
    let mut v: Vec<_> = std::fs::read_dir(rtl_dir)
        .map_err(|e| CosimError::io(rtl_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .filter(|p| {
            p.file_name()
                .is_none_or(|n| n != tofprobe_rtlgen::kit::KIT_TESTBENCH)
        })
        .collect();
    v.sort();
    Ok(v)
}

/// Builds (or reuses) the Verilator harness of the array RTL in `rtl_dir` (top `top`).
pub fn build(rtl_dir: &Path, top: &str, profile: BuildProfile) -> Result<HarnessBuild, CosimError> {
    let verilator = require("verilator")?;
    let t0 = Instant::now();
    let srcs = sources(rtl_dir)?;
    let key = build_key(
        &verilator,
        "array ",
        ARRAY_HARNESS_CPP,
        &format!("{top} {profile:?} {VERILATOR_FLAGS:?}"),
        &srcs,
    )?;
    let hash = format!("array-{:016x}", fnv1a64(&key));
    let root = cache_root().join("verilator");
    let (exe, reused) = cached_entry(&root, &hash, |tmp| {
        let cpp = tmp.join("array_harness.cpp");
        std::fs::write(&cpp, ARRAY_HARNESS_CPP).map_err(|e| CosimError::io(&cpp, e))?;
        let cflags = "-DTOP_HEADER='\"Vtop.h\"' -DTOP_CLASS=Vtop";
        verilate(&verilator, tmp, top, profile, cflags, &[], &srcs, &cpp).map(|_| ())
    })?;
    Ok(HarnessBuild {
        exe,
        reused,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Runs a built array harness on the vectors in `vec_dir`, from `rtl_dir` (where a deep
/// probe ROM's hex file is read), its registers powered up from Verilator's random values
/// of `x_seed` (≥ 1).
pub fn run_verilator(
    exe: &Path,
    rtl_dir: &Path,
    vec_dir: &Path,
    x_seed: u64,
) -> Result<RunOutcome, CosimError> {
    let vec_dir = std::path::absolute(vec_dir).map_err(|e| CosimError::io(vec_dir, e))?;
    let out = Command::new(exe)
        .current_dir(rtl_dir)
        .arg(&vec_dir)
        // Randomised initial values (recorded seed): a register the reset forgets shows.
        .arg("+verilator+rand+reset+2")
        .arg(format!("+verilator+seed+{}", x_seed.max(1)))
        .output()
        .map_err(|e| CosimError::io(exe, e))?;
    parse_output(
        "verilator array harness",
        &format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// Compiles `testbench/array_tb.v` with the array RTL of `rtl_dir` and the vectors of
/// `vec_dir` under Icarus (in `work`), runs it from `rtl_dir` and parses its output.
pub fn run_icarus(rtl_dir: &Path, vec_dir: &Path, work: &Path) -> Result<RunOutcome, CosimError> {
    let iverilog = require("iverilog")?;
    let vvp = require("vvp")?;
    std::fs::create_dir_all(work).map_err(|e| CosimError::io(work, e))?;
    let vec_dir = std::path::absolute(vec_dir).map_err(|e| CosimError::io(vec_dir, e))?;
    let tb = work.join("array_tb.v");
    std::fs::write(&tb, ARRAY_TB_V).map_err(|e| CosimError::io(&tb, e))?;
    let exe =
        std::path::absolute(work.join("array_tb.vvp")).map_err(|e| CosimError::io(work, e))?;
    let t0 = Instant::now();
    let out = Command::new(&iverilog)
        .args(["-g2005", "-o"])
        .arg(&exe)
        .arg(format!("-I{}", vec_dir.display()))
        .arg(format!("-DAR_VECTORS=\"{}/\"", vec_dir.display()))
        .arg(&tb)
        .args(sources(rtl_dir)?)
        .output()
        .map_err(|e| CosimError::io(&iverilog, e))?;
    if !out.status.success() {
        return Err(CosimError::ToolFailed {
            tool: "iverilog",
            status: out.status.to_string(),
            output: String::from_utf8_lossy(&out.stderr).into_owned(),
        });
    }
    let run = Command::new(&vvp)
        .current_dir(rtl_dir)
        .arg("-n")
        .arg(&exe)
        .output()
        .map_err(|e| CosimError::io(&vvp, e))?;
    let mut o = parse_output(
        "icarus array testbench",
        &format!(
            "{}{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        ),
    )?;
    o.seconds = t0.elapsed().as_secs_f64();
    Ok(o)
}
