//! The integration tests of `tofprobe-cosim`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-cosim --test it MODULE::`.

mod committed;
mod common;
mod cosim_default;
mod cosim_random;
mod coverage;
mod directed;
mod exact;
mod icarus_default;
mod mutations;
mod sd_rom;
mod stimulus;
