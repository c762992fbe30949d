//! Scene motion δ(t) and the photon/TDC Monte Carlo of a SPAD direct time-of-flight pixel.
//!
//! The crate turns a validated configuration (`[sensor]`, `[scene]`, `[acquisition]`) into
//! a deterministic stream of per-pulse detections: `Some(code)` is the TDC code of the first
//! photon inside the timing window, counted from the window start; `None` is a pulse with
//! no detection. See [`PhotonSource`] for the exact Monte Carlo semantics.

mod acquisition;
mod batch;
mod depths;
mod error;
mod lanes;
mod ln;
mod motion;
mod scene;
mod sensor;
mod source;
pub mod spatial;
pub mod splitmix;
pub mod tttr;
mod ziggurat;

pub use acquisition::AcquisitionConfig;
pub use batch::{NO_DETECTION, Slot};
pub use error::SceneError;
pub use motion::MotionConfig;
pub use scene::{Scene, SceneConfig};
pub use sensor::SensorConfig;
pub use source::{BLOCK_PULSES, FillCounts, PhotonSource, check_scene};
pub use splitmix::SplitMix64;

/// Depth per picosecond of time of flight, round trip: 1 ps ↔ 0.15 mm (c/2 = 0.15 mm/ps),
/// the paper's convention. Depth → time is `t_ps = depth_mm / MM_PER_PS`.
pub const MM_PER_PS: f64 = 0.15;
