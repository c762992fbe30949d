//! The one root of tofprobe's caches (syntheses under `synth/`, Verilator builds under
//! `verilator/`, the decompressed PDK under `sky130/`), so `size`, `layout`, `cosim` and the
//! tests agree where a cache is and one variable moves all of it; and the one way an entry
//! of a cache is made and read ([`entry`]): built in a private temporary directory, sealed
//! with the completion marker of its files' hashes, published by a rename, under a lock per
//! key (one build per key, across threads and processes), and checked on every read (a
//! torn or changed entry is built again). A single-file cache value is [`sealed`]: its
//! bytes behind a line with their hash, written atomically and checked on read.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::stale::{pid_tagged, temporary_pid};

/// The cache root: `$TOFPROBE_CACHE`, else `$TOFPROBE_CACHE_DIR` (the name the Verilator
/// cache read first, still honoured), else `$XDG_CACHE_HOME/tofprobe`, else
/// `~/.cache/tofprobe`, else the temporary directory's `tofprobe-cache`. An empty
/// variable counts as unset (an empty path would be the working directory).
pub fn root() -> PathBuf {
    root_from(|k| std::env::var_os(k))
}

/// [`root`] with the environment given (the tests' seam).
pub fn root_from(var: impl Fn(&str) -> Option<OsString>) -> PathBuf {
    let set = |k: &str| var(k).filter(|v| !v.is_empty());
    set("TOFPROBE_CACHE")
        .or_else(|| set("TOFPROBE_CACHE_DIR"))
        .map(PathBuf::from)
        .or_else(|| set("XDG_CACHE_HOME").map(|p| PathBuf::from(p).join("tofprobe")))
        .or_else(|| set("HOME").map(|p| PathBuf::from(p).join(".cache/tofprobe")))
        .unwrap_or_else(|| std::env::temp_dir().join("tofprobe-cache"))
}

/// The exclusive lock of cache key `key` under `root` (a lock file beside the entries,
/// released when the returned file is dropped, or by the kernel when the process dies).
pub fn lock_key(root: &Path, key: &str) -> std::io::Result<std::fs::File> {
    std::fs::create_dir_all(root)?;
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(root.join(format!("{key}.lock")))?;
    file.lock()?;
    Ok(file)
}

