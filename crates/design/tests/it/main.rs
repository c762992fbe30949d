//! The integration tests of `tofprobe-design`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-design --test it MODULE::`.

mod level;
mod mutations;
mod readout;
mod resolve;
mod schema_keys;
mod serde_roundtrip;
