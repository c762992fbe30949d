//! Shared helpers of the integration tests: the workspace's one generator of random valid
//! parameters (`tofprobe_testkit::params`: a tiny deterministic generator, so a case is
//! reproducible from its seed, and parameters drawing every knob).

#![allow(dead_code)]

pub use tofprobe_testkit::params::{Rng, random_detection, random_params, random_rom};
