//! The validated `[pixel]` configuration the RTL is rendered from. It mirrors the pixel
//! crate's `PixelParams` field for field (docs/pixel-contract.md, "Parameters") so that a
//! configuration file means the same thing to the model and to the generator.

use crate::error::RtlError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Accumulation mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// I/Q registers driven by the probe ROM.
    Fourier,
    /// Haar wavelet signs from the pulse counter.
    Haar,
}

/// `[pixel]`: see the contract's parameter table for each field's meaning.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PixelParams {
    pub mode: Mode,
    /// B: Fourier bins.
    pub bins: usize,
    /// U: finest Haar scale.
    pub haar_scales: u32,
    /// A: adders.
    pub adders: usize,
    /// C: clock cycles per laser pulse.
    pub cycles_per_pulse: usize,
    /// T: TDC width.
    pub tdc_bits: u32,
    /// Z: zoom (window start in TDC codes).
    pub zoom: u32,
    /// S: prefilter shift.
    pub shift: u32,
    /// F: prefilter fraction bits.
    pub frac_bits: u32,
    /// W: register width.
    pub width: u32,
    /// N: pulses per frame.
    pub frame_pulses: u64,
    /// L: probe ROM depth.
    pub rom_depth: usize,
    /// Prefix of every generated Verilog module name.
    #[serde(default = "default_prefix")]
    pub module_prefix: String,
}

fn default_prefix() -> String {
    "tofprobe".to_string()
}

impl Default for PixelParams {
    /// The paper's operating point: 16 bins, one adder per I/Q lane, 16 cycles per pulse,
    /// a 1 s frame at 10 MHz, α = 1/32.
    fn default() -> Self {
        PixelParams {
            mode: Mode::Fourier,
            bins: 16,
            haar_scales: 4,
            adders: 2,
            cycles_per_pulse: 16,
            tdc_bits: 8,
            zoom: 0,
            shift: 5,
            frac_bits: 6,
            width: 40,
            frame_pulses: 10_000_000,
            rom_depth: 4096,
            module_prefix: default_prefix(),
        }
    }
}

/// Verilog-2005 keywords that a module prefix must not collide with.
const KEYWORDS: &[&str] = &[
    "always",
    "and",
    "assign",
    "begin",
    "buf",
    "case",
    "casex",
    "casez",
    "cell",
    "config",
    "default",
    "defparam",
    "design",
    "disable",
    "edge",
    "else",
    "end",
    "endcase",
    "endconfig",
    "endfunction",
    "endgenerate",
    "endmodule",
    "endtask",
    "event",
    "for",
    "force",
    "forever",
    "fork",
    "function",
    "generate",
    "genvar",
    "if",
    "initial",
    "inout",
    "input",
    "integer",
    "join",
    "localparam",
    "module",
    "nand",
    "negedge",
    "nor",
    "not",
    "or",
    "output",
    "parameter",
    "posedge",
    "reg",
    "repeat",
    "signed",
    "specify",
    "task",
    "time",
    "tri",
    "wait",
    "while",
    "wire",
    "xor",
    "xnor",
];

fn range(field: &'static str, value: impl ToString, allowed: String, hint: String) -> RtlError {
    RtlError::Range {
        field,
        value: value.to_string(),
        allowed,
        hint,
    }
}

/// ceil(log2(n)) with a minimum of 1 bit (a Verilog vector needs at least one bit).
pub fn clog2(n: u64) -> u32 {
    if n <= 2 {
        1
    } else {
        64 - (n - 1).leading_zeros()
    }
}

impl PixelParams {
    /// Reads `[pixel]` from a TOML file (other tables are ignored: they belong to other
    /// crates).
    pub fn from_toml_file(path: &Path) -> Result<Self, RtlError> {
        let text = std::fs::read_to_string(path).map_err(|e| RtlError::io(path, e))?;
        Self::from_toml_str(&text).map_err(|e| match e {
            RtlError::Parse { message, .. } => RtlError::Parse {
                path: path.to_path_buf(),
                message,
            },
            other => other,
        })
    }

    /// Parses `[pixel]` from TOML text and validates it.
    pub fn from_toml_str(text: &str) -> Result<Self, RtlError> {
        #[derive(Deserialize)]
        struct File {
            pixel: Option<toml::Value>,
        }
        let parse = |message: String| RtlError::Parse {
            path: "<config>".into(),
            message,
        };
        let file: File = toml::from_str(text).map_err(|e| parse(e.to_string()))?;
        let p: PixelParams = match file.pixel {
            Some(v) => v
                .try_into()
                .map_err(|e: toml::de::Error| parse(e.to_string()))?,
            None => PixelParams::default(),
        };
        p.validate()?;
        Ok(p)
    }

    /// R: registers.
    pub fn registers(&self) -> usize {
        match self.mode {
            Mode::Fourier => 2 * self.bins,
            Mode::Haar => (1usize << (self.haar_scales + 1)) - 1,
        }
    }

    /// P: operations per pulse.
    pub fn ops_per_pulse(&self) -> usize {
        match self.mode {
            Mode::Fourier => self.registers(),
            Mode::Haar => self.haar_scales as usize + 1,
        }
    }

    /// K: schedule slots per pulse.
    pub fn slots(&self) -> usize {
        self.ops_per_pulse().div_ceil(self.adders.max(1))
    }

