//! The one tool locator: every external program the workspace runs (yosys, OpenSTA,
//! Verilator, Icarus, qflow, magic, netgen, klayout, make, …) is found by [`locate`]:
//! the variable `TOFPROBE_<NAME>` ([`override_var`]: the program's name upper-cased, every
//! other character than a letter or a digit as `_`: `TOFPROBE_STA`, `TOFPROBE_YOSYS`,
//! `TOFPROBE_NETGEN_LVS`) when it is set, else the first executable of that name on `PATH`.
//! A set variable is final: when it names no executable file, that is the error (naming the
//! variable and its value), never a silent fall back to `PATH`. Each crate that runs a
//! tool maps [`ToolNotFound`] into its own error with how to install the tool.

use std::ffi::OsString;
use std::fmt;
use std::path::{Path, PathBuf};

/// The variable that overrides the `PATH` search for `tool`: `TOFPROBE_` and the name
/// upper-cased, every character but an ASCII letter or digit as `_`.
pub fn override_var(tool: &str) -> String {
    let name: String = tool
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("TOFPROBE_{name}")
}

/// A tool that [`locate`] did not find.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ToolNotFound {
    /// The program's name (`sta`).
    pub tool: String,
    /// Its override variable (`TOFPROBE_STA`).
    pub var: String,
    /// The variable's value when it was set (and names no executable file).
    pub set_to: Option<PathBuf>,
}

impl fmt::Display for ToolNotFound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.set_to {
            Some(p) => write!(
                f,
                "`{}`: ${} = {} is not an executable file (unset it to search PATH, or point \
                 it at the program)",
                self.tool,
                self.var,
                p.display()
            ),
            None => write!(
                f,
                "`{}` was not found on PATH (nor via ${}: set it to the program's path)",
                self.tool, self.var
            ),
        }
    }
}

impl std::error::Error for ToolNotFound {}

/// The path of `tool`: `$TOFPROBE_<NAME>` when set, else a `PATH` search.
pub fn locate(tool: &str) -> Result<PathBuf, ToolNotFound> {
    locate_in(tool, |v| std::env::var_os(v))
}

/// [`locate`] reading the environment through `env` (a test's, without touching the
/// process's).
pub fn locate_in(
    tool: &str,
    env: impl Fn(&str) -> Option<OsString>,
) -> Result<PathBuf, ToolNotFound> {
    let var = override_var(tool);
    let missing = |set_to| ToolNotFound {
        tool: tool.to_string(),
        var: var.clone(),
        set_to,
    };
    if let Some(p) = env(&var).filter(|v| !v.is_empty()) {
        let p = PathBuf::from(p);
        return if is_executable(&p) {
            Ok(p)
        } else {
            Err(missing(Some(p)))
        };
    }
    let path = env("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|d| d.join(tool))
        .find(|p| is_executable(p))
        .ok_or_else(|| missing(None))
}

/// A regular file (or a link to one) with an execute bit.
pub fn is_executable(p: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        p.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    }
    #[cfg(not(unix))]
    {
        p.is_file()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An environment of `vars` alone.
    fn env(vars: &[(&str, &Path)]) -> impl Fn(&str) -> Option<OsString> + use<> {
        let vars: Vec<(String, OsString)> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.as_os_str().to_owned()))
            .collect();
        move |k| vars.iter().find(|(n, _)| n == k).map(|(_, v)| v.clone())
    }

    #[test]
    fn the_override_wins_over_path_and_a_bad_one_is_named() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let bin = dir.path().join("bin");
        std::fs::create_dir(&bin).unwrap();
        let on_path = bin.join("sta");
        let mine = dir.path().join("my-sta");
        for p in [&on_path, &mine] {
            std::fs::write(p, "#!/bin/sh\n").unwrap();
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        assert_eq!(override_var("sta"), "TOFPROBE_STA");
        assert_eq!(override_var("netgen-lvs"), "TOFPROBE_NETGEN_LVS");
        // PATH alone: the executable there.
        assert_eq!(
            locate_in("sta", env(&[("PATH", &bin)])),
            Ok(on_path.clone())
        );
        // The variable wins over PATH.
        let both = env(&[("PATH", &bin), ("TOFPROBE_STA", &mine)]);
        assert_eq!(locate_in("sta", both), Ok(mine.clone()));
        // A variable naming nothing executable is the error, not a fall back to PATH.
        let text = dir.path().join("not-executable");
        std::fs::write(&text, "x").unwrap();
        for bad in [text.as_path(), Path::new("/no/such/sta")] {
            let e = locate_in("sta", env(&[("PATH", &bin), ("TOFPROBE_STA", bad)])).unwrap_err();
            assert_eq!(e.set_to.as_deref(), Some(bad));
            let m = e.to_string();
            assert!(
                m.contains("$TOFPROBE_STA") && m.contains(&bad.display().to_string()),
                "{m}"
            );
        }
        // Neither: the error names the variable that would have found it.
        let e = locate_in("yosys", env(&[("PATH", &bin)])).unwrap_err();
        assert_eq!(
            (e.var.as_str(), e.set_to.as_deref()),
            ("TOFPROBE_YOSYS", None)
        );
        assert!(e.to_string().contains("$TOFPROBE_YOSYS"), "{e}");
    }
}
