//! The integration tests of `tofprobe-array`, one binary
//! (`cargo test --release -p tofprobe-array --test it MODULE::`).

mod auto;
mod common;
mod determinism;
mod double_buffer;
mod rtl;
mod set_size;
mod shard;
mod statistical;
mod superpixel;
mod validation;
