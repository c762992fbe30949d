//! Shared helpers of tofprobe's tests, written once (they were written up to five times,
//! and drifted): [`tools`], the gate an EDA test passes before it drives a tool — a skip on
//! a developer's machine, a failure under CI — and [`params`], random valid pixel
//! parameters from `tofprobe_pixel::random`'s one generator (a new knob is drawn there, once), and
//! [`mutants`], the check that a property test fails on a broken input, [`data`], the
//! paths of the real records vendored under `third_party/`, and [`imports`], the check that
//! no file of a crate imports a file that imports it back.
//!
//! A dev-dependency only: no library crate of the workspace depends on it.

pub mod data;
pub mod fuzz;
pub mod imports;
pub mod mutants;
pub mod params;
pub mod tools;
