//! NumPy's `.npy` format, version 1.0 (numpy's `lib/format.py`): the magic `\x93NUMPY`,
//! the version, a little-endian u16 header length, an ASCII Python dict
//! `{'descr': '<f8', 'fortran_order': False, 'shape': (R, C, K), }` padded with spaces to
//! a multiple of 64 bytes ending in a newline, then the C-order data. Written for int64
//! and float64 arrays; read for the numeric dtypes a map comes in (`<f8`, `<f4`, `<i8`,
//! `<i4`, `|u1`, `<u2`), converted to f64. A dependency-free page of code: the NPY crates
//! pull a parser generator and a C build for the header dict.

use std::io::{Error, ErrorKind, Write};

const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Largest header accepted when reading (numpy writes < 200 bytes for these arrays).
const MAX_HEADER: usize = 4096;

/// Elements an `.npy` array can hold, and their `descr`.
pub trait NpyElement: Copy {
    const DESCR: &'static str;
    fn put(self, out: &mut Vec<u8>);
}

impl NpyElement for i64 {
    const DESCR: &'static str = "<i8";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyElement for f64 {
    const DESCR: &'static str = "<f8";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

/// The header of an `.npy` file holding `count` elements of `T` in `shape` (magic,
/// version 1.0, the dict padded to a multiple of 64 bytes); the C-order data follows it.
pub fn header<T: NpyElement>(shape: &[usize]) -> Vec<u8> {
    let dims = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': {dims}, }}",
        T::DESCR
    );
    // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
    let total = (10 + header.len() + 1).div_ceil(64) * 64;
    header.push_str(&" ".repeat(total - 10 - header.len() - 1));
    header.push('\n');
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out
}

/// The size in bytes of the `.npy` file of `shape` with 8-byte elements (what [`write()`]
/// writes), saturating: an output set's size is estimated from it before any work.
pub fn file_bytes(shape: &[usize]) -> u64 {
    let count = shape.iter().fold(1u64, |a, &d| a.saturating_mul(d as u64));
    (header::<f64>(shape).len() as u64).saturating_add(count.saturating_mul(8))
}

/// Elements converted per block of [`write_iter`]: 64 KiB of data at a time.
const BLOCK: usize = 8192;

/// Writes the `.npy` file of `shape` holding the elements `data` yields (C order) to
/// `out`, a block of 64 KiB at a time: never the whole file in memory. The count must
/// match the shape (an error names both).
pub fn write_iter<T: NpyElement>(
    out: &mut dyn Write,
    shape: &[usize],
    data: impl IntoIterator<Item = T>,
) -> Result<(), Error> {
    let count = shape
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| {
            Error::new(
                ErrorKind::InvalidInput,
                format!("shape {shape:?} overflows"),
            )
        })?;
    out.write_all(&header::<T>(shape))?;
    let mut block = Vec::with_capacity(BLOCK * 8);
    let mut written = 0usize;
    for x in data {
        x.put(&mut block);
        written += 1;
        if block.len() >= BLOCK * 8 {
            out.write_all(&block)?;
            block.clear();
        }
    }
    out.write_all(&block)?;
    if written != count {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("shape {shape:?} holds {count} elements, the data {written}"),
        ));
    }
    Ok(())
}

/// [`write_iter`] of a slice (checked against the shape before a byte is written).
pub fn write<T: NpyElement>(out: &mut dyn Write, shape: &[usize], data: &[T]) -> Result<(), Error> {
    let count: usize = shape.iter().product();
    if count != data.len() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!(
                "shape {shape:?} holds {count} elements, the data {}",
                data.len()
            ),
        ));
    }
    write_iter(out, shape, data.iter().copied())
}

/// The bytes of an `.npy` file holding `data` (C order) of `shape` ([`write()`] into
/// memory: for small arrays and tests).
pub fn to_bytes<T: NpyElement>(shape: &[usize], data: &[T]) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    write(&mut out, shape, data)?;
    Ok(out)
}

