//! Reading an input file whole, within a stated size: only a regular file is read (a FIFO,
//! a character device such as `/dev/zero`, a socket would never end or never fit), its
//! length is checked against the cap before a byte is read, and at most `cap + 1` bytes are
//! read even if the file grows meanwhile. The error says which of these failed, with the
//! size and the cap, so the caller's message names the file, what it is and what fits.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// Largest configuration document read (16 MiB: the embedded default is 3 KB; a document
/// holding a megabyte string still fits, so its error can name the key).
pub const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// Largest liberty file read (512 MiB: the timed sky130 `hd` libraries are 6–13 MB, the
/// largest commercial ones a few hundred MB).
pub const MAX_LIBERTY_BYTES: u64 = 512 << 20;

/// The bytes of the regular file `path`, at most `cap` of them. Errors (kind
/// `InvalidInput`) for a file that is not a regular file or is larger than `cap`; I/O errors
/// as they come.
pub fn read_bounded(path: &Path, cap: u64) -> std::io::Result<Vec<u8>> {
    // Checked before opening too: opening a FIFO would wait for a writer.
    check_regular(&std::fs::metadata(path)?)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    check_regular(&meta)?;
    if meta.len() > cap {
        return Err(too_large(meta.len(), cap));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(cap + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap {
        return Err(too_large(bytes.len() as u64, cap));
    }
    Ok(bytes)
}

fn check_regular(meta: &std::fs::Metadata) -> std::io::Result<()> {
    if !meta.is_file() {
        let ft = meta.file_type();
        let what = if ft.is_dir() {
            "a directory"
        } else if ft.is_symlink() {
            "a symbolic link"
        } else {
            special_kind(&ft)
        };
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("it is {what}, not a regular file"),
        ));
    }
    Ok(())
}

/// [`read_bounded`] as UTF-8 text; invalid UTF-8 is an `InvalidData` error naming the
/// offset of the first invalid byte.
pub fn read_bounded_text(path: &Path, cap: u64) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path, cap)?).map_err(|e| {
        Error::new(
            ErrorKind::InvalidData,
            format!(
                "not valid UTF-8 (first invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

fn too_large(len: u64, cap: u64) -> Error {
    Error::new(
        ErrorKind::InvalidInput,
        format!("it holds {len} bytes or more, above the {cap}-byte limit for this input"),
    )
}

#[cfg(unix)]
fn special_kind(ft: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_char_device() {
        "a character device"
    } else if ft.is_block_device() {
        "a block device"
    } else if ft.is_fifo() {
        "a FIFO (named pipe)"
    } else if ft.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_regular_file_within_the_cap_and_refuses_the_rest() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.toml");
        std::fs::write(&p, b"0123456789").unwrap();
        assert_eq!(read_bounded(&p, 10).unwrap(), b"0123456789");
        let e = read_bounded(&p, 9).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidInput);
        assert!(e.to_string().contains("10 bytes") && e.to_string().contains("9-byte"));
        let e = read_bounded(d.path(), 100).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
        std::fs::write(&p, [0xff, 0xfe]).unwrap();
        let e = read_bounded_text(&p, 10).unwrap_err();
        assert!(e.to_string().contains("offset 0"), "{e}");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn dev_zero_is_refused_without_reading() {
        let e = read_bounded(Path::new("/dev/zero"), MAX_CONFIG_BYTES).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
    }
}
