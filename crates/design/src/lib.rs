//! The configuration document and its ONE resolution: [`Document`] (the TOML file or the
//! embedded default) → [`resolve()`] → [`ResolvedDesign`] (scene, sensor, pixel parameters
//! and widths, Fourier bins, the stability-checked ΣΔ probe design). Every `tofprobe`
//! command starts from a `ResolvedDesign`. Also the bin chooser ([`bin_choice`]), the chip the RTL
//! commands build ([`chip`]: array shape, the broadcast probe ROM by the ROM policy
//! [`rom_policy`], the sequencer) and `adders = "auto"`'s pure choice ([`adders`]).

pub mod adders;
pub mod array;
pub mod bin_choice;
pub mod chip;
pub mod document;
pub mod error;
pub mod mode_decision;
pub mod overrides;
pub mod probe_cache;
mod rate_image;
pub mod readout;
pub mod resolve;
pub mod rom_policy;

pub use adders::{AdderChoice, AdderStatus, AdderTiming, CandidateTiming};
pub use array::{ArrayConfig, ArrayLevel, RateMap, SensorArray, pixel_seed};
pub use chip::{Chip, RomPurpose, SequencerKind};
pub use document::{Document, SIZING_SIGMAS, read_text, schema};
pub use error::DesignError;
pub use mode_decision::ModeDecision;
pub use probe_cache::ProbeCache;
pub use readout::{Readout, ReadoutKeys};
pub use resolve::{ResolvedDesign, load, resolve, resolve_timed, resolve_with};
pub use rom_policy::{RtlOverrides, RtlRom, rtl_params};

/// The embedded default configuration text (paper Fig. 8: 0.1 mm at 4.5 kHz on 30 mm,
/// σ_I = 50 ps, ρ_s = 1, ρ_b = 0, 1 s at 10 MHz).
pub const DEFAULT_TOML: &str = include_str!("../../../scenes/default.toml");

/// Name used in messages for the embedded default.
pub const DEFAULT_ORIGIN: &str = "<embedded default>";
