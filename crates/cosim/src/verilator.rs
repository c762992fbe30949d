//! Builds the generated RTL and the C++ harness with Verilator, cached by content hash: the
//! key covers the RTL sources, the harness source, the Verilator version and the flags, so
//! a re-run with unchanged inputs reuses the executable without re-verilating.

use crate::error::CosimError;
use crate::tools::require;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use tofprobe_io::fnv1a64;
use tofprobe_io::stale::{pid_tagged, temporary_pid};

/// The harness source, embedded so the binary works outside the source tree.
pub const HARNESS_CPP: &str = include_str!("../../../testbench/harness.cpp");

/// Verilator flags of every build (lint stays strict: no -Wno-fatal here either). X
/// assignments and initial values are `unique`, i.e. randomised at run time under
/// `+verilator+rand+reset+2` with a recorded `+verilator+seed+`, so a state element that
/// reset forgets does not silently start at zero.
pub const VERILATOR_FLAGS: &[&str] = &["-O3", "--x-assign", "unique", "--x-initial", "unique"];

/// How hard the C++ compiler works: `Check` builds fast for CI, `Speed` runs fast.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuildProfile {
    Check,
    Speed,
}

/// A built harness.
#[derive(Debug, Clone)]
pub struct HarnessBuild {
    pub exe: PathBuf,
    /// True when the cached executable was reused.
    pub reused: bool,
    pub seconds: f64,
}

/// Where builds are cached: $TOFPROBE_CACHE_DIR, else $XDG_CACHE_HOME/tofprobe, else
/// ~/.cache/tofprobe, else the system temp dir.
pub fn cache_root() -> PathBuf {
    if let Some(d) = std::env::var_os("TOFPROBE_CACHE_DIR") {
        return PathBuf::from(d);
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(d).join("tofprobe");
    }
    if let Some(d) = std::env::var_os("HOME") {
        return PathBuf::from(d).join(".cache").join("tofprobe");
    }
    std::env::temp_dir().join("tofprobe-cache")
}

fn verilog_sources(rtl_dir: &Path) -> Result<Vec<PathBuf>, CosimError> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(rtl_dir)
        .map_err(|e| CosimError::io(rtl_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .collect();
    v.sort();
    Ok(v)
}

/// A per-process counter: two threads of one process (parallel tests) building the same
/// RTL must not share a temporary directory (the first to finish publishes, the other's
/// copy is dropped).
fn next_build_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Builds (or reuses) the harness for the RTL in `rtl_dir` whose top module is `top`.
pub fn build(
    rtl_dir: &Path,
    top: &str,
    trace: bool,
    profile: BuildProfile,
) -> Result<HarnessBuild, CosimError> {
    build_with(rtl_dir, top, trace, false, profile)
}

/// A Verilator build directory in progress: removed when dropped (after a failure; after
/// the rename that publishes it there is nothing left to remove).
struct BuildInProgress<'a> {
    dir: &'a Path,
    _live: tofprobe_io::live::Live,
}

impl Drop for BuildInProgress<'_> {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(self.dir);
    }
}

