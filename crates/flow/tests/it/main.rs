//! The flow crate's integration tests: one binary, a module per file.

mod array_spec;
mod array_stimulus;
mod command;