/// An array read from an `.npy` file, converted to f64.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub data: Vec<f64>,
}

fn bad(message: impl Into<String>) -> Error {
    Error::new(ErrorKind::InvalidData, message.into())
}

/// The dtype and shape in an `.npy` header's dict (C order only).
fn parse_dict(dict: &[u8]) -> Result<(String, Vec<usize>), Error> {
    let header = std::str::from_utf8(dict).map_err(|_| bad("the .npy header is not text"))?;
    let field = |key: &str| -> Result<&str, Error> {
        let at = header
            .find(&format!("'{key}'"))
            .ok_or_else(|| bad(format!("the .npy header has no '{key}'")))?;
        let rest = header[at + key.len() + 2..].trim_start();
        Ok(rest.strip_prefix(':').unwrap_or(rest).trim_start())
    };
    let descr = field("descr")?;
    let descr = descr
        .strip_prefix('\'')
        .and_then(|d| d.split('\'').next())
        .ok_or_else(|| bad("the .npy descr is not a string"))?;
    if field("fortran_order")?.starts_with("True") {
        return Err(bad(
            "a Fortran-order .npy array (save it with numpy's default C order)",
        ));
    }
    let shape_text = field("shape")?;
    let shape_text = shape_text
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("the .npy shape is not a tuple"))?;
    let shape = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| bad(format!("shape entry {s:?}")))
        })
        .collect::<Result<Vec<usize>, Error>>()?;
    Ok((descr.to_string(), shape))
}

/// Reads an `.npy` file's header from `r` (versions 1.0–3.0, at most 4 KiB of dict, C
/// order), leaving `r` at the first data byte: the dtype (`<i8`, …) and the shape. For
/// readers that stream the data into place instead of holding the file.
pub fn read_header(r: &mut dyn std::io::Read) -> Result<(String, Vec<usize>), Error> {
    let mut head = [0u8; 8];
    r.read_exact(&mut head)
        .map_err(|_| bad("not an .npy file (shorter than its 8-byte preamble)"))?;
    if &head[..6] != MAGIC {
        return Err(bad("not an .npy file (no \\x93NUMPY magic)"));
    }
    let len = match head[6] {
        1 => {
            let mut l = [0u8; 2];
            r.read_exact(&mut l)
                .map_err(|_| bad("an .npy file cut short in its header"))?;
            usize::from(u16::from_le_bytes(l))
        }
        2 | 3 => {
            let mut l = [0u8; 4];
            r.read_exact(&mut l)
                .map_err(|_| bad("an .npy file cut short in its header"))?;
            u32::from_le_bytes(l) as usize
        }
        v => return Err(bad(format!(".npy version {v} is not one of 1, 2, 3"))),
    };
    if len > MAX_HEADER {
        return Err(bad(format!("an .npy header of {len} bytes")));
    }
    let mut dict = vec![0u8; len];
    r.read_exact(&mut dict)
        .map_err(|_| bad("an .npy file cut short in its header"))?;
    parse_dict(&dict)
}

