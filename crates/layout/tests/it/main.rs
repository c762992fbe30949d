//! The integration tests of `tofprobe-layout`, one binary (`cargo test --release -p
//! tofprobe-layout --test it MODULE::`).

mod laid_out;
mod routed_factor;
mod spef_sta;
mod tools;
