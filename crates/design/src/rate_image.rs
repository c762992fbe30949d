//! The images a rate map comes from: a binary PGM (P5, maxval < 256: 8-bit, else 16-bit
//! big-endian) read as value / maxval, or a `.npy` of R × C numbers read as they are.
//! Bounded: a regular file of at most the size an R × C float64 map needs, checked before
//! it is read.

use std::io::Read;
use std::path::Path;

/// Reads `path` as an R × C map (row-major).
pub fn read(path: &Path, rows: usize, cols: usize) -> Result<Vec<f64>, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read it ({e})"))?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    let cap = 8 * (rows * cols) as u64 + 4096;
    if meta.len() > cap {
        return Err(format!(
            "{} bytes is larger than an {rows} × {cols} map can be ({cap} bytes)",
            meta.len()
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(cap).read_to_end(&mut bytes))
        .map_err(|e| format!("cannot read it ({e})"))?;
    let (shape, data) = if bytes.starts_with(b"P5") {
        pgm(&bytes)?
    } else if bytes.starts_with(b"\x93NUMPY") {
        let a = tofprobe_io::npy::from_bytes(&bytes).map_err(|e| e.to_string())?;
        (a.shape, a.data)
    } else {
        return Err("neither a binary PGM (P5) nor a .npy file".into());
    };
    if shape != [rows, cols] {
        return Err(format!(
            "the image is {shape:?}, the array [{rows}, {cols}] (rows, cols)"
        ));
    }
    Ok(data)
}

/// A binary PGM: "P5", width, height, maxval (whitespace and # comments between), one
/// whitespace byte, then height × width samples.
fn pgm(bytes: &[u8]) -> Result<(Vec<usize>, Vec<f64>), String> {
    let mut pos = 2;
    let mut fields = [0usize; 3];
    for f in &mut fields {
        loop {
            while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if pos < bytes.len() && bytes[pos] == b'#' {
                while pos < bytes.len() && bytes[pos] != b'\n' {
                    pos += 1;
                }
                continue;
            }
            break;
        }
        let start = pos;
        while pos < bytes.len() && bytes[pos].is_ascii_digit() {
            pos += 1;
        }
        *f = std::str::from_utf8(&bytes[start..pos])
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or("a PGM header without width, height and maxval")?;
    }
    let [w, h, maxval] = fields;
    if !(1..=65535).contains(&maxval) {
        return Err(format!("PGM maxval {maxval}: allowed 1..=65535"));
    }
    pos += 1;
    let depth = if maxval < 256 { 1 } else { 2 };
    let data = bytes.get(pos..).unwrap_or_default();
    if data.len() != w * h * depth {
        return Err(format!(
            "a {w} × {h} PGM of {}-bit samples needs {} bytes of pixels, the file has {}",
            8 * depth,
            w * h * depth,
            data.len()
        ));
    }
    let values = data
        .chunks_exact(depth)
        .map(|c| {
            let v = if depth == 1 {
                u32::from(c[0])
            } else {
                u32::from(c[0]) << 8 | u32::from(c[1])
            };
            f64::from(v) / maxval as f64
        })
        .collect();
    Ok((vec![h, w], values))
}