/// Parses an `.npy` file's bytes (versions 1.0–3.0, C order, the numeric dtypes above).
pub fn from_bytes(bytes: &[u8]) -> Result<NpyArray, Error> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(bad("not an .npy file (no \\x93NUMPY magic)"));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v @ (2 | 3) => {
            return Err(bad(format!(
                "a version {v} .npy file of {} bytes is cut short: its header length takes \
                 bytes 8..12",
                bytes.len()
            )));
        }
        v => return Err(bad(format!(".npy version {v} is not one of 1, 2, 3"))),
    };
    if len > MAX_HEADER || start + len > bytes.len() {
        return Err(bad(format!("an .npy header of {len} bytes")));
    }
    let (descr, shape) = parse_dict(&bytes[start..start + len])?;
    let descr = descr.as_str();
    let count = shape
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| bad("the .npy shape overflows"))?;
    let data = &bytes[start + len..];
    let size = match descr {
        "<f8" | "<i8" => 8,
        "<f4" | "<i4" => 4,
        "<u2" => 2,
        "|u1" => 1,
        other => {
            return Err(bad(format!(
                "dtype {other:?}: expected one of <f8, <f4, <i8, <i4, <u2, |u1"
            )));
        }
    };
    if count.checked_mul(size) != Some(data.len()) {
        return Err(bad(format!(
            "shape {shape:?} of {descr} needs {} data bytes, the file has {}",
            count.saturating_mul(size),
            data.len()
        )));
    }
    let values = data
        .chunks_exact(size)
        .map(|c| match descr {
            "<f8" => f64::from_le_bytes(c.try_into().unwrap_or_default()),
            "<i8" => i64::from_le_bytes(c.try_into().unwrap_or_default()) as f64,
            "<f4" => f64::from(f32::from_le_bytes(c.try_into().unwrap_or_default())),
            "<i4" => f64::from(i32::from_le_bytes(c.try_into().unwrap_or_default())),
            "<u2" => f64::from(u16::from_le_bytes(c.try_into().unwrap_or_default())),
            _ => f64::from(c[0]),
        })
        .collect();
    Ok(NpyArray {
        shape,
        data: values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header numpy 1.26 writes for `np.save(f, np.zeros((2, 3)))`, byte for byte
    /// (numpy pads the v1.0 header to 64 bytes in all; `format.py` documents the layout).
    #[test]
    fn header_is_numpys() {
        let b = to_bytes(&[2, 3], &[0.0f64; 6]).unwrap();
        let want =
            b"\x93NUMPY\x01\x00\x76\x00{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
        assert_eq!(&b[..want.len()], want);
        assert_eq!((10 + 0x76) % 64, 0);
        assert_eq!(b[10 + 0x76 - 1], b'\n');
        assert_eq!(b.len(), 128 + 48);
    }

    #[test]
    fn round_trip_and_refusals() {
        let data: Vec<i64> = (0..24).map(|i| i * 1_000_000_007 - 5).collect();
        let b = to_bytes(&[2, 3, 4], &data).unwrap();
        let a = from_bytes(&b).unwrap();
        assert_eq!(a.shape, vec![2, 3, 4]);
        assert_eq!(a.data, data.iter().map(|&x| x as f64).collect::<Vec<_>>());
        let one = from_bytes(&to_bytes(&[3], &[1.5f64, 2.0, -3.0]).unwrap()).unwrap();
        assert_eq!((one.shape, one.data), (vec![3], vec![1.5, 2.0, -3.0]));
        assert!(to_bytes(&[2, 2], &[1i64]).is_err());
        assert!(from_bytes(&b[..b.len() - 1]).is_err(), "truncated data");
        assert!(from_bytes(b"not numpy").is_err());
        // A 10-byte version-2 file is cut short, not of an unknown version.
        let e = from_bytes(b"\x93NUMPY\x02\x00\x10\x00")
            .unwrap_err()
            .to_string();
        assert!(e.contains("version 2") && e.contains("cut short"), "{e}");
    }

    /// The streamed writer gives [`to_bytes`]' bytes across block boundaries, and
    /// [`file_bytes`] is their length.
    #[test]
    fn streamed_file_is_the_whole_one() {
        let n = 3 * BLOCK + 5;
        let data: Vec<i64> = (0..n as i64).map(|i| i * 7 - 3).collect();
        let mut w = Vec::new();
        write_iter(&mut w, &[n], data.iter().copied()).unwrap();
        assert_eq!(w, to_bytes(&[n], &data).unwrap());
        assert_eq!(file_bytes(&[n]), w.len() as u64);
        assert_eq!(from_bytes(&w).unwrap().data.len(), n);
        // A count that does not match the shape is refused.
        assert!(write_iter(&mut Vec::new(), &[2, 2], [1i64, 2, 3]).is_err());
    }
}
