//! One writer per output directory: [`lock_dir`] takes an exclusive advisory lock
//! (`flock`) on the directory itself, held by an [`crate::OutputSet`] from its start to its
//! commit (or drop), so two runs writing into one `--out` cannot interleave their commits
//! (one run's `summary.json` beside the other's arrays). The second writer is refused at
//! once, naming the process that holds the directory (the pid in its stage's name,
//! `.output-set.tofprobe-PID.stage`), rather than waiting for a run that may take hours.
//! The kernel releases the lock when the holder exits, however it dies, so a killed run
//! never leaves the directory locked; no lock file is left behind either.

use std::fs::{File, TryLockError};
use std::io::{Error, ErrorKind};
use std::path::Path;

/// An exclusive lock on a directory, released when dropped (or when the process dies).
#[derive(Debug)]
pub struct DirLock {
    _file: File,
}

/// The live process, other than this one, whose stage directory is in `dir` (the holder
/// of its lock), if any.
fn holder(dir: &Path) -> Option<u32> {
    let me = std::process::id();
    std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .filter_map(|e| crate::stage::stage_pid(&e.file_name().to_string_lossy()))
        .find(|&pid| pid != me && crate::stale::pid_alive(pid))
}

/// Takes the exclusive lock of directory `dir` (which must exist); refuses, naming the
/// holder, when another writer has it.
pub fn lock_dir(dir: &Path) -> std::io::Result<DirLock> {
    let file = File::open(dir)?;
    match file.try_lock() {
        Ok(()) => Ok(DirLock { _file: file }),
        Err(TryLockError::WouldBlock) => {
            let who = match holder(dir) {
                Some(pid) => format!("tofprobe process {pid}"),
                None => "another tofprobe run".to_string(),
            };
            Err(Error::new(
                ErrorKind::ResourceBusy,
                format!(
                    "{} is being written by {who}: two runs into one output directory would \
                     mix their files, so this one is refused and nothing of it is written; \
                     wait for that run to finish, or write into another directory",
                    dir.display()
                ),
            ))
        }
        Err(TryLockError::Error(e)) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_until_the_first_lets_go() {
        let dir = tempfile::tempdir().unwrap();
        let first = lock_dir(dir.path()).unwrap();
        // A second open of the directory (as another process would) is refused.
        let e = lock_dir(dir.path()).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::ResourceBusy);
        assert!(e.to_string().contains("is being written by"), "{e}");
        drop(first);
        lock_dir(dir.path()).expect("free again once the first is dropped");
    }
}
