//! Runs the plain-Verilog self-checking testbench (testbench/tb.v) under Icarus Verilog.

use crate::error::CosimError;
use crate::harness::{RunOutcome, parse_output};
use crate::tools::require;
use std::path::Path;
use std::process::Command;

/// The testbench source, embedded so the binary works outside the source tree.
pub const TB_V: &str = include_str!("../../../testbench/tb.v");

/// Compiles `tb.v` with the RTL of `rtl_dir` and the vectors of `vec_dir` (which holds
/// `tb_params.vh`), runs it from `rtl_dir`, and parses its completion line.
pub fn run(
    rtl_dir: &Path,
    vec_dir: &Path,
    top: &str,
    work: &Path,
) -> Result<RunOutcome, CosimError> {
    let iverilog = require("iverilog")?;
    let vvp = require("vvp")?;
    std::fs::create_dir_all(work).map_err(|e| CosimError::io(work, e))?;
    let tb = work.join("tb.v");
    std::fs::write(&tb, TB_V).map_err(|e| CosimError::io(&tb, e))?;
    let mut sources: Vec<_> = std::fs::read_dir(rtl_dir)
        .map_err(|e| CosimError::io(rtl_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .collect();
    sources.sort();
    let exe = work.join("tb.vvp");
    let out = Command::new(&iverilog)
        .args(["-g2005", "-o"])
        .arg(&exe)
        .arg(format!("-I{}", vec_dir.display()))
        .arg(format!("-DTB_TOP={top}"))
        .arg(format!("-DTB_VECTORS=\"{}/\"", vec_dir.display()))
        .arg(&tb)
        .args(&sources)
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
    parse_output(
        "icarus testbench",
        &format!(
            "{}{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        ),
    )
}
