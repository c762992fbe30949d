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

/// The executable `name` as the libraries find it (`tofprobe_io::tools::locate`: its
/// `TOFPROBE_*` variable, else `PATH`), if any: a test is gated on the tool its library
/// would run.
pub fn find(name: &str) -> Option<PathBuf> {
    tofprobe_io::tools::locate(name).ok()
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
        (!present).then(|| match t.contains('/') {
            true => format!("{t} not installed (scripts/install-tools.sh)"),
            false => format!(
                "{t} not installed (scripts/install-tools.sh), nor set by ${}",
                tofprobe_io::tools::override_var(t)
            ),
        })
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

/// The variable that marks a child of [`run_in_child`].
const CHILD: &str = "TOFPROBE_TEST_CHILD";

/// Whether this test runs as the child of [`run_in_child`] (its variables set).
pub fn in_child() -> bool {
    std::env::var_os(CHILD).is_some()
}

/// Runs the test `name` (its full path, `tools::the_test`) of this test binary again,
/// alone, in a child process with `vars` set: a test that needs the environment changed (a
/// tool's `TOFPROBE_*` override) without the binary's other tests, on other threads,
/// seeing it. The test does its work when [`in_child`] and returns at once otherwise. Panics
/// unless the child ran that one test and it passed (a misspelt `name` runs none).
pub fn run_in_child(name: &str, vars: &[(&str, &std::ffi::OsStr)]) {
    let exe = std::env::current_exe().expect("the test binary's path");
    let mut cmd = std::process::Command::new(exe);
    cmd.args([name, "--exact", "--nocapture", "--test-threads", "1"])
        .env(CHILD, "1");
    for (k, v) in vars {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("the test binary runs again");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("test result: ok. 1 passed"),
        "{name} in a child with {vars:?}:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A shell script at `path` that stands for a tool: it records its arguments in
/// `path` + `.called` and exits 3 without output (the caller's parse of its report then
/// fails, after the call was recorded).
pub fn recording_tool(path: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let called = PathBuf::from(format!("{}.called", path.display()));
    std::fs::write(path, "#!/bin/sh\necho \"$@\" > \"$0.called\"\nexit 3\n").expect("writes");
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    called
}

/// A tool's override honoured, the parent's half: runs the test `name` in a child twice
/// ([`run_in_child`]), first with `var` naming a [`recording_tool`], then with `var` naming
/// no file ([`NO_SUCH_TOOL`]); returns the arguments the recording tool was called with
/// (panics if it was not called). The child calls the library that runs the tool and, in
/// the second run, checks the error names `var` and its value.
pub fn override_is_honoured(name: &str, var: &str) -> String {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let script = dir.path().join("recording-tool");
    let called = recording_tool(&script);
    run_in_child(name, &[(var, script.as_os_str())]);
    let args = std::fs::read_to_string(&called)
        .unwrap_or_else(|e| panic!("{name}: ${var} was not run ({e})"));
    run_in_child(name, &[(var, NO_SUCH_TOOL.as_ref())]);
    args
}

/// The path [`override_is_honoured`] sets a tool's variable to in its second run.
pub const NO_SUCH_TOOL: &str = "/no/such/tool";

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
