//! Locating the external EDA tools (yosys, OpenSTA) and reporting how to get them.

use crate::error::{EdaError, Result};
use std::path::{Path, PathBuf};

/// An external program the report drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// Yosys, for synthesis and area.
    Yosys,
    /// OpenSTA (`sta`), for timing.
    Sta,
}

impl Tool {
    fn binary(self) -> &'static str {
        match self {
            Tool::Yosys => "yosys",
            Tool::Sta => "sta",
        }
    }

    fn env(self) -> &'static str {
        match self {
            Tool::Yosys => "TOFPROBE_YOSYS",
            Tool::Sta => "TOFPROBE_STA",
        }
    }

    fn install(self) -> &'static str {
        match self {
            Tool::Yosys => "apt-get install yosys, or scripts/install-tools.sh",
            Tool::Sta => "apt-get install opensta, or scripts/install-tools.sh",
        }
    }

    /// The tool's path: `$TOFPROBE_YOSYS` / `$TOFPROBE_STA` when set, else a PATH search.
    pub fn locate(self) -> Result<PathBuf> {
        let missing = EdaError::ToolMissing {
            tool: self.binary(),
            env: self.env(),
            install: self.install(),
        };
        if let Some(p) = std::env::var_os(self.env()) {
            let p = PathBuf::from(p);
            return if is_executable(&p) {
                Ok(p)
            } else {
                Err(missing)
            };
        }
        search_path(self.binary()).ok_or(missing)
    }
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    p.metadata()
        .map(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        .unwrap_or(false)
}

fn search_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| is_executable(p))
}

/// The last `n` lines of a log, for error messages.
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_tool_names_the_package() {
        let err = EdaError::ToolMissing {
            tool: Tool::Sta.binary(),
            env: Tool::Sta.env(),
            install: Tool::Sta.install(),
        };
        let msg = err.to_string();
        assert!(msg.contains("`sta`") && msg.contains("opensta") && msg.contains("TOFPROBE_STA"));
        assert!(search_path("surely-not-a-tool-tofprobe").is_none());
    }

    #[test]
    fn tail_keeps_last_lines() {
        assert_eq!(tail("a\nb\nc\nd", 2), "c\nd");
        assert_eq!(tail("a", 5), "a");
    }
}
