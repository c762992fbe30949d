//! The PicoQuant PTU header: the `PQTTTR` magic, a version, then tagged values
//! (a 32-byte ident, index i32, type u32, value 8 bytes; strings, arrays and blobs carry their
//! byte length in the value and follow it), ending at `Header_End`.

use std::io::Read;

use crate::error::SceneError;

/// The 8-byte magic every PTU file starts with.
pub const PTU_MAGIC: &[u8; 8] = b"PQTTTR\0\0";

/// Longest string, array or blob a header tag may carry: real headers are a few kB, so
/// a larger length means a corrupt file, not a reason to allocate gigabytes.
const MAX_TAG_BYTES: u64 = 1 << 24;
/// Most tags a header may hold before we call it corrupt (no `Header_End`).
const MAX_TAGS: usize = 100_000;

const TY_EMPTY8: u32 = 0xFFFF_0008;
const TY_BOOL8: u32 = 0x0000_0008;
const TY_INT8: u32 = 0x1000_0008;
const TY_BITSET64: u32 = 0x1100_0008;
const TY_COLOR8: u32 = 0x1200_0008;
const TY_FLOAT8: u32 = 0x2000_0008;
const TY_TDATETIME: u32 = 0x2100_0008;
const TY_FLOAT8ARRAY: u32 = 0x2001_FFFF;
const TY_ANSISTRING: u32 = 0x4001_FFFF;
const TY_WIDESTRING: u32 = 0x4002_FFFF;
const TY_BINARYBLOB: u32 = 0xFFFF_FFFF;

/// The value of one header tag.
#[derive(Debug, Clone, PartialEq)]
pub enum TagValue {
    /// `tyEmpty8`: no value (e.g. `Header_End`).
    Empty,
    /// `tyBool8`.
    Bool(bool),
    /// `tyInt8`.
    Int(i64),
    /// `tyBitSet64`.
    BitSet(u64),
    /// `tyColor8`.
    Color(u64),
    /// `tyFloat8`.
    Float(f64),
    /// `tyTDateTime`: days since 1899-12-30 (the Delphi epoch).
    DateTime(f64),
    /// `tyFloat8Array`.
    FloatArray(Vec<f64>),
    /// `tyAnsiString` (trailing NULs removed; decoded lossily as UTF-8).
    Ansi(String),
    /// `tyWideString` (UTF-16LE, trailing NULs removed).
    Wide(String),
    /// `tyBinaryBlob`.
    Blob(Vec<u8>),
}

/// One header tag: identifier, index (−1 when the tag is not an array element), value.
#[derive(Debug, Clone, PartialEq)]
pub struct Tag {
    /// Identifier, e.g. `TTResultFormat_TTTRRecType`.
    pub ident: String,
    /// Array index, −1 for a scalar tag.
    pub index: i32,
    /// The value.
    pub value: TagValue,
}

/// A parsed PTU header.
#[derive(Debug, Clone, PartialEq)]
pub struct PtuHeader {
    /// Format version, e.g. `1.0.00`.
    pub version: String,
    /// Every tag, in file order.
    pub tags: Vec<Tag>,
    /// Header length in bytes (the first record's byte offset).
    pub len: u64,
}

impl PtuHeader {
    /// The value of the first tag named `ident` (any index).
    pub fn get(&self, ident: &str) -> Option<&TagValue> {
        self.tags
            .iter()
            .find(|t| t.ident == ident)
            .map(|t| &t.value)
    }

    /// An integer tag.
    pub fn int(&self, ident: &str) -> Option<i64> {
        match self.get(ident)? {
            TagValue::Int(v) => Some(*v),
            _ => None,
        }
    }

    /// A float tag.
    pub fn float(&self, ident: &str) -> Option<f64> {
        match self.get(ident)? {
            TagValue::Float(v) => Some(*v),
            _ => None,
        }
    }

