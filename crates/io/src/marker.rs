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
                format!("its completion marker {marker} is missing"),
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
