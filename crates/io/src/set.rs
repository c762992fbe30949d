//! A command's set of output files, whole or absent: [`OutputSet`].
//!
//! Protocol (readers and the next run can check it):
//! 1. every file is written into a hidden stage directory inside the target,
//!    `DIR/.output-set.tofprobe-PID.stage/`, and flushed to disk;
//! 2. a `COMMIT` list (the names, in order, the completion file last) is written there:
//!    from now on the new set is whole on disk;
//! 3. the target's completion file (e.g. `manifest.toml`) is removed, then the files of the
//!    old set that the new one does not write (those the old completion marker lists with
//!    the hash they still have: never a file the old set did not write,
//!    [`crate::marker`]), then each staged file is renamed into place, the completion file
//!    last, and the stage directory is removed.
//!
//! A run killed before step 2 leaves the old set untouched and a stage directory that the
//! next run removes; killed during step 3, it leaves a set without its completion file
//! (readers refuse it) that the next [`recover`] (run by every [`OutputSet::begin`] on the
//! same directory) completes from the stage: the old set or the new set, whole.

use std::path::{Path, PathBuf};

use std::collections::BTreeMap;
use std::io::Write;
use std::time::SystemTime;

use crate::live::{self, Kind, Live};
use crate::lock::DirLock;
use crate::stage::{COMMIT, REMOVE, STAGE_PREFIX, STAGE_SUFFIX, stage_pid};
use crate::stale::{PID_MARK, pid_alive};

/// A protected file's length and modification time at the check (`None`: absent).
type Stamp = Option<(u64, SystemTime)>;

/// Files staged for one directory, moved into place together by [`OutputSet::commit`];
/// dropped uncommitted, it removes its stage (and the target directory if it created it
/// and it is still empty).
#[derive(Debug)]
pub struct OutputSet {
    target: PathBuf,
    stage: PathBuf,
    names: Vec<String>,
    /// FNV-1a-64 of each staged file, for the completion marker.
    hashes: std::collections::BTreeMap<String, u64>,
    created_target: bool,
    done: bool,
    /// The directory's writer lock ([`crate::lock`]), held until the set is committed or
    /// dropped.
    _lock: Option<DirLock>,
    /// Set by [`OutputSet::protect`]: the marker whose listed files alone may be replaced,
    /// and what each protected name was at the check (length and time, `None`: absent), so
    /// the commit checks again only what changed since.
    protected: Option<(String, BTreeMap<String, Stamp>)>,
    /// The stage (and the target if this run made it) in the registry of live
    /// temporaries, removed by an interrupt ([`crate::live`]).
    live: Vec<Live>,
}

impl OutputSet {
    /// Starts a set for directory `target` (created if missing): takes the directory's
    /// writer lock (a second writer is refused, naming the first: [`crate::lock`]), then
    /// [`recover`]s what killed runs left there, then creates this run's stage directory.
    pub fn begin(target: &Path) -> std::io::Result<OutputSet> {
        let created_target = !target.exists();
        let mut registered = Vec::new();
        if created_target {
            let ((), l) = live::create(
                Kind::CreatedDir,
                || std::fs::create_dir_all(target),
                |_| target.to_path_buf(),
            )?;
            registered.push(l);
        } else {
            std::fs::create_dir_all(target)?;
        }
        let dir_lock = match crate::lock::lock_dir(target) {
            Ok(l) => l,
            Err(e) => {
                if created_target {
                    let _ = std::fs::remove_dir(target);
                }
                return Err(e);
            }
        };
        recover(target)?;
        let stage = target.join(format!(
            "{STAGE_PREFIX}{PID_MARK}{}{STAGE_SUFFIX}",
            std::process::id()
        ));
        // A stage of this very process (an earlier set into the same directory that
        // failed) is ours to discard.
        let _ = std::fs::remove_dir_all(&stage);
        let mut set = OutputSet {
            target: target.to_path_buf(),
            stage: stage.clone(),
            names: Vec::new(),
            hashes: Default::default(),
            created_target,
            done: false,
            live: registered,
            _lock: Some(dir_lock),
            protected: None,
        };
        match live::create(
            Kind::Temporary,
            || std::fs::create_dir(&stage),
            |_| stage.clone(),
        ) {
            Ok(((), l)) => set.live.push(l),
            Err(e) => {
                set.done = true;
                set.remove_created_target();
                return Err(e);
            }
        }
        Ok(set)
    }

