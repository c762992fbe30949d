//! The stage directory of an output set ([`crate::OutputSet`], protocol in `set.rs`): its
//! name (`DIR/.output-set.tofprobe-PID.stage`), its `COMMIT` list, and what a commit cut
//! short left there — read by the set, by the directory's lock and by the marker check.

use std::path::Path;

use crate::stale::PID_MARK;

/// Start of a stage directory's name; the pid and `.stage` follow.
pub const STAGE_PREFIX: &str = ".output-set";
pub(crate) const STAGE_SUFFIX: &str = ".stage";
pub(crate) const COMMIT: &str = "COMMIT";

/// The pid in a stage directory's name, `.output-set.tofprobe-PID.stage`.
pub(crate) fn stage_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(STAGE_PREFIX)?.strip_prefix(PID_MARK)?;
    rest.strip_suffix(STAGE_SUFFIX)?.parse().ok()
}

/// Prefix of a `COMMIT` line naming a file of the old set to remove (a staged name never
/// holds `/`, so no name reads as one).
pub(crate) const REMOVE: &str = "remove/";

/// What an interrupted commit in `target` left (the stage of a process that is gone, with
/// its `COMMIT` list): the pid, the files already moved into place, and those still staged
/// (the completion marker among them). `None` when no commit was cut short there.
pub(crate) fn interrupted_commit(target: &Path) -> Option<(u32, Vec<String>, Vec<String>)> {
    for e in std::fs::read_dir(target).ok()?.flatten() {
        let Some(pid) = stage_pid(&e.file_name().to_string_lossy()) else {
            continue;
        };
        let stage = e.path();
        let Ok(list) = crate::read_bounded_text(&stage.join(COMMIT), 1 << 20) else {
            continue;
        };
        let (mut moved, mut pending) = (Vec::new(), Vec::new());
        for name in list.lines().filter(|l| !l.starts_with(REMOVE)) {
            if stage.join(name).exists() {
                pending.push(name.to_string());
            } else {
                moved.push(name.to_string());
            }
        }
        return Some((pid, moved, pending));
    }
    None
}