    /// Reads the header from the start of `r` (the magic included).
    pub fn read(r: &mut impl Read, file: &str) -> Result<PtuHeader, SceneError> {
        let err = |at: String, expected: &str, found: String| SceneError::Tttr {
            file: file.to_string(),
            at,
            expected: expected.to_string(),
            found,
        };
        let mut pos = 0u64;
        let mut fixed = [0u8; 16];
        read_all(r, &mut fixed).map_err(|n| {
            err(
                "byte 0 (magic)".into(),
                "a PTU header (16 bytes: magic PQTTTR and version)",
                format!("{n} bytes, then the end of the file"),
            )
        })?;
        if &fixed[..8] != PTU_MAGIC {
            return Err(err(
                "byte 0 (magic)".into(),
                "the PTU magic \"PQTTTR\\0\\0\" (or a Becker & Hickl file named *.spc)",
                format!("{:?}", String::from_utf8_lossy(&fixed[..8])),
            ));
        }
        let version = c_string(&fixed[8..]);
        pos += 16;
        let mut tags = Vec::new();
        loop {
            let at = format!("header tag {} (byte {pos})", tags.len());
            if tags.len() >= MAX_TAGS {
                return Err(err(at, "Header_End within 100000 tags", "none".into()));
            }
            let mut raw = [0u8; 48];
            read_all(r, &mut raw).map_err(|n| {
                err(
                    at.clone(),
                    "a 48-byte tag (the header ends at Header_End)",
                    format!("{n} bytes, then the end of the file (a truncated header)"),
                )
            })?;
            pos += 48;
            let ident = c_string(&raw[..32]);
            let index = i32::from_le_bytes(raw[32..36].try_into().expect("4 bytes"));
            let ty = u32::from_le_bytes(raw[36..40].try_into().expect("4 bytes"));
            let v: [u8; 8] = raw[40..48].try_into().expect("8 bytes");
            let at = format!("header tag {} `{ident}` (byte {})", tags.len(), pos - 48);
            let value = match ty {
                TY_EMPTY8 => TagValue::Empty,
                TY_BOOL8 => TagValue::Bool(i64::from_le_bytes(v) != 0),
                TY_INT8 => TagValue::Int(i64::from_le_bytes(v)),
                TY_BITSET64 => TagValue::BitSet(u64::from_le_bytes(v)),
                TY_COLOR8 => TagValue::Color(u64::from_le_bytes(v)),
                TY_FLOAT8 => TagValue::Float(f64::from_le_bytes(v)),
                TY_TDATETIME => TagValue::DateTime(f64::from_le_bytes(v)),
                TY_FLOAT8ARRAY | TY_ANSISTRING | TY_WIDESTRING | TY_BINARYBLOB => {
                    let n = u64::from_le_bytes(v);
                    if n > MAX_TAG_BYTES {
                        return Err(err(
                            at,
                            "a tag payload of at most 16 MiB",
                            format!("{n} bytes (a corrupt header)"),
                        ));
                    }
                    let mut bytes = vec![0u8; n as usize];
                    read_all(r, &mut bytes).map_err(|got| {
                        err(
                            at.clone(),
                            &format!("{n} bytes of tag payload"),
                            format!("{got} bytes, then the end of the file"),
                        )
                    })?;
                    pos += n;
                    match ty {
                        TY_FLOAT8ARRAY => TagValue::FloatArray(
                            bytes
                                .chunks_exact(8)
                                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                                .collect(),
                        ),
                        TY_ANSISTRING => TagValue::Ansi(c_string(&bytes)),
                        TY_WIDESTRING => {
                            let units: Vec<u16> = bytes
                                .chunks_exact(2)
                                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                                .take_while(|&u| u != 0)
                                .collect();
                            TagValue::Wide(String::from_utf16_lossy(&units))
                        }
                        _ => TagValue::Blob(bytes),
                    }
                }
                other => {
                    return Err(err(
                        at,
                        "a tag type tyEmpty8/Bool8/Int8/BitSet64/Color8/Float8/TDateTime/\
                         Float8Array/AnsiString/WideString/BinaryBlob",
                        format!("type 0x{other:08X}"),
                    ));
                }
            };
            let end = ident == "Header_End";
            tags.push(Tag {
                ident,
                index,
                value,
            });
            if end {
                break;
            }
        }
        Ok(PtuHeader {
            version,
            tags,
            len: pos,
        })
    }
}

/// Fills `buf`, or reports how many bytes there were before the end (or an I/O error).
fn read_all(r: &mut impl Read, buf: &mut [u8]) -> Result<(), usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => return Err(got),
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return Err(got),
        }
    }
    Ok(())
}

/// A NUL-terminated byte string.
fn c_string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}
