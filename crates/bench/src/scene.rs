//! The photon/TDC Monte Carlo's single-thread throughput on a configuration's scene, at
//! (ρ_s, ρ_b) = (1, 0) and (0.3, 0.3), against the targets of 50 M and 20 M pulses/s.
//!
//! Rates are reported against wall-clock time and, where Linux exposes it, against the
//! thread's own CPU time: `pass` uses the CPU-time rates when available.

use std::time::Instant;

use serde::Serialize;
use tofprobe_design::Document;
use tofprobe_scene::PhotonSource;

use crate::BenchError;
use crate::cpu::thread_cpu_ns;

/// Target throughput with every pulse a signal photon and no background (pulses/s).
pub const TARGET_SIGNAL_ONLY: f64 = 50e6;
/// Target throughput at ρ_s = 0.3, ρ_b = 0.3 (pulses/s).
pub const TARGET_MIXED: f64 = 20e6;
/// Pulses per fill call (a multiple of the source's block); also the fewest pulses a case
/// may time.
pub const CHUNK: usize = 1 << 16;

/// The measured rates.
#[derive(Debug, Clone, Serialize)]
pub struct SceneReport {
    pub pulses: u64,
    pub signal_only_pulses_per_s: f64,
    pub mixed_pulses_per_s: f64,
    pub signal_only_pulses_per_cpu_s: Option<f64>,
    pub mixed_pulses_per_cpu_s: Option<f64>,
    pub signal_only_target_pulses_per_s: f64,
    pub mixed_target_pulses_per_s: f64,
    pub threads: u32,
    pub pass: bool,
}

/// Rates of one case: pulses per wall-clock second and per CPU second of this thread.
struct Rates {
    wall: f64,
    cpu: Option<f64>,
}

/// Times `pulses` pulses through one thread.
fn time_case(config: &Document, rho_s: f64, rho_b: f64, pulses: u64) -> Result<Rates, BenchError> {
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

/// Times both cases on the document's scene, `pulses` pulses each (≥ [`CHUNK`]).
pub fn measure(document: &Document, pulses: u64) -> Result<SceneReport, BenchError> {
    if pulses < CHUNK as u64 {
        return Err(BenchError::option(
            "pulses",
            pulses,
            format!("pulses >= {CHUNK}"),
        ));
    }
    let a = time_case(document, 1.0, 0.0, pulses)?;
    let b = time_case(document, 0.3, 0.3, pulses)?;
    let judged = (a.cpu.unwrap_or(a.wall), b.cpu.unwrap_or(b.wall));
    Ok(SceneReport {
        pulses,
        signal_only_pulses_per_s: a.wall,
        mixed_pulses_per_s: b.wall,
        signal_only_pulses_per_cpu_s: a.cpu,
        mixed_pulses_per_cpu_s: b.cpu,
        signal_only_target_pulses_per_s: TARGET_SIGNAL_ONLY,
        mixed_target_pulses_per_s: TARGET_MIXED,
        threads: 1,
        pass: judged.0 >= TARGET_SIGNAL_ONLY && judged.1 >= TARGET_MIXED,
    })
}
