//! The completion marker of an output set: the one check every reader makes.
//!
//! A set is *whole* when its marker file is present and every file it lists is there with
//! the FNV-1a-64 hash the marker records. The marker is a TOML document whose `[files]`
//! table maps each file's path (relative to the set's directory, `/`-separated, never `..`)
//! to the 16-hex-digit hash of its bytes; anything else in it (a vector set's manifest
//! fields, a header comment) is the writer's. The marker is written last
//! ([`crate::OutputSet::commit`] moves it into place after every other file and removes the
//! old one first), so a set killed mid-commit has no marker and every reader refuses it as
//! incomplete ([`check_set`]); a file changed after the commit fails its hash.
//!
//! The generic marker is [`SET_MARKER`] (`tofprobe-set.toml`: `rtl`, `reproduce`, `flow`); a
//! vector set's `manifest.toml` is a marker of the same form.

use std::collections::BTreeMap;
use std::io::{Error, ErrorKind};
use std::path::Path;

/// The marker file of a set that has no manifest of its own.
pub const SET_MARKER: &str = "tofprobe-set.toml";

/// Largest marker read (a vector set lists a dozen files; 1 MiB is ample).
const MAX_MARKER_BYTES: u64 = 1 << 20;

/// The text of a marker: `preamble` (comment lines or TOML keys, may be empty) then the
/// `[files]` table of `files` (path → FNV-1a-64), sorted by path.
pub fn marker_text(preamble: &str, files: &BTreeMap<String, u64>) -> String {
    let mut s = String::from(preamble);
    if !s.is_empty() && !s.ends_with('\n') {
        s.push('\n');
    }
    s.push_str("[files]\n");
    for (name, hash) in files {
        // TOML basic string: the names are plain (checked by the writers), but escape
        // what a basic string cannot hold raw, so the marker always parses.
        let quoted: String = name
            .chars()
            .flat_map(|c| match c {
                '"' | '\\' => vec!['\\', c],
                c => vec![c],
            })
            .collect();
        s.push_str(&format!("\"{quoted}\" = \"{hash:016x}\"\n"));
    }
    s
}

/// The `[files]` table of the marker text `text` (path → hash), or `None` when it has none
/// or is not TOML (a file that is not a marker).
pub fn marker_files(text: &str) -> Option<BTreeMap<String, u64>> {
    let doc: toml::Table = toml::from_str(text).ok()?;
    let files = doc.get("files")?.as_table()?;
    let mut out = BTreeMap::new();
    for (name, hash) in files {
        let h = u64::from_str_radix(hash.as_str()?, 16).ok()?;
        out.insert(name.clone(), h);
    }
    Some(out)
}

/// A listed path a reader may open: relative, `/`-separated plain components, no `..`.
fn safe_relative(name: &str) -> bool {
    !name.is_empty()
        && !name.starts_with('/')
        && name
            .split('/')
            .all(|c| !c.is_empty() && c != "." && c != ".." && !c.contains('\\'))
}

/// FNV-1a-64 of the file at `path`, streamed.
pub fn hash_file(path: &Path) -> std::io::Result<u64> {
    use std::io::Read;
    let mut f = std::fs::File::open(path)?;
    let mut h = crate::Fnv1a64::default();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            return Ok(h.finish());
        }
        h.write(&buf[..n]);
    }
}

/// What [`inspect_set`] found of a set that has its marker and every listed file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SetStatus {
    /// The listed paths.
    pub files: Vec<String>,
    /// The listed paths whose bytes no longer have the recorded hash (changed since the
    /// commit), each as `path (hash H, the marker records M)`.
    pub changed: Vec<String>,
}

fn incomplete(dir: &Path, kind: ErrorKind, what: String) -> Error {
    Error::new(
        kind,
        format!(
            "{} is not a whole output set: {what}; it was interrupted or changed after it was written: write it again",
            dir.display()
        ),
    )
}

/// Why `dir` has no marker `marker`: a commit cut short (its stage names the files already
/// moved in, which now sit beside the previous set's, and those not), or none found (not a
/// tofprobe set, or one written before its kind carried a marker).
fn missing_marker(dir: &Path, marker: &str) -> String {
    let list = |v: &[String]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.join(", ")
        }
    };
    match crate::stage::interrupted_commit(dir) {
        Some((pid, moved, pending)) => format!(
            "its completion marker {marker} is missing because the commit of process {pid} \
             was cut short: moved in, beside what was there before: {}; still staged: {} \
             (the next tofprobe run writing into it completes that commit)",
            list(&moved),
            list(&pending)
        ),
        None => format!(
            "its completion marker {marker} is missing (no interrupted commit is there to \
             complete: not a tofprobe output set, or one written before its kind carried a \
             marker)"
        ),
    }
}

