//! The programs of the layout flow and the Debian packages that provide them, found by the
//! workspace's one locator (`tofprobe_io::tools::locate`: `$TOFPROBE_<NAME>` when set —
//! `TOFPROBE_STA`, `TOFPROBE_QFLOW`, `TOFPROBE_NETGEN_LVS`, … —, else PATH).

use std::path::PathBuf;

use crate::error::{LayoutError, Result};

/// An external program of the layout flow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// qflow's driver scripts (placement with graywolf, routing with qrouter, magic, netgen).
    Qflow,
    /// graywolf, the placer.
    Graywolf,
    /// qrouter, the detailed router.
    Qrouter,
    /// magic: DEF to layout, DRC, extraction, GDS.
    Magic,
    /// netgen: LVS.
    Netgen,
    /// OpenSTA: post-route timing.
    Sta,
    /// klayout: the picture.
    Klayout,
}

impl Tool {
    /// Every tool, in the order the flow needs them.
    pub const ALL: [Tool; 7] = [
        Tool::Qflow,
        Tool::Graywolf,
        Tool::Qrouter,
        Tool::Magic,
        Tool::Netgen,
        Tool::Sta,
        Tool::Klayout,
    ];

    /// The executable looked up on PATH.
    pub fn binary(self) -> &'static str {
        match self {
            Tool::Qflow => "qflow",
            Tool::Graywolf => "graywolf",
            Tool::Qrouter => "qrouter",
            Tool::Magic => "magic",
            Tool::Netgen => "netgen-lvs",
            Tool::Sta => "sta",
            Tool::Klayout => "klayout",
        }
    }

    /// The Debian package that provides it.
    pub fn package(self) -> &'static str {
        match self {
            Tool::Qflow => "qflow",
            Tool::Graywolf => "graywolf",
            Tool::Qrouter => "qrouter",
            Tool::Magic => "magic",
            Tool::Netgen => "netgen-lvs",
            Tool::Sta => "opensta",
            Tool::Klayout => "klayout",
        }
    }

    /// The program's path (its `TOFPROBE_*` variable, else PATH), or an error naming the
    /// variable and its package.
    pub fn locate(self) -> Result<PathBuf> {
        tofprobe_io::tools::locate(self.binary()).map_err(|found| LayoutError::ToolMissing {
            found,
            package: self.package(),
        })
    }
}

/// Every tool present, or the first missing one named with its package.
pub fn require_all() -> Result<()> {
    Tool::ALL.iter().try_for_each(|t| t.locate().map(|_| ()))
}

/// The last `n` lines of a text.
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_tool_names_its_debian_package() {
        let found = tofprobe_io::tools::locate_in(Tool::Netgen.binary(), |_| None).unwrap_err();
        let e = LayoutError::ToolMissing {
            found,
            package: Tool::Netgen.package(),
        }
        .to_string();
        assert!(
            e.contains("`netgen-lvs`")
                && e.contains("$TOFPROBE_NETGEN_LVS")
                && e.contains("Debian's `netgen-lvs`"),
            "{e}"
        );
        assert_eq!(Tool::Sta.package(), "opensta");
        assert_eq!(tail("a\nb\nc", 2), "b\nc");
    }
}
