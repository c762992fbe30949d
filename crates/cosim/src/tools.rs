//! Finding the EDA tools: a missing one is named, with the script that installs it.

use crate::error::CosimError;
use std::path::PathBuf;

/// The path of `tool` on PATH, or the error that says to run scripts/install-tools.sh.
pub fn require(tool: &'static str) -> Result<PathBuf, CosimError> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|d| d.join(tool))
        .find(|p| p.is_file())
        .ok_or(CosimError::MissingTool { tool })
}

/// True when every tool is installed.
pub fn available(tools: &[&'static str]) -> bool {
    tools.iter().all(|t| require(t).is_ok())
}
