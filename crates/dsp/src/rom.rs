//! The probe ROM image the chip stores: 2·B bits per pulse index (register r = 2k is I of
//! bin k, 2k+1 is Q of bin k), addressed by pulse index mod depth L. Bit 1 means the pixel
//! adds its operand to that register, 0 that it subtracts.
//!
//! Bits are packed little-endian into u64 words, `words_per_entry` words per address, so the
//! pixel model reads one entry per pulse without unpacking.

use crate::error::DspError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A bit-packed probe ROM: `depth` entries of `registers` bits. Serialised as its fields;
/// a deserialised image whose words do not fit its depth and registers is refused.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "RomImageFields")]
pub struct RomImage {
    depth: usize,
    registers: usize,
    words_per_entry: usize,
    data: Vec<u64>,
}

/// [`RomImage`]'s fields as serialised, checked before they become an image.
#[derive(Deserialize)]
struct RomImageFields {
    depth: usize,
    registers: usize,
    words_per_entry: usize,
    data: Vec<u64>,
}

impl TryFrom<RomImageFields> for RomImage {
    type Error = String;

    fn try_from(f: RomImageFields) -> Result<Self, String> {
        let words = f.registers.div_ceil(64).max(1);
        if f.words_per_entry != words || f.depth.checked_mul(words) != Some(f.data.len()) {
            return Err(format!(
                "a ROM image of {} entries × {} registers needs {} words per entry and {} words, \
                 not {} and {}",
                f.depth,
                f.registers,
                words,
                f.depth.saturating_mul(words),
                f.words_per_entry,
                f.data.len()
            ));
        }
        Ok(RomImage {
            depth: f.depth,
            registers: f.registers,
            words_per_entry: f.words_per_entry,
            data: f.data,
        })
    }
}

impl RomImage {
    /// A ROM of all-zero bits (every register subtracts).
    pub fn zeros(depth: usize, registers: usize) -> Self {
        let words_per_entry = registers.div_ceil(64).max(1);
        RomImage {
            depth,
            registers,
            words_per_entry,
            data: vec![0; depth * words_per_entry],
        }
    }

    /// Builds a ROM from a bit function `bit(address, register)`.
    pub fn from_fn(
        depth: usize,
        registers: usize,
        mut bit: impl FnMut(usize, usize) -> bool,
    ) -> Self {
        let mut rom = RomImage::zeros(depth, registers);
        for a in 0..depth {
            for r in 0..registers {
                if bit(a, r) {
                    rom.set_bit(a, r, true);
                }
            }
        }
        rom
    }

    /// A ROM from packed words (`words_per_entry` per address, as [`RomImage::words`]).
    /// Bits at or above `registers` are cleared so equal ROMs compare equal.
    pub fn from_words(depth: usize, registers: usize, mut data: Vec<u64>) -> Self {
        let words_per_entry = registers.div_ceil(64).max(1);
        data.resize(depth * words_per_entry, 0);
        let tail = registers % 64;
        if tail != 0 || registers == 0 {
            let m = if registers == 0 {
                0
            } else {
                (1u64 << tail) - 1
            };
            for e in data.chunks_mut(words_per_entry) {
                e[words_per_entry - 1] &= m;
            }
        }
        RomImage {
            depth,
            registers,
            words_per_entry,
            data,
        }
    }

    /// Number of addresses L.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Bits per address (2·B).
    pub fn registers(&self) -> usize {
        self.registers
    }

    /// u64 words per address.
    pub fn words_per_entry(&self) -> usize {
        self.words_per_entry
    }

    /// The packed entry at `address` (bit r of the entry is bit r % 64 of word r / 64).
    #[inline]
    pub fn entry(&self, address: usize) -> &[u64] {
        let s = address * self.words_per_entry;
        &self.data[s..s + self.words_per_entry]
    }

