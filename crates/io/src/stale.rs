//! Temporaries of killed runs. SIGINT/SIGTERM remove them at once (the binary's handler and
//! [`crate::live`]), but no handler runs on SIGKILL, so every temporary this workspace
//! creates carries the creating process id in its name, and the next run that writes beside
//! it removes those whose process is gone.

use std::path::Path;

/// The marker between a temporary's base name and the process id that created it.
pub const PID_MARK: &str = ".tofprobe-";

/// Whether process `pid` is running. Linux: `/proc/PID` exists. Without `/proc` nothing is
/// known, and a temporary is kept (assumed alive) rather than removed under a live writer.
pub fn pid_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return true;
    }
    proc.join(pid.to_string()).exists()
}

/// A hidden temporary name for `base` carrying this process's id, `.BASE.tofprobe-PID.TAG`:
/// the one spelling every writer uses, which [`temporary_pid`] reads back, so
/// `remove_stale(dir, temporary_pid)` can never mistake another field for the id.
pub fn pid_tagged(base: &str, tag: &str) -> String {
    format!(".{base}{PID_MARK}{}.{tag}", std::process::id())
}

/// The process id in a temporary's name `….tofprobe-PID.…` (hidden names only), if any.
pub fn temporary_pid(name: &str) -> Option<u32> {
    if !name.starts_with('.') {
        return None;
    }
    let at = name.rfind(PID_MARK)? + PID_MARK.len();
    let digits: String = name[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

/// Removes the entries of `dir` (files or directories) whose name `pid_of` maps to a process
/// id that is no longer running; returns how many were removed. Errors reading `dir` or
/// removing an entry are ignored: cleaning is a courtesy, never a reason to fail a run.
pub fn remove_stale(dir: &Path, pid_of: impl Fn(&str) -> Option<u32>) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = pid_of(&name.to_string_lossy()) else {
            continue;
        };
        if pid_alive(pid) {
            continue;
        }
        let p = e.path();
        let ok = if e.file_type().is_ok_and(|t| t.is_dir()) {
            std::fs::remove_dir_all(&p).is_ok()
        } else {
            std::fs::remove_file(&p).is_ok()
        };
        removed += usize::from(ok);
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pid_is_read_from_hidden_temporaries_only() {
        assert_eq!(temporary_pid(".x.v.tofprobe-123.ab12.tmp"), Some(123));
        assert_eq!(temporary_pid(".tofprobe-stage-7"), None);
        assert_eq!(temporary_pid("x.tofprobe-123.tmp"), None);
        assert_eq!(temporary_pid(".x.tmp"), None);
    }

    /// The writer's spelling round-trips through the parser, whatever the tag: the
    /// Verilator cache once wrote `.HASH.PID.N` and parsed N (a build counter) as the PID,
    /// deleting live builds of the same process.
    #[test]
    fn pid_tagged_names_parse_back_to_this_process() {
        for tag in ["0", "17", "tmp", "3.v"] {
            let n = pid_tagged("0123456789abcdef", tag);
            assert_eq!(temporary_pid(&n), Some(std::process::id()), "{n}");
        }
    }

    #[test]
    fn dead_process_temporaries_go_live_ones_stay() {
        let dir = tempfile::tempdir().unwrap();
        // Pid 4194304 is above Linux's pid_max limit (2^22): never a live process.
        let dead = ".a.v.tofprobe-4194304.x.tmp";
        let live = format!(".a.v.tofprobe-{}.x.tmp", std::process::id());
        for n in [dead, live.as_str(), "keep.v"] {
            std::fs::write(dir.path().join(n), b"t").unwrap();
        }
        let removed = remove_stale(dir.path(), temporary_pid);
        let mut left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        left.sort();
        if Path::new("/proc/self").exists() {
            assert_eq!(removed, 1);
            assert_eq!(left, vec![live, "keep.v".to_string()]);
        }
    }
}