/// Reads the marker `marker` of the set in `dir` and checks that every file it lists is
/// there; a missing marker or file is an error (kind `NotFound`; `InvalidData` for a
/// marker that is not one or lists a path outside the set), a changed file is reported in
/// [`SetStatus::changed`] (a reader that co-simulates deliberately edited RTL may go on).
pub fn inspect_set(dir: &Path, marker: &str) -> std::io::Result<SetStatus> {
    let mpath = dir.join(marker);
    let text = match crate::read_bounded_text(&mpath, MAX_MARKER_BYTES) {
        Ok(t) => t,
        Err(e) if e.kind() == ErrorKind::NotFound => {
            return Err(incomplete(
                dir,
                ErrorKind::NotFound,
                missing_marker(dir, marker),
            ));
        }
        Err(e) => {
            return Err(incomplete(
                dir,
                ErrorKind::InvalidData,
                format!("its completion marker {marker} cannot be read: {e}"),
            ));
        }
    };
    let files = marker_files(&text)
        .filter(|f| !f.is_empty())
        .ok_or_else(|| {
            incomplete(
                dir,
                ErrorKind::InvalidData,
                format!("{marker} has no [files] table of path = \"16-hex-digit hash\""),
            )
        })?;
    let mut changed = Vec::new();
    for (name, want) in &files {
        if !safe_relative(name) || name == marker {
            return Err(incomplete(
                dir,
                ErrorKind::InvalidData,
                format!("{marker} lists `{name}`, not a plain relative path inside the set"),
            ));
        }
        match hash_file(&dir.join(name)) {
            Ok(h) if h == *want => {}
            Ok(h) => changed.push(format!(
                "{name} (hash {h:016x}, {marker} records {want:016x})"
            )),
            Err(e) => {
                return Err(incomplete(
                    dir,
                    e.kind(),
                    format!("{name}, listed in {marker}, cannot be read: {e}"),
                ));
            }
        }
    }
    Ok(SetStatus {
        files: files.into_keys().collect(),
        changed,
    })
}

/// Checks that `dir` holds a whole set completed by `marker`, unchanged: the marker is
/// there, lists at least one file, and every listed file exists with its recorded hash.
/// Returns the listed paths; the error says which file failed and that the set is not
/// whole.
pub fn check_set(dir: &Path, marker: &str) -> std::io::Result<Vec<String>> {
    let s = inspect_set(dir, marker)?;
    if let Some(first) = s.changed.first() {
        return Err(incomplete(
            dir,
            ErrorKind::InvalidData,
            format!("{first} was changed"),
        ));
    }
    Ok(s.files)
}