    /// One bit.
    #[inline]
    pub fn bit(&self, address: usize, register: usize) -> bool {
        (self.entry(address)[register / 64] >> (register % 64)) & 1 == 1
    }

    /// Sets one bit.
    pub fn set_bit(&mut self, address: usize, register: usize, value: bool) {
        let w = &mut self.data[address * self.words_per_entry + register / 64];
        let m = 1u64 << (register % 64);
        if value {
            *w |= m;
        } else {
            *w &= !m;
        }
    }

    /// All packed words, entry after entry.
    pub fn words(&self) -> &[u64] {
        &self.data
    }
}

pub use tofprobe_io::fnv1a64;

/// Writes `bytes` to `path` whole or not at all ([`tofprobe_io::write_atomic`]), with the
/// path in the error.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), DspError> {
    tofprobe_io::write_atomic(path, bytes).map_err(|e| DspError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

impl RomImage {
    /// Hex digits per `$readmemh` line: ceil(registers / 4).
    pub fn hex_digits(&self) -> usize {
        self.registers.div_ceil(4).max(1)
    }

    /// The `$readmemh` text: one line per address, the entry as an unsigned hex number
    /// (register r = bit r, most significant digit first), zero-padded to
    /// [`RomImage::hex_digits`], lowercase, `\n` line ends. Byte-identical for equal ROMs.
    pub fn to_readmemh(&self) -> String {
        let digits = self.hex_digits();
        let mut s = String::with_capacity(self.depth * (digits + 1));
        let hex = b"0123456789abcdef";
        let mut line = vec![0u8; digits];
        for a in 0..self.depth {
            let e = self.entry(a);
            for (d, ch) in line.iter_mut().enumerate() {
                // digit d (from the left) holds bits 4·(digits−1−d) .. +3
                let bit = 4 * (digits - 1 - d);
                let nib = (e[bit / 64] >> (bit % 64)) & 0xf;
                *ch = hex[nib as usize];
            }
            s.push_str(std::str::from_utf8(&line).unwrap_or_default());
            s.push('\n');
        }
        s
    }

    /// Parses `$readmemh` text written by [`RomImage::to_readmemh`] (also accepts upper
    /// case, blank lines and `//` comments). `path` only labels errors.
    pub fn from_readmemh(text: &str, registers: usize, path: &str) -> Result<Self, DspError> {
        let digits = registers.div_ceil(4).max(1);
        let wpe = registers.div_ceil(64).max(1);
        let mut data = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split("//").next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let err = |m: String| DspError::RomFormat {
                path: path.to_string(),
                line: i + 1,
                message: m,
            };
            if line.len() != digits {
                return Err(err(format!(
                    "{} hex digits, expected {digits} for {registers} registers",
                    line.len()
                )));
            }
            let mut entry = vec![0u64; wpe];
            for (d, ch) in line.bytes().enumerate() {
                let nib = (ch as char)
                    .to_digit(16)
                    .ok_or_else(|| err(format!("'{}' is not a hex digit", ch as char)))?
                    as u64;
                let bit = 4 * (digits - 1 - d);
                // Bits of this digit at or above `registers` must be clear.
                let live = registers.saturating_sub(bit).min(4);
                if nib >> live != 0 {
                    return Err(err(format!("bits above register {registers} are set")));
                }
                entry[bit / 64] |= nib << (bit % 64);
            }
            data.extend_from_slice(&entry);
        }
        let depth = data.len() / wpe;
        Ok(RomImage::from_words(depth, registers, data))
    }

    /// FNV-1a 64 of the `$readmemh` text: the hash recorded in the manifest.
    pub fn content_hash(&self) -> u64 {
        fnv1a64(self.to_readmemh().as_bytes())
    }
}

