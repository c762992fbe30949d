//! Room on the disk before work: [`free_bytes`] of the file system holding a directory
//! (`statvfs`: the blocks an unprivileged writer may use), so a command that knows the
//! size of the set it will write refuses before running rather than filling the disk
//! halfway through its commit ([`check_room`]).

use std::io::{Error, ErrorKind};
use std::path::Path;

/// Bytes an unprivileged process may still write on the file system holding `path` (the
/// nearest existing ancestor of it).
pub fn free_bytes(path: &Path) -> std::io::Result<u64> {
    let at = path
        .ancestors()
        .find(|p| !p.as_os_str().is_empty() && p.exists())
        .unwrap_or(Path::new("."));
    #[cfg(unix)]
    {
        let s = rustix::fs::statvfs(at).map_err(Error::from)?;
        Ok(s.f_bavail.saturating_mul(s.f_frsize))
    }
    #[cfg(not(unix))]
    {
        let _ = at;
        Ok(u64::MAX)
    }
}

/// Space kept free beyond a set's estimate (the file system's metadata, the marker, the
/// directory entries): 1 MiB.
pub const MARGIN_BYTES: u64 = 1 << 20;

/// Refuses a set of `estimate` bytes that does not fit, with [`MARGIN_BYTES`] to spare, in
/// the free space of the file system of `dir`; `what` names the set and how to make it
/// smaller (it ends the message).
pub fn check_room(dir: &Path, estimate: u64, what: &str) -> std::io::Result<()> {
    let free = free_bytes(dir)?;
    if estimate.saturating_add(MARGIN_BYTES) > free {
        return Err(Error::new(
            ErrorKind::StorageFull,
            format!(
                "{} has {} free, and the set would take about {} (with {} to spare): nothing \
                 was run or written; {what}",
                dir.display(),
                human_bytes(free),
                human_bytes(estimate),
                human_bytes(MARGIN_BYTES)
            ),
        ));
    }
    Ok(())
}

/// Bytes in the largest binary unit that keeps the figure ≥ 1 (`3.2 GiB`, `512 B`).
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_free_space_is_read_and_a_set_too_large_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let free = free_bytes(dir.path()).unwrap();
        assert!(free > 0);
        // A path not made yet is judged by its nearest existing ancestor.
        assert_eq!(
            free_bytes(&dir.path().join("a/b")).unwrap() / (1 << 20),
            free / (1 << 20)
        );
        check_room(dir.path(), 1024, "-").unwrap();
        let e = check_room(dir.path(), free, "use fewer pixels").unwrap_err();
        assert_eq!(e.kind(), ErrorKind::StorageFull);
        assert!(e.to_string().ends_with("use fewer pixels"), "{e}");
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(3 << 29), "1.5 GiB");
    }
}