    /// The target directory.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Refuses to replace what this set does not own: each of `names` (the files the set
    /// will write) already in the target must be listed, unchanged, by the target's
    /// completion marker `marker` ([`crate::marker::check_replaceable`]); checked now,
    /// before the caller's work, and again at the commit for any name that appeared or
    /// changed meanwhile. For sets written into a directory the user names (`--out`).
    pub fn protect(&mut self, marker: &str, names: &[String]) -> std::io::Result<()> {
        let mut all = names.to_vec();
        if !all.iter().any(|n| n == marker) {
            all.push(marker.to_string());
        }
        crate::marker::check_replaceable(&self.target, marker, &all)?;
        let seen = all
            .into_iter()
            .map(|n| {
                let m = stamp(&self.target.join(&n));
                (n, m)
            })
            .collect();
        self.protected = Some((marker.to_string(), seen));
        Ok(())
    }

    /// Stages one file (a plain name, no directories).
    pub fn add(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()> {
        self.add_streamed(name, |w| w.write_all(contents))
            .map(|_| ())
    }

    /// Stages one file whose bytes `write` produces into a bounded buffer (64 KiB) that is
    /// flushed to the stage as it fills, hashed on the way: a file is never held whole in
    /// memory. Returns its length in bytes.
    pub fn add_streamed(
        &mut self,
        name: &str,
        write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> std::io::Result<u64> {
        if name.is_empty() || name.contains(['/', '\\']) || name.starts_with('.') {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("output file name `{name}` is not a plain visible file name"),
            ));
        }
        // Created with the interrupt handler held off: it never misses a file it must
        // remove with the stage.
        let f = live::critical(|| std::fs::File::create(self.stage.join(name)))?;
        let mut w = crate::HashingWriter::new(std::io::BufWriter::with_capacity(1 << 16, f));
        write(&mut w)?;
        let (buffered, hash, len) = w.finish();
        buffered
            .into_inner()
            .map_err(std::io::IntoInnerError::into_error)?
            .sync_all()?;
        self.names.retain(|n| n != name);
        self.names.push(name.to_string());
        self.hashes.insert(name.to_string(), hash);
        Ok(len)
    }

    /// FNV-1a-64 of the staged file `name` (the hash its marker will list), if staged.
    pub fn staged_hash(&self, name: &str) -> Option<u64> {
        self.hashes.get(name).copied()
    }

    /// Stages the completion marker `marker` (`preamble`, then the `[files]` table of every
    /// file staged so far with its hash, [`crate::marker::marker_text`]) and commits with
    /// it last: readers check the set with [`crate::check_set`]`(dir, marker)`.
    pub fn commit_marked(mut self, marker: &str, preamble: &str) -> std::io::Result<()> {
        self.hashes.remove(marker);
        self.names.retain(|n| n != marker);
        let text = crate::marker::marker_text(preamble, &self.hashes);
        self.add(marker, text.as_bytes())?;
        self.commit(Some(marker))
    }

