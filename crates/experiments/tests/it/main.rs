//! The integration tests of `tofprobe-experiments`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-experiments --test it MODULE::`.

mod scalogram_figures;
