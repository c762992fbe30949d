//! The tool gate of the EDA tests. A test that drives Verilator, Icarus, yosys or OpenSTA
//! asks [`have`] first: on a developer's machine without the tool it prints a loud
//! `SKIPPED` line and the test returns; under CI (`CI` set to anything but `false`/`0`, or
//! `TOFPROBE_REQUIRE_TOOLS=1`, which `scripts/test.sh` sets) a missing tool fails the test,
//! so a suite cannot pass by skipping.

use std::path::{Path, PathBuf};

/// Whether a missing tool must fail the test (CI) rather than skip it.
pub fn required() -> bool {
    let set = |name: &str| {
        std::env::var(name)
            .ok()
            .is_some_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
    };
    set("CI") || set("TOFPROBE_REQUIRE_TOOLS")
}

/// The executable `name` on `PATH` (a regular file with an execute bit), if any.
pub fn find(name: &str) -> Option<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| {
            std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        })
}

/// The first of `tools` that is missing, naming what provides it: an executable on
/// `PATH`, or (for a path) a file that exists.
pub fn missing(tools: &[&str]) -> Option<String> {
    tools.iter().find_map(|t| {
        let present = if t.contains('/') {
            Path::new(t).exists()
        } else {
            find(t).is_some()
        };
        (!present).then(|| format!("{t} not installed (scripts/install-tools.sh)"))
    })
}

/// True when every tool of `tools` is present. Otherwise: under CI ([`required`]) a panic
/// naming the tool and `test`; elsewhere a loud `*** SKIPPED` line and false.
pub fn have(tools: &[&str], test: &str) -> bool {
    match missing(tools) {
        None => true,
        Some(why) if required() => {
            panic!("{test}: {why}, and CI/TOFPROBE_REQUIRE_TOOLS requires every EDA tool")
        }
        Some(why) => {
            eprintln!("\n*** SKIPPED {test}: {why} ***\n");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_present_tool_is_found_and_a_missing_one_is_named() {
        assert!(missing(&["sh"]).is_none());
        let m = missing(&["sh", "no-such-tool-tofprobe"]).expect("missing");
        assert!(m.contains("no-such-tool-tofprobe"), "{m}");
        assert!(missing(&["/no/such/liberty.lib"]).is_some());
    }
}