    /// Effective fraction bits (Haar has no prefilter).
    pub fn effective_frac_bits(&self) -> u32 {
        match self.mode {
            Mode::Fourier => self.frac_bits,
            Mode::Haar => 0,
        }
    }

    /// Width of one operand: T+1+F (Fourier), T+1 (Haar).
    pub fn operand_bits(&self) -> u32 {
        self.tdc_bits + 1 + self.effective_frac_bits()
    }

    /// Width of `rd_index`: ceil(log2(R+2)).
    pub fn rd_index_bits(&self) -> u32 {
        clog2(self.registers() as u64 + 2)
    }

    /// log2 N (Haar).
    pub fn log2_frame(&self) -> u32 {
        self.frame_pulses.trailing_zeros()
    }

    /// Checks every contract constraint, naming the field and a value that would work.
    pub fn validate(&self) -> Result<(), RtlError> {
        let p = self;
        if !(1..=16).contains(&p.tdc_bits) {
            return Err(range(
                "tdc_bits",
                p.tdc_bits,
                "1..=16".into(),
                String::new(),
            ));
        }
        if u64::from(p.zoom) >= 1u64 << p.tdc_bits {
            return Err(range(
                "zoom",
                p.zoom,
                format!("0..{} (2^tdc_bits)", 1u64 << p.tdc_bits),
                String::new(),
            ));
        }
        if p.frame_pulses < 1 {
            return Err(range("frame_pulses", 0, "≥ 1".into(), String::new()));
        }
        match p.mode {
            Mode::Fourier => {
                // A 32-bit ROM address (Haar mode has no ROM).
                if p.rom_depth < 1 || p.rom_depth > 1 << 32 {
                    return Err(range(
                        "rom_depth",
                        p.rom_depth,
                        "1..=4294967296".into(),
                        String::new(),
                    ));
                }
                if p.bins < 1 || p.bins > 512 {
                    return Err(range("bins", p.bins, "1..=512".into(), String::new()));
                }
                if p.shift > 15 {
                    return Err(range("shift", p.shift, "0..=15".into(), String::new()));
                }
                if p.frac_bits > 16 {
                    return Err(range(
                        "frac_bits",
                        p.frac_bits,
                        "0..=16".into(),
                        String::new(),
                    ));
                }
            }
            Mode::Haar => {
                if !p.frame_pulses.is_power_of_two() || p.frame_pulses < 2 {
                    return Err(range(
                        "frame_pulses",
                        p.frame_pulses,
                        "a power of two ≥ 2 in Haar mode".into(),
                        format!(" (e.g. {})", p.frame_pulses.max(2).next_power_of_two()),
                    ));
                }
                if p.haar_scales + 1 > p.log2_frame() || p.haar_scales > 9 {
                    return Err(range(
                        "haar_scales",
                        p.haar_scales,
                        format!(
                            "0..={} (log2(frame_pulses) − 1, at most 9)",
                            (p.log2_frame() - 1).min(9)
                        ),
                        String::new(),
                    ));
                }
            }
        }
        let ops = p.ops_per_pulse();
        if p.adders < 1 || p.adders > ops {
            return Err(range(
                "adders",
                p.adders,
                format!("1..={ops} (operations per pulse)"),
                String::new(),
            ));
        }
        if p.cycles_per_pulse < p.slots() {
            return Err(range(
                "cycles_per_pulse",
                p.cycles_per_pulse,
                format!("≥ {} (schedule slots ceil(P/A))", p.slots()),
                format!(" (minimum {})", p.slots()),
            ));
        }
        if p.cycles_per_pulse > 1 << 16 {
            return Err(range(
                "cycles_per_pulse",
                p.cycles_per_pulse,
                "≤ 65536".into(),
                String::new(),
            ));
        }
        let opw = p.operand_bits();
        if p.width < opw || p.width > 63 {
            return Err(range(
                "width",
                p.width,
                format!("{opw}..=63 (one operand is T+1+F = {opw} bits)"),
                format!(" (e.g. {})", opw.clamp(32, 63)),
            ));
        }
        validate_identifier("module_prefix", &p.module_prefix)?;
        Ok(())
    }

    /// A stable 64-bit FNV-1a hash of the canonical TOML form: names the configuration in
    /// generated headers and vector manifests.
    pub fn config_hash(&self) -> String {
        let canonical = toml::to_string(self).unwrap_or_default();
        format!("{:016x}", fnv1a64(canonical.as_bytes()))
    }
}

/// Accepts `[a-z][a-z0-9_]{0,31}` that is not a Verilog keyword: nothing taken from a
/// configuration can inject Verilog into a rendered file.
pub fn validate_identifier(field: &'static str, value: &str) -> Result<(), RtlError> {
    let bytes = value.as_bytes();
    let ok = !bytes.is_empty()
        && bytes.len() <= 32
        && bytes[0].is_ascii_lowercase()
        && bytes
            .iter()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || *b == b'_')
        && !KEYWORDS.contains(&value);
    if ok {
        Ok(())
    } else {
        Err(RtlError::Identifier {
            field,
            value: value.to_string(),
        })
    }
}

/// FNV-1a, 64 bits: a dependency-free content hash for headers, manifests and caches.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