/// The small TOML manifest that travels with a ROM hex file: what the bits mean and how
/// a readout made with them is normalised.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RomManifest {
    /// The hex file, relative to the manifest.
    pub hex_file: String,
    /// FNV-1a 64 of the hex file, as 16 hex digits.
    pub content_hash: String,
    /// ROM depth L (lines of the hex file).
    pub depth: usize,
    /// Bits per entry (2·B).
    pub registers: usize,
    /// "windowed" or "periodic".
    pub mode: String,
    /// Laser pulse rate f_s, Hz.
    pub sample_rate_hz: f64,
    /// Bin indices k (f_k = k·f_s/L).
    pub bin_indices: Vec<u64>,
    /// Bin frequencies, Hz.
    pub bin_frequencies_hz: Vec<f64>,
    pub order: usize,
    pub osr: f64,
    pub h_inf: f64,
    pub optimised_zeros: bool,
    /// The probe convention ("toolbox"); absent for tofprobe's default (docs/probe.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub convention: Option<String>,
    /// Probe amplitude A_p.
    pub amplitude: f64,
    pub window: String,
    /// Window coherent gain G.
    pub coherent_gain: f64,
    /// Largest modulator state mismatch at the periodic wrap (0 for windowed ROMs).
    pub wrap_mismatch: f64,
    /// Worst bitstream's wrap transient in-band energy over its period's in-band error
    /// (0 for windowed ROMs; see `sd::wrap`).
    #[serde(default)]
    pub wrap_error_ratio: f64,
    /// Whether that ratio is within `sd::probe::WRAP_TOLERANCE`.
    #[serde(default)]
    pub wrap_clean: bool,
    /// Periods run after the warm-up to find the cuts (0 for windowed ROMs).
    #[serde(default)]
    pub wrap_periods: usize,
}

impl RomManifest {
    /// Writes `<dir>/<stem>.hex` and `<dir>/<stem>.toml` as one set, whole or absent
    /// (`tofprobe_io::OutputSet`, the manifest last, so a manifest never names a missing
    /// or older file); the manifest's hash is filled in here.
    pub fn write(&self, image: &RomImage, dir: &Path, stem: &str) -> Result<PathBuf, DspError> {
        let hex = image.to_readmemh();
        let mut m = self.clone();
        m.hex_file = format!("{stem}.hex");
        m.content_hash = format!("{:016x}", fnv1a64(hex.as_bytes()));
        m.depth = image.depth();
        m.registers = image.registers();
        let manifest = format!("{stem}.toml");
        let path = dir.join(&manifest);
        let io = |e: &dyn std::fmt::Display| DspError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        let text = toml::to_string(&m).map_err(|e| io(&e))?;
        let mut set = tofprobe_io::OutputSet::begin(dir).map_err(|e| io(&e))?;
        set.add(&m.hex_file, hex.as_bytes()).map_err(|e| io(&e))?;
        set.add(&manifest, text.as_bytes()).map_err(|e| io(&e))?;
        set.commit(Some(&manifest)).map_err(|e| io(&e))?;
        Ok(path)
    }

