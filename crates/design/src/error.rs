//! `DesignError`: every way a configuration document fails to load or resolve. Each message
//! names the file, the section and key, the value, the allowed range and a value that works.

use std::path::PathBuf;

use thiserror::Error;

/// The one error type of the design crate.
#[derive(Debug, Error)]
pub enum DesignError {
    /// The configuration file does not exist or cannot be read.
    #[error("cannot read configuration `{path}`: {source}")]
    Read {
        /// The path as given.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The configuration path is a directory.
    #[error("configuration `{path}` is a directory; expected a TOML file")]
    IsDirectory {
        /// The path as given.
        path: PathBuf,
    },
    /// The configuration file is not valid UTF-8.
    #[error(
        "configuration `{path}` is not valid UTF-8 (first invalid byte at offset {offset}); \
         TOML files must be UTF-8"
    )]
    NotUtf8 {
        /// The path as given.
        path: PathBuf,
        /// Byte offset of the first invalid sequence.
        offset: usize,
    },
    /// TOML syntax error or a key/value that does not fit the schema (the message of the
    /// toml crate carries the line and column).
    #[error("in configuration `{origin}`: {message}")]
    Toml {
        /// The file name, or `<embedded default>`.
        origin: String,
        /// The parser's message, with line, column and the offending snippet.
        message: String,
    },
    /// A value out of range or inconsistent with another one.
    #[error("in configuration `{origin}`: {source}")]
    Scene {
        /// The file name, or `<embedded default>`.
        origin: Box<str>,
        /// What is wrong.
        source: tofprobe_scene::SceneError,
    },
    /// The `[pixel]` section cannot be built (the message names the key, the reason and
    /// the nearest valid value).
    #[error("in configuration `{origin}`: [pixel]: {source}")]
    Pixel {
        /// The file name, or `<embedded default>`.
        origin: Box<str>,
        /// What is wrong.
        source: tofprobe_pixel::PixelError,
    },
    /// The `[probe]` section or the probe ROM cannot be built.
    #[error("in configuration `{origin}`: [probe]: {source}")]
    Probe {
        /// The file name, or `<embedded default>`.
        origin: Box<str>,
        /// What is wrong.
        source: tofprobe_dsp::DspError,
    },
    /// A Haar frame the pixel cannot run (N not a power of two, U too fine); `place` names
    /// the file, the mode's origin and the field N or U came from.
    #[error("in configuration {place}: {source}")]
    Haar {
        /// "`file`: \[pixel\] Haar mode …, N from acquisition.pulses" and the like.
        place: String,
        /// What is wrong (names the nearest powers of two or the largest U).
        source: Box<tofprobe_dsp::DspError>,
    },
    /// The `[array]` section (shape, mapping, rate maps) is invalid, or the command does
    /// not run arrays.
    #[error("in configuration `{origin}`: {message}")]
    Array {
        /// The file name, or `<embedded default>`.
        origin: Box<str>,
        /// The field, the value, the allowed range and a value that works.
        message: String,
    },
    /// The generator refuses the parameters of the chip ROM policy.
    #[error("{0}")]
    Rtl(#[from] tofprobe_rtlgen::RtlError),
}

impl DesignError {
    /// An `[array]` error of the document `origin`.
    pub fn array(origin: &str, message: impl Into<String>) -> Self {
        DesignError::Array {
            origin: origin.into(),
            message: message.into(),
        }
    }

    /// A `[pixel]` error of the document `origin`.
    pub fn pixel(origin: &str, source: tofprobe_pixel::PixelError) -> Self {
        DesignError::Pixel {
            // Boxed: keeps the error (and every Result carrying it) under 128 bytes.
            origin: origin.into(),
            source,
        }
    }

    /// A `[probe]` error of the document `origin`.
    pub fn probe(origin: &str, source: tofprobe_dsp::DspError) -> Self {
        DesignError::Probe {
            // Boxed: keeps the error (and every Result carrying it) under 128 bytes.
            origin: origin.into(),
            source,
        }
    }

    /// A scene/sensor/acquisition error of the document `origin`.
    pub fn scene(origin: &str, source: tofprobe_scene::SceneError) -> Self {
        DesignError::Scene {
            // Boxed: keeps the error (and every Result carrying it) under 128 bytes.
            origin: origin.into(),
            source,
        }
    }
}
