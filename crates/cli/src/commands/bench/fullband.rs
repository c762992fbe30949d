//! `tofprobe bench fullband [CONFIG] [--json] [--svg FILE] [--max-hz 20000] [--step-hz 1]
//! [--precision f64|f32] [--path auto|baseline|avx2] [--periodic] [--pulses N]`: the
//! Fig. 8 scene's full-band spectrum (issue 20 item 4). ΣΔ probing of every bin of
//! 0..max-hz on the step-hz grid (windowed frame, the `[probe]` design with its window)
//! beside the float DFT of the same prefiltered record, timed, with the instruction path
//! that ran and the rate against the scalar reference loop measured in the same run; with
//! `--periodic` also every in-band bin of the chip's periodic ROM (L from `[probe]`, 500 Hz
//! bins at the default). Target: 0–20 kHz at 1 Hz (20,001 bins, N = 10^7, 4·10^11
//! modulator steps) in ≤ 300 s; a shorter run prints the time the full band would take at
//! its rate.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use tofprobe_dsp::sd::fullband_spectrum::{
    BandSpectrum, BandSummary, periodic_band, prefiltered_record, windowed_band,
};
use tofprobe_dsp::sd::{KernelPath, LanePrecision, ProbeDesign, RomMode};

use super::lane_rates::{scalar_reference_rate, speed_record};
use super::sd::process_cpu_seconds;
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
    /// Instruction path of the lanes: auto (the fastest this CPU runs), baseline (x86-64,
    /// SSE2) or avx2. Every path gives the same sums, bit for bit.
    #[arg(long, default_value = "auto", value_parser = ["auto", "baseline", "avx2"])]
    path: String,
    /// Also read every in-band bin of the periodic ROM (L from [probe]).
    #[arg(long)]
    periodic: bool,
    /// Frame length override (default: the configuration's pulses).
    #[arg(long)]
    pulses: Option<u64>,
}

/// The figures of one band, as printed.
#[derive(Debug, Serialize)]
struct BandOut {
    bins: usize,
    bin_hz: f64,
    max_hz: f64,
    /// ΣΔ probing wall time, s.
    sd_seconds: f64,
    dft_seconds: f64,
    /// Modulator steps (windowed: 2 × bins × N; periodic: 0, the ROM is generated once).
    steps: u64,
    steps_per_s: f64,
    peak_hz: f64,
    peak_sd_um: f64,
    peak_dft_um: f64,
    noise_sd_um: f64,
    noise_dft_um: f64,
    /// ΣΔ noise floor / DFT noise floor on the same bins.
    noise_ratio: f64,
    /// Mean |Y_ΣΔ − Y_DFT| over the noise bins, µm, and over the DFT floor.
    error_um: f64,
    error_over_floor: f64,
}

#[derive(Debug, Serialize)]
struct Report {
    configuration: String,
    pulses: u64,
    threads: usize,
    precision: String,
    /// Instruction path the lanes ran on ("avx2" or "baseline") and their group width.
    path: String,
    lanes_per_group: usize,
    record_seconds: f64,
    windowed: BandOut,
    /// CPU time (user + system, all threads) of the windowed ΣΔ pass, s.
    windowed_sd_cpu_seconds: Option<f64>,
    steps_per_cpu_second: Option<f64>,
    steps_per_s_per_core: f64,
    /// The scalar reference loop (`Modulator::run` + direct accumulation, one bin's I and
    /// Q over 2^20 samples) on one thread in this run, steps/s, and the prober's steps/s
    /// per core over it.
    scalar_reference_steps_per_s_per_core: f64,
    speedup_vs_scalar: f64,
    /// The full band (20,001 bins of 1 Hz, N = 10^7: 4.0002·10^11 steps) at this run's
    /// wall-time rate, s, and at its rate per CPU-second on all threads (idle cores), s.
    full_band_seconds_at_this_rate: f64,
    full_band_seconds_idle: Option<f64>,
    target_seconds: f64,
    periodic: Option<BandOut>,
    svg: Option<String>,
    pass: bool,
}

const TARGET_S: f64 = 300.0;
/// Modulator steps of the full band: 2 streams × 20,001 bins × 10^7 pulses.
const FULL_BAND_STEPS: f64 = 2.0 * 20_001.0 * 1e7;
/// Samples of the scalar reference's speed run.
const N_SCALAR: u64 = 1 << 20;

fn err(e: impl std::fmt::Display) -> CliError {
    CliError::option(
        "bench fullband",
        e.to_string(),
        "an internal computation that succeeds",
    )
}

