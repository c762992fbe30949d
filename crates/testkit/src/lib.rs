//! Shared helpers of tofprobe's tests, written once (they were written up to five times,
//! and drifted): [`tools`], the gate an EDA test passes before it drives a tool — a skip on
//! a developer's machine, a failure under CI — and [`params`], random valid pixel
//! parameters drawing every knob of `PixelParams` (a new knob is drawn here, once), and
//! [`mutants`], the check that a property test fails on a broken input, and [`data`], the
//! paths of the real records vendored under `third_party/`.
//!
//! A dev-dependency only: no library crate of the workspace depends on it.

pub mod data;
pub mod imports;
pub mod mutants;
pub mod params;
pub mod tools;
