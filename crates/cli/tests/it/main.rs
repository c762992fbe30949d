//! The integration tests of `tofprobe-cli`, linked into one binary (a binary per file
//! cost a link each: most of a cold CI run's build time). Run one module with
//! `cargo test --release -p tofprobe-cli --test it MODULE::`.

mod adders_auto;
mod array;
mod array_memory;
mod array_rtl;
mod array_sets;
mod array_size;
mod bench_fullband;
mod bench_sd;
mod bit_true;
mod blame;
mod bounds;
mod cli;
mod committed;
mod common;
mod concurrency;
mod core;
mod cosim_directed;
mod cosim_exact;
mod docs_tables;
mod exit_codes;
mod extremes;
mod finite_json;
mod flow;
mod fuzz_binary;
mod fuzz_records;
mod haar;
mod junit;
mod layout;
mod one_resolution;
mod options;
mod output_sets;
mod prefilter_rounding;
mod probe_convention;
mod register_file;
mod register_frac_bits;
mod reliability;
mod replay;
mod reproduce;
mod resolution;
mod shard;
mod signals;
mod size;
mod tile_option;
mod tradeoff;