/// Refuses to replace a file the set in `dir` did not write: each of `names` present in
/// `dir` must be listed by the completion marker `dir/marker` with the hash its bytes have
/// now (a file of the previous set, unchanged since); `marker` itself may be replaced only
/// if it is a marker. The error (kind `AlreadyExists`) names the first file that is not
/// ours and why; nothing is written or removed by the check.
pub fn check_replaceable(dir: &Path, marker: &str, names: &[String]) -> std::io::Result<()> {
    let present: Vec<&String> = names.iter().filter(|n| dir.join(n).exists()).collect();
    if present.is_empty() {
        return Ok(());
    }
    let refuse = |name: &str, why: String| {
        Error::new(
            ErrorKind::AlreadyExists,
            format!(
                "{} is not a file of the tofprobe set in {} ({why}): it is not overwritten and \
                 nothing was run or written; move it away, or write the set into another directory",
                dir.join(name).display(),
                dir.display()
            ),
        )
    };
    let mpath = dir.join(marker);
    let listed = if mpath.exists() {
        let text = crate::read_bounded_text(&mpath, MAX_MARKER_BYTES).map_err(|e| {
            refuse(
                marker,
                format!("it cannot be read as a completion marker: {e}"),
            )
        })?;
        Some(marker_files(&text).ok_or_else(|| {
            refuse(
                marker,
                "it is not a completion marker: no [files] table of path = hash".into(),
            )
        })?)
    } else {
        None
    };
    for name in present {
        if name == marker {
            continue;
        }
        let Some(files) = &listed else {
            return Err(refuse(
                name,
                format!("the directory has no completion marker {marker} listing it"),
            ));
        };
        let Some(want) = files.get(name.as_str()) else {
            return Err(refuse(name, format!("{marker} does not list it")));
        };
        let path = dir.join(name);
        if !path.is_file() {
            return Err(refuse(name, "it is not a regular file".into()));
        }
        let got = hash_file(&path)?;
        if got != *want {
            return Err(refuse(
                name,
                format!(
                    "changed since tofprobe wrote it: hash {got:016x}, {marker} records {want:016x}"
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_marker_round_trips_and_checks_its_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.v"), b"module a;").unwrap();
        let mut files = BTreeMap::new();
        files.insert("a.v".to_string(), crate::fnv1a64(b"module a;"));
        let text = marker_text("# made by a test", &files);
        assert_eq!(marker_files(&text), Some(files.clone()));
        std::fs::write(dir.path().join(SET_MARKER), &text).unwrap();
        assert_eq!(check_set(dir.path(), SET_MARKER).unwrap(), ["a.v"]);
        // A changed file, a missing file and a missing marker are each refused.
        std::fs::write(dir.path().join("a.v"), b"module b;").unwrap();
        let e = check_set(dir.path(), SET_MARKER).unwrap_err().to_string();
        assert!(e.contains("a.v (hash"), "{e}");
        assert_eq!(
            inspect_set(dir.path(), SET_MARKER).unwrap().changed.len(),
            1
        );
        std::fs::remove_file(dir.path().join("a.v")).unwrap();
        assert!(check_set(dir.path(), SET_MARKER).is_err());
        std::fs::remove_file(dir.path().join(SET_MARKER)).unwrap();
        let e = check_set(dir.path(), SET_MARKER).unwrap_err().to_string();
        assert!(
            e.contains("completion marker tofprobe-set.toml is missing"),
            "{e}"
        );
    }

    #[test]
    fn only_files_the_marker_lists_unchanged_may_be_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let names: Vec<String> = ["a.npy", "summary.json", SET_MARKER]
            .map(String::from)
            .to_vec();
        // An empty directory, or one with other files only: nothing to refuse.
        std::fs::write(d.join("notes.txt"), b"mine").unwrap();
        check_replaceable(d, SET_MARKER, &names).unwrap();
        // A user's own summary.json without a marker: refused, named.
        std::fs::write(d.join("summary.json"), b"{}").unwrap();
        let e = check_replaceable(d, SET_MARKER, &names).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::AlreadyExists);
        assert!(
            e.to_string()
                .contains("summary.json is not a file of the tofprobe set"),
            "{e}"
        );
        // Listed with its hash: ours to replace.
        let mut files = BTreeMap::new();
        files.insert("summary.json".to_string(), crate::fnv1a64(b"{}"));
        std::fs::write(d.join(SET_MARKER), marker_text("", &files)).unwrap();
        check_replaceable(d, SET_MARKER, &names).unwrap();
        // Edited since: refused with both hashes.
        std::fs::write(d.join("summary.json"), b"{ }").unwrap();
        let e = check_replaceable(d, SET_MARKER, &names)
            .unwrap_err()
            .to_string();
        assert!(e.contains("changed since tofprobe wrote it"), "{e}");
        // Present but not listed; a marker that is not one.
        std::fs::write(d.join("summary.json"), b"{}").unwrap();
        std::fs::write(d.join("a.npy"), b"x").unwrap();
        let e = check_replaceable(d, SET_MARKER, &names)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.npy") && e.contains("does not list it"), "{e}");
        std::fs::remove_file(d.join("a.npy")).unwrap();
        std::fs::write(d.join(SET_MARKER), b"my notes").unwrap();
        let e = check_replaceable(d, SET_MARKER, &names)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(SET_MARKER) && e.contains("not a completion marker"),
            "{e}"
        );
    }

    #[test]
    fn a_marker_cannot_point_outside_its_set() {
        let dir = tempfile::tempdir().unwrap();
        for bad in ["../x", "/etc/passwd", "a/../../x", ""] {
            let mut files = BTreeMap::new();
            files.insert(bad.to_string(), 0);
            std::fs::write(dir.path().join(SET_MARKER), marker_text("", &files)).unwrap();
            assert!(check_set(dir.path(), SET_MARKER).is_err(), "{bad}");
        }
        assert!(marker_files("not = [toml").is_none());
    }
}
