//! The `tofprobe` command.
fn main() {}