/// [`build`], optionally instrumented for line coverage (`--coverage-line`; the
/// harness then writes the counts with `--coverage FILE`).
pub fn build_with(
    rtl_dir: &Path,
    top: &str,
    trace: bool,
    coverage: bool,
    profile: BuildProfile,
) -> Result<HarnessBuild, CosimError> {
    let verilator = require("verilator")?;
    let t0 = Instant::now();
    let sources = verilog_sources(rtl_dir)?;
    let version = Command::new(&verilator)
        .arg("--version")
        .output()
        .map_err(|e| CosimError::io(&verilator, e))?;
    let mut key = Vec::new();
    key.extend_from_slice(&version.stdout);
    key.extend_from_slice(HARNESS_CPP.as_bytes());
    key.extend_from_slice(
        format!(
            "{top} {trace} {} {profile:?} {VERILATOR_FLAGS:?}",
            if coverage { "--coverage-line" } else { "" }
        )
        .as_bytes(),
    );
    for s in &sources {
        key.extend_from_slice(
            s.file_name()
                .map(|n| n.as_encoded_bytes())
                .unwrap_or_default(),
        );
        key.extend_from_slice(&std::fs::read(s).map_err(|e| CosimError::io(s, e))?);
    }
    let hash = format!("{:016x}", fnv1a64(&key));
    let dir = cache_root().join("verilator").join(&hash);
    let exe = dir.join("harness");
    if exe.is_file() {
        return Ok(HarnessBuild {
            exe,
            reused: true,
            seconds: t0.elapsed().as_secs_f64(),
        });
    }
    let tmp = cache_root()
        .join("verilator")
        .join(pid_tagged(&hash, &next_build_id().to_string()));
    let _ = std::fs::remove_dir_all(&tmp);
    // Builds of killed runs (a dead PID in the name) are never finished: remove them.
    tofprobe_io::stale::remove_stale(&cache_root().join("verilator"), temporary_pid);
    // Registered while the build runs, so an interrupt removes it (tofprobe_io::live), and
    // removed by the guard on any error: a failed or interrupted build leaves no directory.
    let ((), live) = tofprobe_io::live::create(
        tofprobe_io::live::Kind::Temporary,
        || std::fs::create_dir_all(&tmp),
        |_| tmp.clone(),
    )
    .map_err(|e| CosimError::io(&tmp, e))?;
    let _building = BuildInProgress {
        dir: &tmp,
        _live: live,
    };
    let pre = format!("{top}__DOT__u_pixel__DOT__");
    let config = format!(
        "// Generated by tofprobe-cosim for {top}.\n\
         #define TOP_HEADER \"Vtop.h\"\n#define TOP_ROOT_HEADER \"Vtop___024root.h\"\n\
         #define TOP_CLASS Vtop\n#define PIX_WE (top->rootp->{pre}we)\n\
         #define PIX_Y (top->rootp->{pre}y)\n{}",
        if trace {
            "#define TOFPROBE_TRACE 1\n"
        } else {
            ""
        }
    );
    let cfg_path = tmp.join("tofprobe_harness_config.h");
    std::fs::write(&cfg_path, config).map_err(|e| CosimError::io(&cfg_path, e))?;
    let cpp = tmp.join("harness.cpp");
    std::fs::write(&cpp, HARNESS_CPP).map_err(|e| CosimError::io(&cpp, e))?;
    let obj = tmp.join("obj");
    let mut cmd = Command::new(&verilator);
    cmd.args(["--cc", "--exe", "--build", "-j", "2", "--prefix", "Vtop"])
        .args(VERILATOR_FLAGS)
        .args(["--top-module", top, "-Mdir"])
        .arg(&obj)
        .args(["-o", "harness", "-CFLAGS"])
        .arg(format!(
            "-I{} {}",
            tmp.display(),
            match profile {
                BuildProfile::Check => "-O1",
                BuildProfile::Speed => "-O2",
            }
        ));
    cmd.arg("-MAKEFLAGS").arg(match profile {
        // CI: verilator's C++ compile dominates, so compile cheaply.
        BuildProfile::Check => "OPT_FAST=-O1 OPT_SLOW=-O0 OPT_GLOBAL=-O1",
        BuildProfile::Speed => "OPT_FAST=-O2 OPT_SLOW=-O1 OPT_GLOBAL=-O2",
    });
    if trace {
        cmd.arg("--trace");
    }
    if coverage {
        cmd.arg("--coverage-line");
    }
    cmd.args(&sources).arg(&cpp);
    let out = cmd.output().map_err(|e| CosimError::io(&verilator, e))?;
    if !out.status.success() {
        return Err(CosimError::ToolFailed {
            tool: "verilator",
            status: out.status.to_string(),
            output: format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ),
        });
    }
    let built = obj.join("harness");
    std::fs::rename(&built, tmp.join("harness")).map_err(|e| CosimError::io(&built, e))?;
    let _ = std::fs::remove_dir_all(&obj);
    // Publish atomically; a concurrent identical build may have won the race.
    if std::fs::rename(&tmp, &dir).is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    Ok(HarnessBuild {
        exe,
        reused: false,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
