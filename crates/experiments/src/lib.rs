//! Experiments on a resolved design (`tofprobe_design::ResolvedDesign`): what the pixel and
//! its float references measure of a scene. The bit-true spectrum ([`spectrum`]), the Haar
//! transient analysis ([`transients`], drawn by [`scalogram`]), the fidelity levels a user
//! trades speed for accuracy with ([`level`]: one enum and its registry), the paper reproduction
//! ([`paper`]), the speed/accuracy trade-off of the fidelity levels ([`tradeoff`]), the
//! architecture options' accuracy and area ([`options`]), and the replay of real
//! time-tagged records ([`replay`], through [`records`]). The hardware flow (RTL, vectors,
//! co-simulation, sizing, sign-off) is `tofprobe-flow`, one floor up.

pub mod error;
pub mod level;
pub mod options;
pub mod paper;
pub mod record_bounds;
pub mod records;
pub mod references;
pub mod replay;
pub mod scalogram;
pub mod simulation;
pub mod spectrum;
pub mod tradeoff;
pub mod transients;

pub use error::ExperimentError;
