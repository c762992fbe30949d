//! The crate's one error type: every message names the field, the value, the allowed range
//! and, where one exists, a value that would work.

use std::path::PathBuf;

/// Errors of configuration validation, rendering and file writing.
#[derive(Debug, thiserror::Error)]
pub enum RtlError {
    /// Parameters the pixel does not accept (the one validation, tofprobe-pixel's), or
    /// stimuli and a ROM that do not fit them.
    #[error(transparent)]
    Pixel(#[from] tofprobe_pixel::PixelError),
    /// An identifier taken from the configuration is not a safe Verilog identifier.
    #[error(
        "{field} = {value:?} is not a safe Verilog identifier: allowed [a-z][a-z0-9_]{{0,31}}, not a keyword (e.g. \"tofprobe\")"
    )]
    Identifier { field: &'static str, value: String },
    /// A path given for the FuseSoC core cannot stand in it unquoted.
    #[error(
        "{field} = {value:?} cannot go into the FuseSoC core: allowed a relative path of [A-Za-z0-9._+-] and `/`, not starting with `-` or `/`, at most 200 characters (e.g. \"../vectors\")"
    )]
    CorePath { field: &'static str, value: String },
    /// A template failed to render.
    #[error("template {template} failed to render: {message}")]
    Render {
        template: &'static str,
        message: String,
    },
    /// Refusing to overwrite a file this generator did not write.
    #[error(
        "refusing to overwrite {path}: it does not start with the tofprobe-rtlgen header (move it away or choose another --out)"
    )]
    Foreign { path: PathBuf },
    /// The ROM image has the wrong shape.
    #[error("ROM image has {value} {field}; the configuration needs {allowed}")]
    Rom {
        field: &'static str,
        value: usize,
        allowed: usize,
    },
    /// The array's shape or readout cannot be rendered.
    #[error("{field} = {value} cannot be rendered: allowed {allowed}")]
    Array {
        field: &'static str,
        value: String,
        allowed: String,
    },
    /// A vector or RTL file is malformed.
    #[error("{path}: line {line}: {message}")]
    Format {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// File-system error, with the path.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl RtlError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        RtlError::Io {
            path: path.into(),
            source,
        }
    }
}
