//! One file whole or absent: [`write_atomic`].

use std::io::Write;
use std::path::Path;

use crate::stale::{PID_MARK, remove_stale, temporary_pid};

/// Longest part of the target's name kept in its temporary's name: a legal 255-byte name
/// plus the temporary's decorations would exceed NAME_MAX.
const NAME_IN_TEMPORARY: usize = 64;

/// `name` cut to at most `max` bytes on a character boundary.
pub(crate) fn shortened(name: &str, max: usize) -> &str {
    let mut end = name.len().min(max);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    &name[..end]
}

/// Writes `contents` to `path` whole or not at all: a temporary file in the target's
/// directory (created if missing), flushed to disk, then renamed over the target, so a
/// reader never sees a half-written file, and the temporary vanishes on any error
/// (`tempfile` deletes it when dropped). The temporary is hidden and named
/// `.NAME.tofprobe-PID.XXXXXX.tmp` (NAME cut to 64 bytes, so any legal file name works);
/// a run that was killed leaves it behind, and the next write into the same directory
/// removes it ([`crate::stale`]).
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)?;
    remove_stale(dir, temporary_pid);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let prefix = format!(
        ".{}{PID_MARK}{}.",
        shortened(&name, NAME_IN_TEMPORARY),
        std::process::id()
    );
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // A generated file is readable like any other file, not private (tempfile's default
    // 0600 would surprise whoever reads rtl/ or a report).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    // Registered while it lives, so an interrupt removes it (crate::live).
    let (mut tmp, live) = crate::live::create(
        crate::live::Kind::Temporary,
        || builder.tempfile_in(dir),
        |t| t.path().to_path_buf(),
    )?;
    tmp.write_all(contents)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    drop(live);
    Ok(())
}

/// [`write_atomic`] for an SVG the user named (`--svg FILE`): an existing file at `path`
/// is replaced only if it is an SVG (its first non-blank bytes `<svg` or `<?xml`), never a
/// foreign file; the refusal is an `AlreadyExists` error naming why.
pub fn write_svg_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(path) {
        let foreign = |why: String| {
            std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                format!("refusing to replace it: {why}; remove it or choose another path"),
            )
        };
        if !meta.is_file() {
            return Err(foreign("it exists and is not a regular file".into()));
        }
        let mut head = [0u8; 256];
        let n = std::fs::File::open(path).and_then(|mut f| {
            use std::io::Read;
            f.read(&mut head)
        })?;
        let text = String::from_utf8_lossy(&head[..n]);
        let t = text.trim_start();
        if !(t.starts_with("<svg") || t.starts_with("<?xml")) {
            return Err(foreign("it exists and is not an SVG".into()));
        }
    }
    write_atomic(path, contents)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_250_byte_name_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a".repeat(250) + ".svg");
        write_atomic(&p, b"<svg/>").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"<svg/>");
        // Cut on a character boundary, never inside a multi-byte character.
        assert_eq!(shortened("ééé", 3), "é");
    }
}
