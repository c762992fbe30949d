//! The integration tests of `tofprobe-rtlgen`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-rtlgen --test it MODULE::`.

mod accepted_render;
mod array_gates;
mod array_scale;
mod array_vectors;
mod gates;
mod render;
mod superpixel;
