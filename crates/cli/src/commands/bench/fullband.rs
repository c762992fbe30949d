//! `tofprobe bench fullband [CONFIG] [--json] [--svg FILE] [--max-hz 20000] [--step-hz 1]
//! [--precision f64|f32] [--path auto|baseline|avx2|avx512] [--periodic] [--pulses N]`: the
//! Fig. 8 scene's full-band spectrum (`tofprobe_bench::fullband` measures; this shows the
//! progress bar and prints).

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use tofprobe_bench::fullband::{BandOut, FullBandOptions, FullBandReport};
use tofprobe_dsp::sd::{Isa, LanePrecision};

use crate::error::CliError;

/// Arguments of `tofprobe bench fullband`.
#[derive(Debug, Args)]
pub struct FullBandArgs {
    /// Configuration file (TOML); without it the embedded default (paper Fig. 8).
    config: Option<PathBuf>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// Write both spectra (ΣΔ and DFT, µm vs Hz) as SVG to this path.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Highest probed frequency, Hz (below f_s/(2·OSR)).
    #[arg(long, default_value_t = 20_000.0)]
    max_hz: f64,
    /// Bin spacing, Hz (rounded to a multiple of f_s/N).
    #[arg(long, default_value_t = 1.0)]
    step_hz: f64,
    /// Modulator lane arithmetic: f64 (bit-exact with the scalar modulator) or f32.
    #[arg(long, default_value = "f64", value_parser = ["f64", "f32"])]
    precision: String,
    /// Instruction path of the lanes: auto (the workspace's ISA: TOFPROBE_ISA, else the
    /// fastest this CPU runs), scalar (x86-64, SSE2), avx2 or avx512. Every path gives the
    /// same sums, bit for bit.
    #[arg(long, default_value = "auto", value_parser = ["auto", "scalar", "avx2", "avx512"])]
    path: String,
    /// Also read every in-band bin of the periodic ROM (L from `[probe]`).
    #[arg(long)]
    periodic: bool,
    /// Frame length override (default: the configuration's pulses).
    #[arg(long)]
    pulses: Option<u64>,
}

/// Runs the benchmark.
pub fn run(args: &FullBandArgs) -> Result<(), CliError> {
    let loaded = crate::commands::load_design(args.config.as_deref())?;
    loaded.single_pixel("bench fullband")?;
    let precision = match args.precision.as_str() {
        "f32" => LanePrecision::F32,
        _ => LanePrecision::F64,
    };
    let path = match args.path.as_str() {
        "auto" => Isa::current(),
        name => Isa::parse(name, "--path").map_err(|e| {
            let runs: Vec<&str> = Isa::supported().iter().map(|p| p.name()).collect();
            CliError::option(
                "path",
                &args.path,
                format!("auto or {} ({})", runs.join(", "), e.reason),
            )
        })?,
    };
    let pulses = args.pulses.unwrap_or_else(|| loaded.document.pulses());
    let bar = ProgressBar::with_draw_target(Some(pulses), ProgressDrawTarget::hidden());
    if !args.json && std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} pulses ({eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    let opts = FullBandOptions {
        max_hz: args.max_hz,
        step_hz: args.step_hz,
        precision,
        path,
        periodic: args.periodic,
        pulses: args.pulses,
        svg: args.svg.as_deref(),
    };
    let report = tofprobe_bench::fullband::measure(&loaded, &opts, |n| bar.set_position(n));
    bar.finish_and_clear();
    let report = report?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_band(name: &str, b: &BandOut) {
    println!(
        "{name}: {} bins of {:.3} Hz up to {:.0} Hz",
        b.bins, b.bin_hz, b.max_hz
    );
    if b.steps > 0 {
        println!(
            "  sigma-delta {:.2} s ({:.3e} modulator steps/s), DFT {:.2} s",
            b.sd_seconds, b.steps_per_s, b.dft_seconds
        );
    } else {
        println!(
            "  sigma-delta {:.2} s (ROM generation, fold and correlate), DFT {:.2} s",
            b.sd_seconds, b.dft_seconds
        );
    }
    println!(
        "  peak {:.1} Hz: sigma-delta {:.2} um, DFT {:.2} um",
        b.peak_hz, b.peak_sd_um, b.peak_dft_um
    );
    println!(
        "  noise floor: sigma-delta {:.3} um, DFT {:.3} um (ratio {:.4}); error |SD - DFT| {:.3} um = {:.3} x floor",
        b.noise_sd_um, b.noise_dft_um, b.noise_ratio, b.error_um, b.error_over_floor
    );
}

fn print_text(r: &FullBandReport) {
    println!(
        "full-band sigma-delta spectrum of {} (N = {}, {} lanes on the {} path, {} per group, {} threads; record {:.2} s)",
        r.configuration,
        r.pulses,
        r.precision,
        r.path,
        r.lanes_per_group,
        r.threads,
        r.record_seconds
    );
    print_band("windowed frame", &r.windowed);
    if let (Some(c), Some(s)) = (r.windowed_sd_cpu_seconds, r.steps_per_cpu_second) {
        println!(
            "  CPU time {c:.1} s ({s:.3e} steps per CPU-second); {:.3e} steps/s per core of wall time",
            r.steps_per_s_per_core
        );
    }
    println!(
        "  scalar reference loop {:.3e} steps/s on one core: the prober is {:.1}x per core",
        r.scalar_reference_steps_per_s_per_core, r.speedup_vs_scalar
    );
    print!(
        "  the full band (20,001 bins, N = 10^7) at this rate: {:.0} s",
        r.full_band_seconds_at_this_rate
    );
    match r.full_band_seconds_idle {
        Some(s) => println!(", on {} idle cores {s:.0} s", r.threads),
        None => println!(),
    }
    println!(
        "  target: the full band <= {:.0} s, judged on CPU time over {} threads ({:.1} s; this run's wall {:.1} s): {}",
        r.target_seconds,
        r.threads,
        r.judged_seconds,
        r.windowed.sd_seconds,
        if r.pass { "pass" } else { "FAIL" }
    );
    if let Some(p) = &r.periodic {
        print_band("periodic ROM", p);
    }
    if let Some(p) = &r.svg {
        println!("  spectra: {p}");
    }
}
