//! The integration tests of `tofprobe-experiments`, linked into one binary: the library's
//! entries tested through the library (the binary's tests in crates/cli test what users
//! run). Run one module with `cargo test --release -p tofprobe-experiments --test it MODULE::`.

mod common;
mod extremes;
mod haar_figures;
mod imputation;
mod levels;
mod scalogram_figures;
mod simulation;
mod study;
mod transients;
