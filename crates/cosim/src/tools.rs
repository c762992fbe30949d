//! Finding the EDA tools through the workspace's one locator (`tofprobe_io::tools::locate`:
//! `$TOFPROBE_VERILATOR`, `$TOFPROBE_IVERILOG`, … when set, else PATH): a missing one is
//! named, with its variable and the script that installs it; a tool's `--version`, asked
//! once per process.

use crate::error::CosimError;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The path of `tool` (its `TOFPROBE_*` variable, else PATH), or the error that names the
/// variable and says to run scripts/install-tools.sh.
pub fn require(tool: &str) -> Result<PathBuf, CosimError> {
    tofprobe_io::tools::locate(tool).map_err(CosimError::MissingTool)
}

/// True when every tool is installed.
pub fn available(tools: &[&'static str]) -> bool {
    tools.iter().all(|t| require(t).is_ok())
}

/// `verilator --version`'s output, run once per executable path in a process (every
/// Verilator build's key and its run-time library's key hold it).
pub(crate) fn version(verilator: &Path) -> Result<Vec<u8>, CosimError> {
    type Seen = std::sync::Mutex<Vec<(PathBuf, Vec<u8>)>>;
    static SEEN: std::sync::OnceLock<Seen> = std::sync::OnceLock::new();
    let seen = SEEN.get_or_init(Default::default);
    if let Some((_, v)) = seen
        .lock()
        .ok()
        .and_then(|s| s.iter().find(|(p, _)| p == verilator).cloned())
    {
        return Ok(v);
    }
    let out = Command::new(verilator)
        .arg("--version")
        .output()
        .map_err(|e| CosimError::io(verilator, e))?;
    if let Ok(mut s) = seen.lock() {
        s.push((verilator.to_path_buf(), out.stdout.clone()));
    }
    Ok(out.stdout)
}
