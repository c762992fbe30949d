//! The integration tests of `tofprobe-layout`, one binary (`cargo test --release -p
//! tofprobe-layout --test it MODULE::`).

mod routed_factor;
mod spef_sta;
