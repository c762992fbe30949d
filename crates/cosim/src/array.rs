//! Co-simulation of the array RTL (`templates/array.v`) at its ports: the Verilator
//! harness `testbench/array_harness.cpp` (built once per RTL, cached by content hash like
//! the pixel's: every run of one design shares the build, whatever vectors it replays) and
//! the Icarus testbench `testbench/array_tb.v`, both replaying the array's golden vectors
//! (`tofprobe_rtlgen::array_vectors`) and reporting mismatches in the harness protocol.

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

/// From this many pixels on, the harness is Verilated hierarchically: the pixel module is a
/// `hier_block`, Verilated and compiled once and instantiated R × C times, instead of
/// inlined R × C times. Measured (`tofprobe bench cosim-array`, docs/performance.md "The
/// array RTL at scale"): a 2 × 2 array of the tiny example pixel builds cheaper flat (9.9
/// against 13 CPU-s), 4 × 4 of scenes/sensor-64x64.toml's pixel hierarchically (13.1
/// against 23.6 CPU-s), and the flat build grows faster than R × C.
pub const HIERARCHICAL_FROM_PIXELS: usize = 16;

/// The hierarchical build's C++ in pieces: the array top's model (R × C pixel instances'
/// calls) is otherwise one file of a few giant functions, which one compiler process takes
/// alone (at 64 × 64: 5.9 GB and most of the build); split into files of functions of at
/// most this many Verilator statements, `make -j 2` compiles them side by side.
pub const SPLIT_FLAGS: &[&str] = &["--output-split", "10000", "--output-split-cfuncs", "10000"];

/// How the harness's Verilator build treats the pixel module.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Every pixel inlined into one model (small arrays).
    Flat,
    /// The pixel one `hier_block` model, compiled once.
    Hierarchical,
}

impl Layout {
    /// Its name in reports: `flat` or `hierarchical`.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Flat => "flat",
            Layout::Hierarchical => "hierarchical",
        }
    }

    /// The layout for an array of `pixels` pixels ([`HIERARCHICAL_FROM_PIXELS`]).
    pub fn for_pixels(pixels: usize) -> Layout {
        if pixels >= HIERARCHICAL_FROM_PIXELS {
            Layout::Hierarchical
        } else {
            Layout::Flat
        }
    }
}

/// The pixel module of the array top `top` (`<prefix>_array` → `<prefix>_pixel`).
fn pixel_module(top: &str) -> String {
    let prefix = top.strip_suffix("_array").unwrap_or(top);
    tofprobe_rtlgen::naming::module_names(prefix).0
}

/// Builds (or reuses) the Verilator harness of the array RTL in `rtl_dir` (top `top`), its
/// pixel inlined or a hierarchical block as `layout` says, in the build cache (`cache`:
/// another cache root, e.g. an empty one for a benchmark's cold build).
pub fn build(
    rtl_dir: &Path,
    top: &str,
    profile: BuildProfile,
    layout: Layout,
    cache: Option<&Path>,
) -> Result<HarnessBuild, CosimError> {
    let verilator = require("verilator")?;
    let t0 = Instant::now();
    let srcs = sources(rtl_dir)?;
    let key = build_key(
        &verilator,
        "array ",
        ARRAY_HARNESS_CPP,
        &format!("{top} {profile:?} {layout:?} {VERILATOR_FLAGS:?} {SPLIT_FLAGS:?}"),
        &srcs,
    )?;
    let hash = format!("array-{:016x}", fnv1a64(&key));
    let root = cache
        .map_or_else(cache_root, Path::to_path_buf)
        .join("verilator");
    let (exe, reused) = cached_entry(&root, &hash, |tmp| {
        let cpp = tmp.join("array_harness.cpp");
        std::fs::write(&cpp, ARRAY_HARNESS_CPP).map_err(|e| CosimError::io(&cpp, e))?;
        let cflags = "-DTOP_HEADER='\"Vtop.h\"' -DTOP_CLASS=Vtop";
        let vlt = tmp.join("hier.vlt");
        let extra: Vec<String> = match layout {
            Layout::Flat => Vec::new(),
            Layout::Hierarchical => {
                let text = format!(
                    "`verilator_config\nhier_block -module \"{}\"\n",
                    pixel_module(top)
                );
                std::fs::write(&vlt, text).map_err(|e| CosimError::io(&vlt, e))?;
                let mut v: Vec<String> = vec!["--hierarchical".into(), vlt.display().to_string()];
                v.extend(SPLIT_FLAGS.iter().map(|f| f.to_string()));
                v
            }
        };
        let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
        verilate(&verilator, tmp, top, profile, cflags, &extra, &srcs, &cpp).map(|_| ())
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
