//! The integration tests of `tofprobe-scene`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-scene --test it MODULE::`.

mod common;
mod determinism;
mod ks;
mod mixture;
mod motion;
mod pileup;
mod tdc;
mod tttr;
mod tttr_crosscheck;
mod validation;
