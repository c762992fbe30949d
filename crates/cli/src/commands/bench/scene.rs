//! `tofprobe bench scene`: single-thread throughput of the photon/TDC Monte Carlo on the
//! configuration's scene, at (ρ_s, ρ_b) = (1, 0) and (0.3, 0.3), against the targets of
//! 50 M and 20 M pulses/s.
//!
//! Rates are reported against wall-clock time and, where Linux exposes it, against the
//! thread's own CPU time (`/proc/thread-self/schedstat`, ns resolution): on a shared
//! machine the wall-clock rate drops with the load while the CPU-time rate measures the
//! code. `pass` uses the CPU-time rates when available.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use tofprobe_scene::PhotonSource;

use crate::error::CliError;
use tofprobe_design::Document;

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
    signal_only_pulses_per_cpu_s: Option<f64>,
    mixed_pulses_per_cpu_s: Option<f64>,
    signal_only_target_pulses_per_s: f64,
    mixed_target_pulses_per_s: f64,
    threads: u32,
    pass: bool,
}

/// CPU time this thread has run (ns), from the scheduler's statistics.
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// Rates of one case: pulses per wall-clock second and per CPU second of this thread.
struct Rates {
    wall: f64,
    cpu: Option<f64>,
}

/// Times `pulses` pulses through one thread.
fn time_case(config: &Document, rho_s: f64, rho_b: f64, pulses: u64) -> Result<Rates, CliError> {
    let mut c = config.clone();
    c.sensor.signal_rate = rho_s;
    c.sensor.background_rate = rho_b;
    let source: PhotonSource = c
        .photon_source()
        .map_err(|source| tofprobe_design::DesignError::scene("bench scene", source))?;
    let mut buf = vec![None; CHUNK];
    // Warm-up, then the timed run; the detection count keeps the work observable.
    source.fill(0, &mut buf);
    let cpu0 = thread_cpu_ns();
    let start = Instant::now();
    let mut detections = 0u64;
    let mut first = 0u64;
    while first < pulses {
        let n = (pulses - first).min(CHUNK as u64) as usize;
        detections += source.fill_counted(first, &mut buf[..n]).detections;
        first += n as u64;
    }
    let s = start.elapsed().as_secs_f64();
    let cpu = match (cpu0, thread_cpu_ns()) {
        (Some(a), Some(b)) if b > a => Some(pulses as f64 / ((b - a) as f64 * 1e-9)),
        _ => None,
    };
    std::hint::black_box(detections);
    Ok(Rates {
        wall: pulses as f64 / s.max(1e-9),
        cpu,
    })
}

/// Runs the benchmark.
pub fn run(args: &SceneBenchArgs) -> Result<(), CliError> {
    if args.pulses < CHUNK as u64 {
        return Err(CliError::option(
            "pulses",
            args.pulses,
            format!("pulses >= {CHUNK}"),
        ));
    }
    let design = tofprobe_design::load(args.config.as_deref())?;
    let a = time_case(&design.document, 1.0, 0.0, args.pulses)?;
    let b = time_case(&design.document, 0.3, 0.3, args.pulses)?;
    let judged = (a.cpu.unwrap_or(a.wall), b.cpu.unwrap_or(b.wall));
    let report = Report {
        pulses: args.pulses,
        signal_only_pulses_per_s: a.wall,
        mixed_pulses_per_s: b.wall,
        signal_only_pulses_per_cpu_s: a.cpu,
        mixed_pulses_per_cpu_s: b.cpu,
        signal_only_target_pulses_per_s: TARGET_SIGNAL_ONLY,
        mixed_target_pulses_per_s: TARGET_MIXED,
        threads: 1,
        pass: judged.0 >= TARGET_SIGNAL_ONLY && judged.1 >= TARGET_MIXED,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "scene Monte Carlo, one thread, {} pulses per case",
            args.pulses
        );
        let cpu = |r: &Rates| match r.cpu {
            Some(c) => format!("{:8.1} M pulses/CPU-s", c / 1e6),
            None => "(no thread CPU time on this OS)".to_string(),
        };
        println!(
            "rho_s = 1.0, rho_b = 0.0   {:8.1} M pulses/s wall, {} (target {:.0})",
            a.wall / 1e6,
            cpu(&a),
            TARGET_SIGNAL_ONLY / 1e6
        );
        println!(
            "rho_s = 0.3, rho_b = 0.3   {:8.1} M pulses/s wall, {} (target {:.0})",
            b.wall / 1e6,
            cpu(&b),
            TARGET_MIXED / 1e6
        );
        println!("pass                       {}", report.pass);
    }
    Ok(())
}
