//! The external EDA tools the report drives (yosys, OpenSTA), found by the workspace's one
//! locator (`tofprobe_io::tools::locate`: `$TOFPROBE_YOSYS` / `$TOFPROBE_STA` when set,
//! else PATH), and how to get them.

use crate::error::{EdaError, Result};
use std::path::PathBuf;

/// An external program the report drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// Yosys, for synthesis and area.
    Yosys,
    /// OpenSTA (`sta`), for timing.
    Sta,
}

impl Tool {
    /// The executable's name.
    pub fn binary(self) -> &'static str {
        match self {
            Tool::Yosys => "yosys",
            Tool::Sta => "sta",
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
        tofprobe_io::tools::locate(self.binary()).map_err(|found| EdaError::ToolMissing {
            found,
            install: self.install(),
        })
    }
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
    fn missing_tool_names_the_package_and_the_variable() {
        let found =
            tofprobe_io::tools::locate_in("sta", |v| (v == "PATH").then(|| "/nonexistent".into()))
                .unwrap_err();
        let err = EdaError::ToolMissing {
            found,
            install: Tool::Sta.install(),
        };
        let msg = err.to_string();
        assert!(msg.contains("`sta`") && msg.contains("opensta") && msg.contains("TOFPROBE_STA"));
    }

    #[test]
    fn tail_keeps_last_lines() {
        assert_eq!(tail("a\nb\nc\nd", 2), "c\nd");
        assert_eq!(tail("a", 5), "a");
    }
}
