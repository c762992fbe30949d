//! The integration tests of `tofprobe-layout`, one binary (`cargo test --release -p
//! tofprobe-layout --test it MODULE::`).

mod spef_sta;
