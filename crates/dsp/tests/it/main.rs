//! The integration tests of `tofprobe-dsp`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-dsp --test it MODULE::`.

mod fullband_isa;
mod haar_noise;
mod probe_convention;
