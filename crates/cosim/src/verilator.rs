//! Builds the generated RTL and the C++ harness with Verilator, cached by content hash: the
//! key covers the RTL sources, the harness source, the Verilator version and the flags, so
//! a re-run with unchanged inputs reuses the executable without re-verilating.
//!
//! One build per key, however many runs want it at once: a build holds an exclusive lock
//! on `<hash>.lock` (threads of one process and other processes alike), so the parallel
//! tests that co-simulate one design wait for the first build and reuse it. An entry is
//! published whole (a directory renamed into place) with a checksum of its executable; an
//! entry whose executable is missing or does not match is removed and built again.

use crate::error::CosimError;
use crate::runtime::next_build_id;
use crate::tools::{require, version};
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

/// Where builds are cached: the one cache root of every tofprobe cache
/// ([`tofprobe_io::cache::root`]: `$TOFPROBE_CACHE`, …).
pub fn cache_root() -> PathBuf {
    tofprobe_io::cache::root()
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

/// The harness's `PIX_RST` define when `top`'s file declares the directed sequencer's
/// `px_rst` (the pixel's reset: the pin, or a reset in the middle of a frame); empty for
/// a top whose pixel is reset by the `rst` pin alone (the harness's default).
fn pixel_reset(top: &str, sources: &[PathBuf]) -> Result<String, CosimError> {
    let file = format!("{top}.v");
    for path in sources
        .iter()
        .filter(|p| p.file_name().is_some_and(|n| *n == *file))
    {
        let text = std::fs::read_to_string(path).map_err(|e| CosimError::io(path, e))?;
        if text.contains("wire px_rst ") {
            return Ok(format!(
                "#define PIX_RST (top->rootp->{top}__DOT__px_rst)\n"
            ));
        }
    }
    Ok(String::new())
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

/// The file beside a cached executable holding its checksum ([`checksum`]).
const CHECKSUM: &str = "harness.fnv";

/// The checksum of an executable's bytes: its length and FNV-1a 64.
fn checksum(bytes: &[u8]) -> String {
    format!("{} {:016x}\n", bytes.len(), fnv1a64(bytes))
}

/// Whether the cache entry `dir` holds an executable matching its checksum.
fn entry_is_whole(dir: &Path) -> bool {
    let Ok(sum) = std::fs::read_to_string(dir.join(CHECKSUM)) else {
        return false;
    };
    std::fs::read(dir.join("harness")).is_ok_and(|bytes| checksum(&bytes) == sum)
}

/// The exclusive lock of cache key `hash` (a lock file beside the entries; the lock is
/// released when the returned file is dropped, or by the kernel if the process dies).
fn lock_key(root: &Path, hash: &str) -> Result<std::fs::File, CosimError> {
    std::fs::create_dir_all(root).map_err(|e| CosimError::io(root, e))?;
    let path = root.join(format!("{hash}.lock"));
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(|e| CosimError::io(&path, e))?;
    file.lock().map_err(|e| CosimError::io(&path, e))?;
    Ok(file)
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
    let key = build_key(
        &verilator,
        "",
        HARNESS_CPP,
        &format!(
            "{top} {trace} {} {profile:?} {VERILATOR_FLAGS:?}",
            if coverage { "--coverage-line" } else { "" }
        ),
        &sources,
    )?;
    let hash = format!("{:016x}", fnv1a64(&key));
    let root = cache_root().join("verilator");
    let (exe, reused) = cached_entry(&root, &hash, |tmp| {
        let pre = format!("{top}__DOT__u_pixel__DOT__");
        let config = format!(
            "// Generated by tofprobe-cosim for {top}.\n\
         #define TOP_HEADER \"Vtop.h\"\n#define TOP_ROOT_HEADER \"Vtop___024root.h\"\n\
         #define TOP_CLASS Vtop\n#define PIX_WE (top->rootp->{pre}we)\n\
         #define PIX_Y (top->rootp->{pre}y)\n{}{}",
            pixel_reset(top, &sources)?,
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
        let mut extra = Vec::new();
        if trace {
            extra.push("--trace");
        }
        if coverage {
            extra.push("--coverage-line");
        }
        let cflags = format!("-I{}", tmp.display());
        verilate(
            &verilator, tmp, top, profile, &cflags, &extra, &sources, &cpp,
        )
        .map(|_| ())
    })?;
    Ok(HarnessBuild {
        exe,
        reused,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// The cache key of a harness build: the Verilator version, a `tag`, the harness source,
/// the build's `options` (top, profile, flags) and every RTL source's name and bytes.
pub(crate) fn build_key(
    verilator: &Path,
    tag: &str,
    harness: &str,
    options: &str,
    sources: &[PathBuf],
) -> Result<Vec<u8>, CosimError> {
    let mut key = tag.as_bytes().to_vec();
    key.extend_from_slice(&version(verilator)?);
    key.extend_from_slice(harness.as_bytes());
    key.extend_from_slice(options.as_bytes());
    for s in sources {
        key.extend_from_slice(
            s.file_name()
                .map(|n| n.as_encoded_bytes())
                .unwrap_or_default(),
        );
        key.extend_from_slice(&std::fs::read(s).map_err(|e| CosimError::io(s, e))?);
    }
    Ok(key)
}

/// Verilates `sources` with the harness `cpp` (top `top`, the class `Vtop`) into the
/// executable `tmp/harness`, compiled at `profile`'s optimisation with `cflags` and the
/// `extra` Verilator options; the object directory is removed afterwards. `tmp` is a
/// directory of the cache root ([`cached_entry`]): the run-time library's objects are
/// shared through that root ([`crate::runtime`]), so Verilator only generates and make
/// is run here. Returns whether those objects came from the cache.
#[allow(clippy::too_many_arguments)]
pub(crate) fn verilate(
    verilator: &Path,
    tmp: &Path,
    top: &str,
    profile: BuildProfile,
    cflags: &str,
    extra: &[&str],
    sources: &[PathBuf],
    cpp: &Path,
) -> Result<bool, CosimError> {
    let obj = tmp.join("obj");
    let out = Command::new(verilator)
        .args(["--cc", "--exe", "--prefix", "Vtop"])
        .args(VERILATOR_FLAGS)
        .args(["--top-module", top, "-Mdir"])
        .arg(&obj)
        .args(["-o", "harness", "-CFLAGS"])
        .arg(format!(
            "{cflags} {}",
            match profile {
                BuildProfile::Check => "-O1",
                BuildProfile::Speed => "-O2",
            }
        ))
        .args(extra)
        .args(sources)
        .arg(cpp)
        .output()
        .map_err(|e| CosimError::io(verilator, e))?;
    tool_succeeded("verilator", &out)?;
    let make_flags: &[&str] = match profile {
        // CI: verilator's C++ compile dominates, so compile cheaply.
        BuildProfile::Check => &["OPT_FAST=-O1", "OPT_SLOW=-O0", "OPT_GLOBAL=-O1"],
        BuildProfile::Speed => &["OPT_FAST=-O2", "OPT_SLOW=-O1", "OPT_GLOBAL=-O2"],
    };
    let runtime = tmp
        .parent()
        .and_then(|root| crate::runtime::seed(root, verilator, &obj, tmp, make_flags));
    let out = Command::new(require("make")?)
        .arg("-C")
        .arg(&obj)
        .args(["-f", "Vtop.mk", "-j", "2"])
        .args(make_flags)
        .output()
        .map_err(|e| CosimError::io(Path::new("make"), e))?;
    tool_succeeded("make", &out)?;
    let reused = runtime.as_ref().is_some_and(|r| r.reused);
    if let Some(r) = runtime {
        r.publish(&obj);
    }
    let built = obj.join("harness");
    std::fs::rename(&built, tmp.join("harness")).map_err(|e| CosimError::io(&built, e))?;
    let _ = std::fs::remove_dir_all(&obj);
    Ok(reused)
}

/// A tool's failure with its output, or nothing.
fn tool_succeeded(tool: &'static str, out: &std::process::Output) -> Result<(), CosimError> {
    if out.status.success() {
        return Ok(());
    }
    Err(CosimError::ToolFailed {
        tool,
        status: out.status.to_string(),
        output: format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    })
}

/// The cache entry `root/<hash>` (an executable `harness` and its checksum): reused when
/// whole, else built by `build` into a temporary directory (which must leave the executable
/// at `harness` in it) and published by renaming that directory into place. The key's lock
/// is held throughout. Returns the executable and whether it was reused.
pub(crate) fn cached_entry(
    root: &Path,
    hash: &str,
    build: impl FnOnce(&Path) -> Result<(), CosimError>,
) -> Result<(PathBuf, bool), CosimError> {
    let dir = root.join(hash);
    let exe = dir.join("harness");
    // Held until this function returns: a concurrent build of the same key waits here.
    let _lock = lock_key(root, hash)?;
    if entry_is_whole(&dir) {
        return Ok((exe, true));
    }
    // Missing or corrupt (an interrupted copy, a truncated executable): built again.
    let _ = std::fs::remove_dir_all(&dir);
    let tmp = root.join(pid_tagged(hash, &next_build_id().to_string()));
    let _ = std::fs::remove_dir_all(&tmp);
    // Builds of killed runs (a dead PID in the name) are never finished: remove them.
    tofprobe_io::stale::remove_stale(root, temporary_pid);
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
    build(&tmp)?;
    let built = tmp.join("harness");
    let bytes = std::fs::read(&built).map_err(|e| CosimError::io(&built, e))?;
    let sum = tmp.join(CHECKSUM);
    std::fs::write(&sum, checksum(&bytes)).map_err(|e| CosimError::io(&sum, e))?;
    std::fs::rename(&tmp, &dir).map_err(|e| CosimError::io(&dir, e))?;
    Ok((exe, false))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// The cache's mechanics with a stand-in build (no Verilator): one build for four
    /// threads that want the same key at once; a truncated executable or a missing
    /// checksum is built again; a failed build leaves no entry and the next call builds.
    #[test]
    fn one_build_per_key_and_a_corrupt_entry_is_rebuilt() {
        let root = std::env::temp_dir().join(format!("tofprobe-vcache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let builds = AtomicUsize::new(0);
        let build = |tmp: &Path| {
            builds.fetch_add(1, Ordering::SeqCst);
            std::thread::sleep(std::time::Duration::from_millis(50));
            std::fs::write(tmp.join("harness"), b"an executable")
                .map_err(|e| CosimError::io(tmp, e))
        };
        let reused: Vec<bool> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| s.spawn(|| cached_entry(&root, "k", build).unwrap().1))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(builds.load(Ordering::SeqCst), 1);
        assert_eq!(reused.iter().filter(|r| !**r).count(), 1, "{reused:?}");

        let exe = root.join("k").join("harness");
        std::fs::write(&exe, b"an exec").unwrap();
        assert_eq!(
            cached_entry(&root, "k", build).unwrap(),
            (exe.clone(), false)
        );
        assert_eq!(std::fs::read(&exe).unwrap(), b"an executable");
        std::fs::remove_file(root.join("k").join(CHECKSUM)).unwrap();
        assert!(!cached_entry(&root, "k", build).unwrap().1);
        assert!(cached_entry(&root, "k", build).unwrap().1);
        assert_eq!(builds.load(Ordering::SeqCst), 3);

        let failing = |_: &Path| -> Result<(), CosimError> {
            Err(CosimError::ToolFailed {
                tool: "verilator",
                status: "1".into(),
                output: String::new(),
            })
        };
        assert!(cached_entry(&root, "j", failing).is_err());
        assert!(!root.join("j").exists());
        assert!(!cached_entry(&root, "j", build).unwrap().1);
        let _ = std::fs::remove_dir_all(&root);
    }

    /// The run-time library objects shared between builds ([`crate::runtime`]): a first
    /// build compiles and publishes them, a build of another design with the same flags
    /// links them from the cache, and its executable is byte-identical to the one of a
    /// build that compiled them itself (a fresh root). (That other flags key another entry
    /// is `runtime::tests::the_key_ignores_the_build_directory_but_not_the_flags`.)
    #[test]
    fn library_objects_are_shared_and_change_no_byte() {
        if !tofprobe_testkit::tools::have(&["verilator", "make"], "library_objects_are_shared") {
            return;
        }
        let verilator = tofprobe_testkit::tools::find("verilator").unwrap();
        let base = std::env::temp_dir().join(format!("tofprobe-vrt-build-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        let src = base.join("src");
        std::fs::create_dir_all(&src).unwrap();
        let design = |n: u32| {
            let v = src.join(format!("top{n}.v"));
            std::fs::write(
                &v,
                format!(
                    "module top(input wire clk, output reg [7:0] q);\n\
                     initial q = 0;\n\
                     always @(posedge clk) q <= q + 8'd{n};\nendmodule\n"
                ),
            )
            .unwrap();
            v
        };
        let cpp = src.join("main.cpp");
        std::fs::write(
            &cpp,
            "#include \"Vtop.h\"\n#include \"verilated.h\"\n\
             int main(int argc, char** argv) { VerilatedContext c; c.commandArgs(argc, argv);\n\
             Vtop t(&c); for (int i = 0; i < 6; i++) { t.clk = !t.clk; t.eval(); }\n\
             return t.q > 0 && t.q % 5 == 0 ? 0 : 1; }\n",
        )
        .unwrap();
        let build = |root: &Path, name: &str, v: &Path, extra: &[&str]| {
            let tmp = root.join(name);
            std::fs::create_dir_all(&tmp).unwrap();
            let reused = verilate(
                &verilator,
                &tmp,
                "top",
                BuildProfile::Check,
                "",
                extra,
                &[v.to_path_buf()],
                &cpp,
            )
            .expect("builds");
            (std::fs::read(tmp.join("harness")).unwrap(), reused)
        };
        let (root_a, root_b) = (base.join("a"), base.join("b"));
        let (_, reused) = build(&root_a, "first", &design(1), &[]);
        assert!(!reused, "an empty cache has no objects to lend");
        let five = design(5);
        let (shared, reused) = build(&root_a, "second", &five, &[]);
        assert!(
            reused,
            "another design with the same flags links the shared objects"
        );
        let (fresh, reused) = build(&root_b, "fresh", &five, &[]);
        assert!(!reused);
        assert!(shared == fresh, "shared objects changed the executable");
        let ran = Command::new(root_a.join("second").join("harness"))
            .status()
            .unwrap();
        assert!(
            ran.success(),
            "the linked harness runs: q a positive multiple of 5"
        );
        let _ = std::fs::remove_dir_all(&base);
    }
}
