//! The workspace's foundation utilities, written once and used by every crate: whole-or-absent
//! file output ([`write_atomic`] for one file, [`OutputSet`] for a command's set of files),
//! the registry of live temporaries that an interrupt removes ([`live`]), the cleaning of
//! temporaries left by killed runs ([`stale`]), inputs read within a stated size
//! ([`bounded`]: regular files only, so `/dev/zero` cannot exhaust memory), the sanitising of user text
//! before it reaches a generated file ([`text`]) and the FNV-1a content hash ([`fnv1a64`],
//! [`Fnv1a64`]) that names configurations, ROMs, vector files and cache entries, and the one
//! root of the caches ([`cache::root`]), the writer lock of an output directory
//! ([`lock`]) and the free space on its disk ([`disk`]), the [`watch::Watch`] a host
//! stops a long computation with, the one locator of the external tools
//! ([`tools::locate`]: `$TOFPROBE_<NAME>`, else `PATH`) and the one instruction-set
//! selection of the vector kernels ([`isa`]: detected, `TOFPROBE_ISA`, or a benchmark's
//! `--isa`), the one Markdown table writer of the reports ([`markdown::Table`]) and, behind
//! the `chart` feature, the one builder of the SVG plots (`chart`: the only user of plotters).
//!
//! Errors are plain [`std::io::Error`]s: each crate maps them into its own error enum with
//! the path it was writing.

mod atomic;
pub mod bounded;
pub mod cache;
#[cfg(feature = "chart")]
pub mod chart;
pub mod cpu;
pub mod disk;
pub mod isa;
pub mod live;
pub mod lock;
pub mod markdown;
pub mod marker;
pub mod npy;
mod set;
mod stage;
pub mod stale;
pub mod text;
pub mod tools;
pub mod watch;

pub use atomic::{write_atomic, write_svg_atomic};
pub use bounded::{read_bounded, read_bounded_text};
pub use marker::{SET_MARKER, SetStatus, check_set, inspect_set};
pub use set::{OutputSet, committed_sets, recover};
pub use stage::STAGE_PREFIX;

/// FNV-1a 64-bit offset basis: the hash of no bytes.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
/// FNV-1a 64-bit prime.
pub const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a, 64 bits, of `bytes`: small, dependency-free and stable across runs and
/// platforms. It identifies content (headers, manifests, caches); it is not a
/// cryptographic digest.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = Fnv1a64::default();
    h.write(bytes);
    h.finish()
}

/// Streaming FNV-1a, 64 bits: [`Fnv1a64::write`] any number of byte slices, then
/// [`Fnv1a64::finish`]; the result equals [`fnv1a64`] of their concatenation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fnv1a64(u64);

impl Default for Fnv1a64 {
    fn default() -> Self {
        Fnv1a64(FNV_OFFSET)
    }
}

impl Fnv1a64 {
    /// Feeds bytes.
    pub fn write(&mut self, bytes: &[u8]) -> &mut Self {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(FNV_PRIME);
        }
        self
    }

    /// The hash of everything fed so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// A writer that hashes (FNV-1a-64) and counts the bytes it passes on to `inner`: a file
/// streamed into an output set gets its marker's hash without being read back.
#[derive(Debug)]
pub struct HashingWriter<W: std::io::Write> {
    inner: W,
    hash: crate::Fnv1a64,
    len: u64,
}

impl<W: std::io::Write> HashingWriter<W> {
    /// Wraps `inner`, with nothing hashed yet.
    pub fn new(inner: W) -> Self {
        HashingWriter {
            inner,
            hash: crate::Fnv1a64::default(),
            len: 0,
        }
    }

    /// The inner writer, the hash and the length of what was written.
    pub fn finish(self) -> (W, u64, u64) {
        (self.inner, self.hash.finish(), self.len)
    }
}

impl<W: std::io::Write> std::io::Write for HashingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hash.write(&buf[..n]);
        self.len += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // From the FNV reference (isthe.com/chongo/tech/comp/fnv): "", "a", "foobar".
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
        let mut h = Fnv1a64::default();
        h.write(b"foo").write(b"bar");
        assert_eq!(h.finish(), fnv1a64(b"foobar"));
        // A deliberately wrong prime fails the vector: the check can fail.
        let wrong = b"a".iter().fold(FNV_OFFSET, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(FNV_PRIME + 2)
        });
        assert_ne!(wrong, 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn atomic_write_replaces_whole_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sub").join("x.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(p.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("x.txt")]);
    }

    #[test]
    fn failed_write_leaves_neither_target_nor_temporary() {
        let dir = tempfile::tempdir().unwrap();
        // The target is a directory: the rename fails, and the temporary must go.
        let target = dir.path().join("taken");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("keep"), b"k").unwrap();
        assert!(write_atomic(&target, b"data").is_err());
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("taken")]);
    }
}
