//! What a configuration is called in generated files: Verilog module names from a safe
//! prefix, the configuration hash in every header and manifest, and Verilog vector widths.

use serde::Serialize;
use tofprobe_pixel::PixelParams;

use crate::error::RtlError;

/// Prefix of every generated Verilog module name unless [`crate::RenderOptions`] says
/// otherwise.
pub const DEFAULT_MODULE_PREFIX: &str = "tofprobe";

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

/// Names of the pixel, probe ROM and top modules (and files) for a module prefix.
pub fn module_names(prefix: &str) -> (String, String, String) {
    (
        format!("{prefix}_pixel"),
        format!("{prefix}_probe_rom"),
        format!("{prefix}_top"),
    )
}

/// The chip's one sequencer module (`templates/sequencer.v`) for a module prefix: the
/// single pixel's top and the array instantiate it.
pub fn sequencer_module_name(prefix: &str) -> String {
    format!("{prefix}_sequencer")
}

/// ceil(log2(n)) with a minimum of 1 bit (a Verilog vector needs at least one bit).
pub fn clog2(n: u64) -> u32 {
    if n <= 2 {
        1
    } else {
        64 - (n - 1).leading_zeros()
    }
}

/// A stable 64-bit FNV-1a hash of the canonical TOML form of the parameters and the
/// module prefix: names the configuration in generated headers and vector manifests.
pub fn config_hash_with_prefix(p: &PixelParams, module_prefix: &str) -> String {
    /// The canonical form: the `[pixel]` fields in their order, then the prefix.
    #[derive(Serialize)]
    struct Canonical<'a> {
        #[serde(flatten)]
        params: &'a PixelParams,
        module_prefix: &'a str,
    }
    let canonical = toml::to_string(&Canonical {
        params: p,
        module_prefix,
    })
    .unwrap_or_default();
    format!("{:016x}", tofprobe_io::fnv1a64(canonical.as_bytes()))
}

/// [`config_hash_with_prefix`] with the default module prefix (what the vectors, `tofprobe
/// rtl` and the co-simulation render).
pub fn config_hash(p: &PixelParams) -> String {
    config_hash_with_prefix(p, DEFAULT_MODULE_PREFIX)
}
