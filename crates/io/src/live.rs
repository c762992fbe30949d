//! The process-wide registry of live temporaries, so that an interrupted run (SIGINT,
//! SIGTERM) leaves none behind.
//!
//! Every temporary this workspace creates — [`crate::write_atomic`]'s temporary file, an
//! [`crate::OutputSet`]'s stage directory (and the target directory it created), a
//! Verilator build directory in progress — is created through [`create`], which registers
//! its path, and is deregistered when the returned [`Live`] guard is dropped (after the
//! temporary was committed or removed). The binary's signal handler calls
//! [`remove_all_and_exit`], which removes every registered path and exits.
//!
//! Races with the handler are closed by one lock: creation and registration happen under
//! it (a temporary created while the handler runs waits, and never exists), and so do the
//! steps that must not be cut in half — an output set's commit ([`critical`]) — so the
//! handler sees a set either staged (removed: the old set stays) or fully moved into place
//! (nothing left to remove). The handler exits while holding the lock, so no other thread
//! creates anything afterwards.
//!
//! Stale temporaries of runs killed by SIGKILL, when no handler runs, are still cleaned by
//! the next run ([`crate::stale`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// What the handler does with a registered path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A temporary file or directory: removed with everything in it.
    Temporary,
    /// A directory the run created for its output: removed only if empty.
    CreatedDir,
}

#[derive(Debug, Default)]
struct Registry {
    next: u64,
    live: BTreeMap<u64, (PathBuf, Kind)>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    live: BTreeMap::new(),
});

fn lock() -> MutexGuard<'static, Registry> {
    // A thread that panicked while holding the lock left the map consistent (every
    // operation on it is a single insert or remove): keep using it.
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

/// Registration of one live temporary: dropping it deregisters the path (it does not
/// remove it: the owner commits or removes the temporary itself).
#[derive(Debug)]
#[must_use = "dropping the guard deregisters the temporary at once"]
pub struct Live {
    id: u64,
}

impl Drop for Live {
    fn drop(&mut self) {
        lock().live.remove(&self.id);
    }
}

/// Creates a temporary with `make` and registers the path `path_of` gives for it, both
/// under the registry's lock (see the module header: the handler never misses it).
pub fn create<T>(
    kind: Kind,
    make: impl FnOnce() -> std::io::Result<T>,
    path_of: impl FnOnce(&T) -> PathBuf,
) -> std::io::Result<(T, Live)> {
    let mut reg = lock();
    let made = make()?;
    let id = reg.next;
    reg.next += 1;
    reg.live.insert(id, (path_of(&made), kind));
    Ok((made, Live { id }))
}

/// Registers an existing path (e.g. a directory made before the registry knew about it).
pub fn register(kind: Kind, path: &Path) -> Live {
    let mut reg = lock();
    let id = reg.next;
    reg.next += 1;
    reg.live.insert(id, (path.to_path_buf(), kind));
    Live { id }
}

/// Runs `f` with the handler held off: a signal during `f` is acted on after it. `f` must
/// not create, register or drop a [`Live`] (the lock is not reentrant).
pub fn critical<T>(f: impl FnOnce() -> T) -> T {
    let _reg = lock();
    f()
}

/// The registered paths, oldest first (for tests and diagnostics).
pub fn registered() -> Vec<(PathBuf, Kind)> {
    lock().live.values().cloned().collect()
}

/// Removes every registered path, newest first (a stage before the directory holding it),
/// and returns how many existed and were removed.
fn remove_all(reg: &mut Registry) -> usize {
    let mut removed = 0;
    for (path, kind) in reg.live.values().rev() {
        removed += usize::from(remove(path, *kind));
    }
    reg.live.clear();
    removed
}

fn remove(path: &Path, kind: Kind) -> bool {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return false;
    };
    match kind {
        Kind::CreatedDir => std::fs::remove_dir(path).is_ok(),
        Kind::Temporary if meta.is_dir() => {
            // A child process (a compiler of a Verilator build) may still add files while
            // the tree is removed: try again a few times.
            (0..5).any(|_| std::fs::remove_dir_all(path).is_ok() || !path.exists())
        }
        Kind::Temporary => std::fs::remove_file(path).is_ok(),
    }
}

/// Removes every registered temporary and exits the process with `code` (130 for an
/// interrupt, the shell's 128 + SIGINT). For a signal handler: never returns.
pub fn remove_all_and_exit(code: i32) -> ! {
    let mut reg = lock();
    remove_all(&mut reg);
    // The lock stays held through exit: no thread creates a temporary from here on.
    let _held = reg;
    std::process::exit(code)
}

/// Removes the registered temporaries under `root` (without exiting) and forgets them;
/// returns how many were removed. For tests, which share the process with other tests'
/// temporaries.
pub fn remove_under(root: &Path) -> usize {
    let mut reg = lock();
    let ours: Vec<u64> = reg
        .live
        .iter()
        .filter(|(_, (p, _))| p.starts_with(root))
        .map(|(id, _)| *id)
        .collect();
    let mut removed = 0;
    for id in ours.into_iter().rev() {
        if let Some((p, kind)) = reg.live.remove(&id) {
            removed += usize::from(remove(&p, kind));
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registered_temporaries_are_removed_and_dropped_guards_forgotten() {
        let dir = tempfile::tempdir().unwrap();
        let kept = dir.path().join("kept.tmp");
        let gone = dir.path().join("gone.tmp");
        let made = dir.path().join("made");
        let stage = made.join(".stage");
        let (_, g_kept) = create(
            Kind::Temporary,
            || std::fs::write(&kept, b"k"),
            |_| kept.clone(),
        )
        .unwrap();
        let (_, _g_gone) = create(
            Kind::Temporary,
            || std::fs::write(&gone, b"g"),
            |_| gone.clone(),
        )
        .unwrap();
        std::fs::create_dir(&made).unwrap();
        let _g_made = register(Kind::CreatedDir, &made);
        let (_, _g_stage) = create(
            Kind::Temporary,
            || std::fs::create_dir(&stage),
            |_| stage.clone(),
        )
        .unwrap();
        std::fs::write(stage.join("a.hex"), b"a").unwrap();
        drop(g_kept);
        // Other tests of this process may register temporaries of their own at the same
        // time; only ours are looked at.
        let ours: Vec<_> = registered()
            .into_iter()
            .filter(|(p, _)| p.starts_with(dir.path()))
            .collect();
        assert_eq!(ours.len(), 3, "{ours:?}");
        assert_eq!(remove_under(dir.path()), 3);
        assert!(kept.exists(), "a deregistered temporary is not touched");
        assert!(!gone.exists() && !stage.exists() && !made.exists());
        assert!(registered().iter().all(|(p, _)| !p.starts_with(dir.path())));
    }

    #[test]
    fn a_created_directory_with_files_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("old.hex"), b"o").unwrap();
        assert!(!remove(dir.path(), Kind::CreatedDir));
        assert!(dir.path().join("old.hex").exists());
    }
}
