//! `tofprobe bench <target> [--json]`: speed measurements, one file per target. To add a
//! target, add a variant to [`BenchTarget`] and a line to [`run`].

pub mod array;
pub mod cosim_array;
pub mod dsp;
pub mod fullband;
pub mod pixel;
pub mod scene;
pub mod sd;

use clap::{Args, Subcommand};

use crate::error::CliError;

/// Arguments of `tofprobe bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    target: BenchTarget,
}

/// What to benchmark.
#[derive(Debug, Subcommand)]
pub enum BenchTarget {
    /// The array model: pixel-pulses/s of a 64 × 64 array at N = 10^6 and 10^7 on all
    /// cores beside the single-pixel Monte Carlo alone, and peak memory.
    Array(array::ArrayBenchArgs),
    /// The whole array co-simulated under Verilator: each layout (every pixel inlined, the
    /// pixel one hierarchical block) built cold, build and run times side by side.
    CosimArray(cosim_array::CosimArrayBenchArgs),
    /// Photon/TDC Monte Carlo throughput (pulses/s, one thread) at (ρ_s, ρ_b) = (1, 0) and
    /// (0.3, 0.3).
    Scene(scene::SceneBenchArgs),
    /// Float references: 10^7-point FFT, one Table 2 row, selected-bin DFT vs FFT.
    Dsp(dsp::DspBenchArgs),
    /// Bit-true pixel: transaction model pulses/s on a 10^7-pulse B = 16 frame (target
    /// ≤ 0.1 s), cycle model cycles/s.
    Pixel(pixel::PixelBenchArgs),
    /// ΣΔ probes: stability limits, SNR vs eq. 4 (orders 1–4, OSR 8–128), a 16-bin
    /// N = 10^7 ROM's generation time (target ≤ 1 s), `--svg` the 50 kHz probe spectrum.
    Sd(sd::SdBenchArgs),
    /// The Fig. 8 scene's full-band spectrum: ΣΔ probing of every 1 Hz bin of 0–20 kHz
    /// (N = 10^7) beside the DFT of the same record (target ≤ 300 s); `--periodic` also
    /// the periodic ROM's whole band.
    Fullband(fullband::FullBandArgs),
}

/// Runs one benchmark.
pub fn run(args: BenchArgs) -> Result<(), CliError> {
    match args.target {
        BenchTarget::Array(a) => array::run(&a),
        BenchTarget::CosimArray(a) => cosim_array::run(&a),
        BenchTarget::Scene(a) => scene::run(&a),
        BenchTarget::Dsp(a) => dsp::run(&a),
        BenchTarget::Pixel(a) => pixel::run(&a),
        BenchTarget::Sd(a) => sd::run(&a),
        BenchTarget::Fullband(a) => fullband::run(&a),
    }
}
