//! ΣΔ probe design: NTF synthesis, the modulator, probe waveforms and the ROM they fill.

pub mod config;
pub mod fullband;
pub mod fullband_check;
pub mod fullband_spectrum;
pub mod modulator;
pub mod ntf;
pub mod probe;
pub mod probing;
pub mod quality;
pub mod realize;
pub mod simd;
pub mod wrap;

pub use config::{MAX_PERIODIC_ROM_DEPTH, ProbeConfig, ProbeConvention, RomMode};
pub use fullband::FullBandProber;
pub use modulator::Modulator;
pub use ntf::{Ntf, synthesize_ntf};
pub use probe::{ProbeDesign, ProbeRom, nearest_bin};
pub use probing::{
    ProbeAccumulator, amplitudes_um, normalise, prefilter_response, probe_detections,
};
pub use realize::{Cifb, StateSpace, realize_cifb};
pub use simd::{Isa, LanePrecision};
pub use wrap::WrapMetric;

/// |state| above which the modulator is declared unstable (the scalar [`Modulator`] and
/// the lanes of [`simd::lanes`] and [`simd::pairs`] alike).
pub const STATE_BOUND: f64 = 100.0;