    /// Moves the staged files into place, `last` (the set's completion file, e.g. its
    /// manifest; `None` for none) after all the others.
    pub fn commit(mut self, last: Option<&str>) -> std::io::Result<()> {
        if let Some((marker, seen)) = &self.protected {
            // Whatever appeared or changed in the target since `protect` is checked again.
            let again: Vec<String> = self
                .names
                .iter()
                .filter(|n| {
                    let now = stamp(&self.target.join(n));
                    now.is_some() && seen.get(n.as_str()).is_none_or(|was| *was != now)
                })
                .cloned()
                .collect();
            crate::marker::check_replaceable(&self.target, marker, &again)?;
        }
        let mut order: Vec<String> = self
            .names
            .iter()
            .filter(|n| Some(n.as_str()) != last)
            .cloned()
            .collect();
        if let Some(l) = last.filter(|l| self.names.iter().any(|n| n == l)) {
            order.push(l.to_string());
        }
        // The old set's files that the new one drops: only those its completion marker
        // lists and that still have the listed hash (a file changed since is not ours).
        let mut list = String::new();
        if let Some(l) = last {
            for name in dropped_files(&self.target, l, &self.names) {
                list.push_str(REMOVE);
                list.push_str(&name);
                list.push('\n');
            }
        }
        list.push_str(&(order.join("\n") + "\n"));
        let commit = self.stage.join(COMMIT);
        // An interrupt waits for the commit: it finds the set staged (and removes the
        // stage: the old set stays) or moved into place, never half moved.
        // If the COMMIT list cannot be written, `done` stays false and dropping the set
        // removes the stage.
        live::critical(|| {
            std::fs::write(&commit, &list)?;
            std::fs::File::open(&commit)?.sync_all()?;
            self.done = true;
            finish(&self.target, &self.stage, &list, kill_hook())
        })?;
        if let Ok(mut v) = COMMITTED.lock() {
            v.push(self.target.clone());
        }
        Ok(())
    }

    fn remove_created_target(&self) {
        if self.created_target {
            // Only if empty: `remove_dir` refuses a directory with anything in it.
            let _ = std::fs::remove_dir(&self.target);
        }
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_dir_all(&self.stage);
            self.remove_created_target();
        }
    }
}

/// A file's length and modification time (`None` when absent).
fn stamp(path: &Path) -> Stamp {
    let m = std::fs::symlink_metadata(path).ok()?;
    Some((m.len(), m.modified().unwrap_or(SystemTime::UNIX_EPOCH)))
}

/// The target directories of the sets this process committed, in order.
static COMMITTED: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// The directories of the sets this process committed so far (whole on disk), for a
/// command that fails afterwards to say which sets it left written: a full standard
/// output after the commit is an error (exit 2), the set stays whole.
pub fn committed_sets() -> Vec<PathBuf> {
    COMMITTED.lock().map(|v| v.clone()).unwrap_or_default()
}

/// The files of the set completed by `target/marker` that are not in `keep`, still as the
/// marker lists them (plain names whose bytes have the listed hash).
fn dropped_files(target: &Path, marker: &str, keep: &[String]) -> Vec<String> {
    let Ok(text) = crate::read_bounded_text(&target.join(marker), 1 << 20) else {
        return Vec::new();
    };
    let Some(files) = crate::marker::marker_files(&text) else {
        return Vec::new();
    };
    files
        .into_iter()
        .filter(|(name, hash)| {
            !keep.contains(name)
                && name.as_str() != marker
                && !name.is_empty()
                && !name.contains(['/', '\\'])
                && !name.starts_with('.')
                && crate::marker::hash_file(&target.join(name)).is_ok_and(|h| h == *hash)
        })
        .map(|(name, _)| name)
        .collect()
}

/// Tests only: `TOFPROBE_TEST_KILL_AFTER_RENAMES=k` aborts the process (no handler, no
/// destructor runs: a SIGKILL's effect) right after the k-th rename of a commit, so tests
/// through the binary can stop a commit at every point.
fn kill_hook() -> Option<usize> {
    std::env::var("TOFPROBE_TEST_KILL_AFTER_RENAMES")
        .ok()?
        .parse()
        .ok()
}