    /// Reads a manifest and its hex file, checking depth, width and content hash.
    pub fn read(manifest: &Path) -> Result<(RomManifest, RomImage), DspError> {
        let name = manifest.display().to_string();
        let io = |p: &str, e: std::io::Error| DspError::Io {
            path: p.to_string(),
            message: e.to_string(),
        };
        let text = std::fs::read_to_string(manifest).map_err(|e| io(&name, e))?;
        let m: RomManifest = toml::from_str(&text).map_err(|e| DspError::RomFormat {
            path: name.clone(),
            line: 0,
            message: e.to_string(),
        })?;
        let hex_path = manifest.with_file_name(&m.hex_file);
        let hex_name = hex_path.display().to_string();
        let hex = std::fs::read_to_string(&hex_path).map_err(|e| io(&hex_name, e))?;
        let hash = format!("{:016x}", fnv1a64(hex.as_bytes()));
        if hash != m.content_hash {
            return Err(DspError::RomFormat {
                path: hex_name,
                line: 0,
                message: format!(
                    "content hash {hash} does not match the manifest's {}",
                    m.content_hash
                ),
            });
        }
        let image = RomImage::from_readmemh(&hex, m.registers, &hex_name)?;
        if image.depth() != m.depth {
            return Err(DspError::RomFormat {
                path: hex_name,
                line: image.depth(),
                message: format!(
                    "{} entries, the manifest says depth {}",
                    image.depth(),
                    m.depth
                ),
            });
        }
        Ok((m, image))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_across_word_boundaries() {
        // 70 registers span two words per entry; a pattern that differs per address and
        // register catches any packing offset error.
        let f = |a: usize, r: usize| (a * 7 + r * 3) % 5 < 2;
        let rom = RomImage::from_fn(9, 70, f);
        assert_eq!(rom.words_per_entry(), 2);
        for a in 0..9 {
            for r in 0..70 {
                assert_eq!(rom.bit(a, r), f(a, r), "address {a} register {r}");
            }
        }
    }

    #[test]
    fn readmemh_round_trips_and_is_msb_first() {
        // Register 0 and 5 set in entry 0 of a 6-register ROM: 0b100001 = 0x21.
        let mut rom = RomImage::zeros(2, 6);
        rom.set_bit(0, 0, true);
        rom.set_bit(0, 5, true);
        rom.set_bit(1, 3, true);
        assert_eq!(rom.to_readmemh(), "21\n08\n");
        let f = |a: usize, r: usize| (a * 13 + r * 7).is_multiple_of(3);
        let big = RomImage::from_fn(50, 70, f);
        let back = RomImage::from_readmemh(&big.to_readmemh(), 70, "mem").unwrap();
        assert_eq!(back, big);
        let e = RomImage::from_readmemh("21\n8\n", 6, "x.hex")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x.hex: line 2") && e.contains("expected 2"),
            "{e}"
        );
        let e = RomImage::from_readmemh("41\n", 6, "x.hex")
            .unwrap_err()
            .to_string();
        assert!(e.contains("above register 6"), "{e}");
    }

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // Reference values of FNV-1a 64 (Fowler/Noll/Vo test suite).
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn manifest_and_hex_round_trip_and_detect_tampering() {
        let dir = std::env::temp_dir().join(format!("tofprobe-rom-{}", std::process::id()));
        let rom = RomImage::from_fn(33, 10, |a, r| (a + r) % 4 == 1);
        let m = RomManifest {
            hex_file: String::new(),
            content_hash: String::new(),
            depth: 0,
            registers: 0,
            mode: "windowed".into(),
            sample_rate_hz: 10e6,
            bin_indices: vec![1, 2, 3, 4, 5],
            bin_frequencies_hz: vec![1.0, 2.0, 3.0, 4.0, 5.0],
            order: 3,
            osr: 32.0,
            h_inf: 1.5,
            optimised_zeros: false,
            convention: None,
            amplitude: 0.5,
            window: "blackman".into(),
            coherent_gain: 0.42,
            wrap_mismatch: 0.0,
            wrap_error_ratio: 0.0,
            wrap_clean: true,
            wrap_periods: 0,
        };
        let path = m.write(&rom, &dir, "probe").unwrap();
        let first = std::fs::read(dir.join("probe.hex")).unwrap();
        m.write(&rom, &dir, "probe").unwrap();
        assert_eq!(std::fs::read(dir.join("probe.hex")).unwrap(), first);
        let (back_m, back) = RomManifest::read(&path).unwrap();
        assert_eq!(back, rom);
        assert_eq!(back_m.depth, 33);
        assert_eq!(back_m.content_hash, format!("{:016x}", rom.content_hash()));
        let mut tampered = first.clone();
        tampered[0] = if tampered[0] == b'0' { b'1' } else { b'0' };
        std::fs::write(dir.join("probe.hex"), &tampered).unwrap();
        let e = RomManifest::read(&path).unwrap_err().to_string();
        assert!(e.contains("content hash"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