/// Runs the benchmark.
pub fn run(args: &FullBandArgs) -> Result<(), CliError> {
    let loaded = tofprobe_design::load(args.config.as_deref())?;
    let cfg = &loaded.document;
    let probe_err =
        |source| CliError::from(tofprobe_design::DesignError::probe(&loaded.origin, source));
    let fs = cfg.sensor.laser_rate_hz;
    let pulses = args.pulses.unwrap_or_else(|| cfg.pulses());
    let alpha = 1.0 / f64::from(1u32 << cfg.pixel.shift);
    let precision = match args.precision.as_str() {
        "f32" => LanePrecision::F32,
        _ => LanePrecision::F64,
    };
    let path = KernelPath::parse(&args.path).map_err(|_| {
        CliError::option("path", &args.path, "auto or baseline: this CPU lacks AVX2")
    })?;
    let bins = grid(args.max_hz, args.step_hz, fs, pulses, cfg.probe.osr)?;
    let windowed_cfg = tofprobe_dsp::sd::ProbeConfig {
        rom_mode: RomMode::Windowed,
        ..cfg.probe.clone()
    };
    let design = ProbeDesign::new(&windowed_cfg, 1000.0 / fs).map_err(probe_err)?;

    let t0 = Instant::now();
    let source = cfg
        .photon_source()
        .map_err(|e| CliError::from(tofprobe_design::DesignError::scene(&loaded.origin, e)))?;
    let x = prefiltered_record(&source, pulses, alpha).map_err(err)?;
    let record_seconds = t0.elapsed().as_secs_f64();

    let bar = ProgressBar::with_draw_target(Some(pulses), ProgressDrawTarget::hidden());
    if !args.json && std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} pulses ({eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    let cpu0 = process_cpu_seconds();
    let spec = windowed_band(&x, &design, fs, &bins, alpha, precision, path, |n| {
        bar.set_position(n)
    })
    .map_err(probe_err)?;
    let cpu = cpu0
        .zip(process_cpu_seconds())
        .map(|(a, b)| (b - a) * spec.sd_seconds / (spec.sd_seconds + spec.dft_seconds));
    bar.finish_and_clear();
    let windowed = band_out(&spec, pulses)?;

    let periodic = if args.periodic {
        let d = ProbeDesign::with_known_limit(
            &tofprobe_dsp::sd::ProbeConfig {
                rom_mode: RomMode::Periodic,
                ..cfg.probe.clone()
            },
            design.max_stable_amplitude,
            design.limit_f_norm,
        )
        .map_err(probe_err)?;
        let s = periodic_band(&x, &d, fs, alpha).map_err(probe_err)?;
        Some(band_out(&s, pulses)?)
    } else {
        None
    };

    let svg = match &args.svg {
        Some(p) => {
            super::fullband_svg::write(p, &spec, &loaded.origin)?;
            Some(p.display().to_string())
        }
        None => None,
    };
    let threads = rayon::current_num_threads();
    let scalar = scalar_reference_rate(&design, &speed_record(N_SCALAR))?;
    let steps_per_cpu_second = cpu.map(|c| spec.steps as f64 / c);
    let per_core = windowed.steps_per_s / threads as f64;
    let report = Report {
        configuration: loaded.origin.clone(),
        pulses,
        threads,
        precision: precision.name().into(),
        path: path.name().into(),
        lanes_per_group: path.lanes(precision),
        record_seconds,
        steps_per_cpu_second,
        windowed_sd_cpu_seconds: cpu,
        steps_per_s_per_core: per_core,
        scalar_reference_steps_per_s_per_core: scalar,
        speedup_vs_scalar: per_core / scalar,
        full_band_seconds_at_this_rate: FULL_BAND_STEPS / windowed.steps_per_s,
        full_band_seconds_idle: steps_per_cpu_second
            .map(|r| FULL_BAND_STEPS / (r * threads as f64)),
        target_seconds: TARGET_S,
        pass: windowed.sd_seconds <= TARGET_S,
        windowed,
        periodic,
        svg,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

/// Bin indices of 0, step, 2·step, … ≤ max (rounded to the record's f_s/N grid, distinct).
fn grid(max_hz: f64, step_hz: f64, fs: f64, pulses: u64, osr: f64) -> Result<Vec<u64>, CliError> {
    let df = fs / pulses as f64;
    let band = fs / (2.0 * osr);
    let opt = |option: &str, value: f64, allowed: String| CliError::option(option, value, allowed);
    if !(step_hz.is_finite() && step_hz >= df) {
        return Err(opt("step-hz", step_hz, format!(">= f_s/N = {df} Hz")));
    }
    if !(max_hz.is_finite() && (0.0..band).contains(&max_hz)) {
        return Err(opt(
            "max-hz",
            max_hz,
            format!("0 <= max-hz < f_s/(2·OSR) = {band} Hz, e.g. 20000"),
        ));
    }
    let mut bins: Vec<u64> = (0..=(max_hz / step_hz).floor() as u64)
        .map(|i| (i as f64 * step_hz / df).round() as u64)
        .collect();
    bins.dedup();
    Ok(bins)
}

fn band_out(s: &BandSpectrum, pulses: u64) -> Result<BandOut, CliError> {
    let sum = BandSummary::of(s, pulses).map_err(err)?;
    let bin_hz = s.frequencies_hz.get(1).copied().unwrap_or(0.0) - s.frequencies_hz[0];
    Ok(BandOut {
        bins: s.bins.len(),
        bin_hz,
        max_hz: s.frequencies_hz.last().copied().unwrap_or(0.0),
        sd_seconds: s.sd_seconds,
        dft_seconds: s.dft_seconds,
        steps: s.steps,
        steps_per_s: s.steps as f64 / s.sd_seconds.max(1e-9),
        peak_hz: sum.peak_hz,
        peak_sd_um: sum.peak_sd_um,
        peak_dft_um: sum.peak_dft_um,
        noise_sd_um: sum.noise_sd_um,
        noise_dft_um: sum.noise_dft_um,
        noise_ratio: sum.noise_sd_um / sum.noise_dft_um,
        error_um: sum.error_um,
        error_over_floor: sum.error_um / sum.noise_dft_um,
    })
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

fn print_text(r: &Report) {
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
        "  target <= {:.0} s: {}",
        r.target_seconds,
        if r.pass { "pass" } else { "FAIL" }
    );
    if let Some(p) = &r.periodic {
        print_band("periodic ROM", p);
    }
    if let Some(p) = &r.svg {
        println!("  spectra: {p}");
    }
}