/// Step 3 of the protocol for a stage whose `COMMIT` list is `list`: files already moved
/// or removed are skipped, so this also completes an interrupted commit.
fn finish(
    target: &Path,
    stage: &Path,
    list: &str,
    kill_after: Option<usize>,
) -> std::io::Result<()> {
    let mut order: Vec<String> = Vec::new();
    let mut removals: Vec<&str> = Vec::new();
    for line in list.lines() {
        match line.strip_prefix(REMOVE) {
            Some(name) => removals.push(name),
            None => order.push(line.to_string()),
        }
    }
    let mut renamed = 0;
    if let Some(last) = order.last() {
        let staged_last = stage.join(last);
        if staged_last.exists() && order.len() > 1 {
            match std::fs::remove_file(target.join(last)) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
                _ => {}
            }
        }
    }
    for name in removals {
        match std::fs::remove_file(target.join(name)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    for name in &order {
        let from = stage.join(name);
        if from.exists() {
            std::fs::rename(&from, target.join(name))?;
            renamed += 1;
            if kill_after == Some(renamed) {
                std::process::abort();
            }
        }
    }
    std::fs::remove_dir_all(stage)
}

/// Cleans what killed runs left in `target`: a stage directory of a dead process is
/// completed (it has a `COMMIT` list: its set was whole) or removed (it has none: the old
/// set was never touched); stray temporaries of [`crate::write_atomic`] are removed.
/// Returns an error only when completing a committed stage fails.
pub fn recover(target: &Path) -> std::io::Result<()> {
    if let Ok(entries) = std::fs::read_dir(target) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(pid) = stage_pid(&name) else {
                continue;
            };
            if pid_alive(pid) {
                continue;
            }
            let stage = e.path();
            match std::fs::read_to_string(stage.join(COMMIT)) {
                Ok(list) => finish(target, &stage, &list, None)?,
                Err(_) => {
                    let _ = std::fs::remove_dir_all(&stage);
                }
            }
        }
    }
    crate::stale::remove_stale(target, crate::stale::temporary_pid);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_set_appears_whole_and_its_stage_vanishes() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path().join("out");
        let mut s = OutputSet::begin(&t).unwrap();
        s.add("a.hex", b"a").unwrap();
        s.add("manifest.toml", b"m").unwrap();
        s.add("b.hex", b"b").unwrap();
        assert!(s.add(".hidden", b"x").is_err());
        assert!(s.add("../escape", b"x").is_err());
        s.commit(Some("manifest.toml")).unwrap();
        assert_eq!(listing(&t), ["a.hex", "b.hex", "manifest.toml"]);
    }

    #[test]
    fn a_shrinking_set_drops_only_the_old_markers_files() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path().join("out");
        let mut s = OutputSet::begin(&t).unwrap();
        for n in ["a.v", "rom.hex", "rom.toml", "mine.txt"] {
            s.add(n, n.as_bytes()).unwrap();
        }
        s.commit_marked(crate::SET_MARKER, "# old").unwrap();
        // The user edits one file of the old set and adds one of their own.
        std::fs::write(t.join("mine.txt"), b"edited").unwrap();
        std::fs::write(t.join("notes.md"), b"user").unwrap();
        let mut s = OutputSet::begin(&t).unwrap();
        s.add("a.v", b"new a").unwrap();
        s.commit_marked(crate::SET_MARKER, "# new").unwrap();
        assert_eq!(
            listing(&t),
            ["a.v", "mine.txt", "notes.md", crate::SET_MARKER]
        );
        assert_eq!(crate::check_set(&t, crate::SET_MARKER).unwrap(), ["a.v"]);
    }

    #[test]
    fn a_protected_set_replaces_only_its_own_files_and_one_writer_at_a_time() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path().join("out");
        let names = ["a.npy".to_string(), "summary.json".to_string()];
        let mut s = OutputSet::begin(&t).unwrap();
        // A second writer into the same directory is refused while the first holds it.
        let e = OutputSet::begin(&t).unwrap_err();
        assert!(e.to_string().contains("is being written by"), "{e}");
        s.protect(crate::SET_MARKER, &names).unwrap();
        s.add_streamed("a.npy", |w| w.write_all(b"a1")).unwrap();
        s.add("summary.json", b"s1").unwrap();
        s.commit_marked(crate::SET_MARKER, "").unwrap();
        assert_eq!(crate::check_set(&t, crate::SET_MARKER).unwrap(), names);
        // Our own files are replaced; a user's file that appears during the run is not.
        let mut s = OutputSet::begin(&t).unwrap();
        s.protect(crate::SET_MARKER, &names).unwrap();
        s.add("a.npy", b"a2").unwrap();
        std::fs::write(t.join("summary.json"), b"the user's").unwrap();
        s.add("summary.json", b"s2").unwrap();
        let e = s.commit_marked(crate::SET_MARKER, "").unwrap_err();
        assert!(e.to_string().contains("summary.json is not a file"), "{e}");
        assert_eq!(
            std::fs::read(t.join("summary.json")).unwrap(),
            b"the user's"
        );
        assert_eq!(std::fs::read(t.join("a.npy")).unwrap(), b"a1");
        assert!(listing(&t).iter().all(|n| !n.starts_with('.')));
    }

    #[test]
    fn a_cut_commit_is_named_by_the_check() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path();
        std::fs::write(t.join("a.npy"), b"new").unwrap();
        let dead = t.join(format!("{STAGE_PREFIX}{PID_MARK}4194304{STAGE_SUFFIX}"));
        std::fs::create_dir(&dead).unwrap();
        std::fs::write(dead.join(COMMIT), "a.npy\nb.npy\ntofprobe-set.toml\n").unwrap();
        std::fs::write(dead.join("b.npy"), b"b").unwrap();
        std::fs::write(dead.join(crate::SET_MARKER), b"m").unwrap();
        let e = crate::check_set(t, crate::SET_MARKER)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("process 4194304 was cut short")
                && e.contains("moved in, beside what was there before: a.npy;")
                && e.contains("still staged: b.npy, tofprobe-set.toml"),
            "{e}"
        );
    }

    #[test]
    fn a_dropped_set_leaves_nothing_not_even_the_directory_it_made() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path().join("out");
        let mut s = OutputSet::begin(&t).unwrap();
        s.add("a.hex", b"a").unwrap();
        drop(s);
        assert!(!t.exists());
    }

    #[test]
    fn an_interrupted_commit_is_completed_and_an_uncommitted_stage_removed() {
        let dir = tempfile::tempdir().unwrap();
        let t = dir.path().to_path_buf();
        std::fs::write(t.join("a.hex"), b"old a").unwrap();
        std::fs::write(t.join("manifest.toml"), b"old m").unwrap();
        // A dead writer (pid above Linux's pid_max) that committed and moved a.hex only.
        let dead = t.join(format!("{STAGE_PREFIX}{PID_MARK}4194304{STAGE_SUFFIX}"));
        std::fs::create_dir(&dead).unwrap();
        std::fs::write(dead.join(COMMIT), "a.hex\nmanifest.toml\n").unwrap();
        std::fs::write(dead.join("manifest.toml"), b"new m").unwrap();
        std::fs::write(t.join("a.hex"), b"new a").unwrap();
        std::fs::remove_file(t.join("manifest.toml")).unwrap();
        // Another dead writer that never committed.
        let torn = t.join(format!("{STAGE_PREFIX}{PID_MARK}4194303{STAGE_SUFFIX}"));
        std::fs::create_dir(&torn).unwrap();
        std::fs::write(torn.join("a.hex"), b"half").unwrap();
        if !Path::new("/proc/self").exists() {
            return;
        }
        recover(&t).unwrap();
        assert_eq!(listing(&t), ["a.hex", "manifest.toml"]);
        assert_eq!(std::fs::read(t.join("a.hex")).unwrap(), b"new a");
        assert_eq!(std::fs::read(t.join("manifest.toml")).unwrap(), b"new m");
    }
}
