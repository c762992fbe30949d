//! `tofprobe bench scene`: single-thread throughput of the photon/TDC Monte Carlo on the
//! configuration's scene, at (ρ_s, ρ_b) = (1, 0) and (0.3, 0.3), against the targets of
//! 50 M and 20 M pulses/s.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use tofprobe_scene::PhotonSource;

use crate::config::Config;
use crate::error::CliError;

/// Target throughput with every pulse a signal photon and no background (pulses/s).
const TARGET_SIGNAL_ONLY: f64 = 50e6;
/// Target throughput at ρ_s = 0.3, ρ_b = 0.3 (pulses/s).
const TARGET_MIXED: f64 = 20e6;
/// Pulses per fill call (a multiple of the source's block).
const CHUNK: usize = 1 << 16;

/// Arguments of `tofprobe bench scene`.
#[derive(Debug, Args)]
pub struct SceneBenchArgs {
    /// Configuration whose sensor and scene are timed (default: the embedded default).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Pulses per case.
    #[arg(long, default_value_t = 20_000_000)]
    pulses: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct Report {
    pulses: u64,
    signal_only_pulses_per_s: f64,
    mixed_pulses_per_s: f64,
    signal_only_target_pulses_per_s: f64,
    mixed_target_pulses_per_s: f64,
    threads: u32,
    pass: bool,
}

/// Times `pulses` pulses through one thread; returns pulses/s.
fn time_case(config: &Config, rho_s: f64, rho_b: f64, pulses: u64) -> Result<f64, CliError> {
    let mut c = config.clone();
    c.sensor.signal_rate = rho_s;
    c.sensor.background_rate = rho_b;
    let source: PhotonSource = c.photon_source().map_err(|source| CliError::Scene {
        origin: "bench scene".into(),
        source,
    })?;
    let mut buf = vec![None; CHUNK];
    // Warm-up, then the timed run; the detection count keeps the work observable.
    source.fill(0, &mut buf);
    let start = Instant::now();
    let mut detections = 0u64;
    let mut first = 0u64;
    while first < pulses {
        let n = (pulses - first).min(CHUNK as u64) as usize;
        detections += source.fill_counted(first, &mut buf[..n]).detections;
        first += n as u64;
    }
    let s = start.elapsed().as_secs_f64();
    std::hint::black_box(detections);
    Ok(pulses as f64 / s.max(1e-9))
}

/// Runs the benchmark.
pub fn run(args: &SceneBenchArgs) -> Result<(), CliError> {
    if args.pulses < CHUNK as u64 {
        return Err(CliError::Option {
            option: "pulses".into(),
            value: args.pulses.to_string(),
            allowed: format!("pulses >= {CHUNK}"),
        });
    }
    let loaded = Config::load(args.config.as_deref())?;
    let a = time_case(&loaded.config, 1.0, 0.0, args.pulses)?;
    let b = time_case(&loaded.config, 0.3, 0.3, args.pulses)?;
    let report = Report {
        pulses: args.pulses,
        signal_only_pulses_per_s: a,
        mixed_pulses_per_s: b,
        signal_only_target_pulses_per_s: TARGET_SIGNAL_ONLY,
        mixed_target_pulses_per_s: TARGET_MIXED,
        threads: 1,
        pass: a >= TARGET_SIGNAL_ONLY && b >= TARGET_MIXED,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "scene Monte Carlo, one thread, {} pulses per case",
            args.pulses
        );
        println!(
            "rho_s = 1.0, rho_b = 0.0   {:8.1} M pulses/s (target {:.0})",
            a / 1e6,
            TARGET_SIGNAL_ONLY / 1e6
        );
        println!(
            "rho_s = 0.3, rho_b = 0.3   {:8.1} M pulses/s (target {:.0})",
            b / 1e6,
            TARGET_MIXED / 1e6
        );
        println!("pass                       {}", report.pass);
    }
    Ok(())
}