/// The files under `dir`, as `/`-separated relative paths (sorted; directories walked,
/// symbolic links listed as they are not followed).
fn files_under(dir: &Path) -> std::io::Result<Vec<String>> {
    let mut out = Vec::new();
    let mut todo = vec![(dir.to_path_buf(), String::new())];
    while let Some((d, prefix)) = todo.pop() {
        for e in std::fs::read_dir(&d)? {
            let e = e?;
            let name = format!("{prefix}{}", e.file_name().to_string_lossy());
            let t = e.file_type()?;
            if t.is_dir() {
                todo.push((e.path(), format!("{name}/")));
            } else if t.is_file() {
                out.push(name);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Whether the entry `dir` is whole: its marker there, every listed file with its hash.
pub fn entry_is_whole(dir: &Path) -> bool {
    crate::marker::check_set(dir, crate::SET_MARKER).is_ok()
}

static BUILDS: AtomicU64 = AtomicU64::new(0);

/// A temporary build directory, removed when dropped unless published.
struct Building {
    dir: PathBuf,
    _live: crate::live::Live,
}

impl Drop for Building {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The cache entry `root/key`: reused when whole ([`entry_is_whole`]); else built by
/// `build` into a private temporary directory (`root/.KEY.tofprobe-PID.N`, removed on any
/// failure or interrupt, and by the next build if the process was killed), sealed with the
/// marker of its files' hashes and published by renaming it into place. The key's lock is
/// held throughout, so concurrent callers wait for one build and reuse it, and no reader
/// ever sees a file half written (`size` once read a half-written `netlist.v`). `build`
/// receives the directory it fills; whatever it records about the entry must name the
/// final `root/key` paths. Returns the entry and whether it was reused; `io` maps an
/// I/O failure at a path into the caller's error.
pub fn entry<E>(
    root: &Path,
    key: &str,
    build: impl FnOnce(&Path) -> Result<(), E>,
    io: impl Fn(&Path, std::io::Error) -> E,
) -> Result<(PathBuf, bool), E> {
    let dir = root.join(key);
    let _lock = lock_key(root, key).map_err(|e| io(root, e))?;
    if entry_is_whole(&dir) {
        return Ok((dir, true));
    }
    // Missing, torn (a run killed while an older tofprobe wrote in place) or changed.
    match std::fs::remove_dir_all(&dir) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(&dir, e)),
        _ => {}
    }
    crate::stale::remove_stale(root, temporary_pid);
    let tmp = root.join(pid_tagged(
        key,
        &BUILDS.fetch_add(1, Ordering::Relaxed).to_string(),
    ));
    let ((), live) = crate::live::create(
        crate::live::Kind::Temporary,
        || std::fs::create_dir_all(&tmp),
        |_| tmp.clone(),
    )
    .map_err(|e| io(&tmp, e))?;
    let building = Building {
        dir: tmp.clone(),
        _live: live,
    };
    build(&tmp)?;
    let mut hashes = std::collections::BTreeMap::new();
    for name in files_under(&tmp).map_err(|e| io(&tmp, e))? {
        let h = crate::marker::hash_file(&tmp.join(&name)).map_err(|e| io(&tmp.join(&name), e))?;
        hashes.insert(name, h);
    }
    let marker = tmp.join(crate::SET_MARKER);
    let text = crate::marker::marker_text(
        "# A tofprobe cache entry: each file's FNV-1a-64, checked on every read.",
        &hashes,
    );
    std::fs::write(&marker, text).map_err(|e| io(&marker, e))?;
    std::fs::File::open(&marker)
        .and_then(|f| f.sync_all())
        .map_err(|e| io(&marker, e))?;
    std::fs::rename(&tmp, &dir).map_err(|e| io(&dir, e))?;
    drop(building);
    Ok((dir, false))
}

/// The first line of a [`sealed`] value: this prefix, then the hash and length of the rest.
const SEAL: &str = "# tofprobe cache value, fnv1a64 ";

/// `bytes` sealed for a single-file cache: a first line with their FNV-1a-64 and length,
/// then the bytes.
pub fn sealed(bytes: &[u8]) -> Vec<u8> {
    let mut out = format!("{SEAL}{:016x} {}\n", crate::fnv1a64(bytes), bytes.len()).into_bytes();
    out.extend_from_slice(bytes);
    out
}

/// The bytes of a [`sealed`] file's contents, if its seal holds (`None`: not sealed, cut
/// short or changed — the value is computed again).
pub fn unsealed(contents: &[u8]) -> Option<&[u8]> {
    let nl = contents.iter().position(|&b| b == b'\n')?;
    let head = std::str::from_utf8(&contents[..nl])
        .ok()?
        .strip_prefix(SEAL)?;
    let (hash, len) = head.split_once(' ')?;
    let body = &contents[nl + 1..];
    (u64::from_str_radix(hash, 16).ok()? == crate::fnv1a64(body)
        && len.parse::<usize>().ok()? == body.len())
    .then_some(body)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| OsString::from(v))
        }
    }

    /// Four threads want one key: one build, three reuses; a torn entry (a file changed
    /// since it was sealed) is built again; a failed build leaves nothing.
    #[test]
    fn an_entry_is_built_once_published_whole_and_checked_on_read() {
        use std::sync::atomic::AtomicUsize;
        let root = tempfile::tempdir().unwrap();
        let builds = AtomicUsize::new(0);
        let io = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
        let make = |tmp: &Path| -> Result<(), String> {
            builds.fetch_add(1, Ordering::SeqCst);
            std::thread::sleep(std::time::Duration::from_millis(50));
            std::fs::create_dir(tmp.join("sub")).unwrap();
            std::fs::write(tmp.join("netlist.v"), b"module m; endmodule\n").unwrap();
            std::fs::write(tmp.join("sub/log"), b"ok").unwrap();
            Ok(())
        };
        let reused: Vec<bool> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|_| s.spawn(|| entry(root.path(), "k1", make, io).unwrap().1))
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(builds.load(Ordering::SeqCst), 1);
        assert_eq!(reused.iter().filter(|r| **r).count(), 3);
        let dir = root.path().join("k1");
        assert_eq!(
            crate::check_set(&dir, crate::SET_MARKER).unwrap(),
            ["netlist.v", "sub/log"]
        );
        // Half a netlist (what a reader once met): rebuilt, not read.
        std::fs::write(dir.join("netlist.v"), b"module m;").unwrap();
        assert!(!entry(root.path(), "k1", make, io).unwrap().1);
        assert_eq!(builds.load(Ordering::SeqCst), 2);
        assert_eq!(
            std::fs::read(dir.join("netlist.v")).unwrap(),
            b"module m; endmodule\n"
        );
        // A failed build publishes nothing and leaves no temporary.
        let e = entry(root.path(), "k2", |_| Err("no".to_string()), io).unwrap_err();
        assert_eq!(e, "no");
        let left: Vec<_> = std::fs::read_dir(root.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with('.') || n == "k2")
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }

    #[test]
    fn a_sealed_value_reads_back_only_whole() {
        let s = sealed(b"{\"slack\": 1.5}");
        assert_eq!(unsealed(&s), Some(&b"{\"slack\": 1.5}"[..]));
        assert_eq!(unsealed(&s[..s.len() - 1]), None, "cut short");
        let mut changed = s.clone();
        let last = changed.len() - 2;
        changed[last] = b'7';
        assert_eq!(unsealed(&changed), None, "changed");
        assert_eq!(unsealed(b"{\"slack\": 1.5}"), None, "not sealed");
    }

    #[test]
    fn the_cache_root_follows_the_variables_in_order() {
        let all = [
            ("TOFPROBE_CACHE", "/a"),
            ("TOFPROBE_CACHE_DIR", "/b"),
            ("XDG_CACHE_HOME", "/x"),
            ("HOME", "/h"),
        ];
        assert_eq!(root_from(env(&all)), PathBuf::from("/a"));
        assert_eq!(root_from(env(&all[1..])), PathBuf::from("/b"));
        assert_eq!(root_from(env(&all[2..])), PathBuf::from("/x/tofprobe"));
        assert_eq!(
            root_from(env(&all[3..])),
            PathBuf::from("/h/.cache/tofprobe")
        );
        // Empty counts as unset: not the working directory.
        assert_eq!(
            root_from(env(&[("TOFPROBE_CACHE", ""), ("HOME", "/h")])),
            PathBuf::from("/h/.cache/tofprobe")
        );
        assert_eq!(
            root_from(env(&[])),
            std::env::temp_dir().join("tofprobe-cache")
        );
    }
}
