//! The integration tests of `tofprobe-eda`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-eda --test it MODULE::`.

mod array_timing;
mod generated;
mod report;
mod signoff;
mod synthesis;
mod tools;
