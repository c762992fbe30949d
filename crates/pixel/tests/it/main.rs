//! The integration tests of `tofprobe-pixel`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-pixel --test it MODULE::`.

mod common;
mod directed;
mod equivalence;
mod float_sd;
mod fold;
mod haar;
mod lanes;
mod numerics;
mod refusal;
mod register_frac_bits;
mod segments;
mod sequencer;
mod sizing;
mod superpixel;
mod valid_codes;
