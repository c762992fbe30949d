//! The photon/TDC Monte Carlo's single-thread throughput on a configuration's scene, at
//! (ρ_s, ρ_b) = (1, 0) and (0.3, 0.3), against the targets of 50 M and 20 M pulses/s.
//!
//! Each case times the batched kernel writing the compact codes the pixel's drivers read
//! (`PhotonSource::fill_counted_codes`, what the array and `run_pixel` stream) beside the
//! per-pulse reference kernel (`fill_counted_reference`, its `Option`s) in the same run,
//! alternating halves of the pulses so both see the same machine load, and reports the
//! ratio (issue 28's target: ≥ 3× per CPU-second). Rates are reported against wall-clock
//! time and, where Linux exposes it, against the thread's own CPU time: `pass` and the
//! ratios use the CPU-time rates when available. Each ISA of the batched kernel
//! (`tofprobe_io::isa`) is its own row ([`measure_isas`]), its reference timed beside it.

use std::time::Instant;

use serde::Serialize;
use tofprobe_design::Document;
use tofprobe_scene::PhotonSource;

use crate::BenchError;
use crate::cpu::thread_cpu_ns;
use crate::isa::{IsaRows, rows};
use tofprobe_io::isa::Isa;

/// Target throughput with every pulse a signal photon and no background (pulses/s).
pub const TARGET_SIGNAL_ONLY: f64 = 50e6;
/// Target throughput at ρ_s = 0.3, ρ_b = 0.3 (pulses/s).
pub const TARGET_MIXED: f64 = 20e6;
/// Target speed-up of the batched kernel over the per-pulse reference (CPU time).
pub const TARGET_SPEEDUP: f64 = 3.0;
/// Pulses per fill call (a multiple of the source's block); also the fewest pulses a case
/// may time.
pub const CHUNK: usize = 1 << 16;

/// The measured rates.
#[derive(Debug, Clone, Serialize)]
pub struct SceneReport {
    /// The instruction set the batched kernel ran on ("scalar", "avx2", "avx512"); the
    /// reference is scalar code on every row.
    pub isa: &'static str,
    pub pulses: u64,
    pub signal_only_pulses_per_s: f64,
    pub mixed_pulses_per_s: f64,
    pub signal_only_pulses_per_cpu_s: Option<f64>,
    pub mixed_pulses_per_cpu_s: Option<f64>,
    /// The per-pulse reference kernel, same run.
    pub signal_only_reference_pulses_per_s: f64,
    pub mixed_reference_pulses_per_s: f64,
    pub signal_only_reference_pulses_per_cpu_s: Option<f64>,
    pub mixed_reference_pulses_per_cpu_s: Option<f64>,
    /// Batched ÷ reference pulses per CPU-second (wall where CPU time is not measured).
    pub signal_only_speedup_vs_reference: f64,
    pub mixed_speedup_vs_reference: f64,
    pub speedup_target: f64,
    pub signal_only_target_pulses_per_s: f64,
    pub mixed_target_pulses_per_s: f64,
    pub threads: u32,
    /// Both absolute targets met.
    pub pass: bool,
    /// Both speed-ups ≥ [`TARGET_SPEEDUP`].
    pub speedup_pass: bool,
}

/// Rates of one kernel: pulses per wall-clock second and per CPU second of this thread.
struct Rates {
    wall: f64,
    cpu: Option<f64>,
}

impl Rates {
    fn judged(&self) -> f64 {
        self.cpu.unwrap_or(self.wall)
    }
}

/// Wall and CPU seconds of one kernel over pulses `first .. first + pulses`.
fn run(
    source: &PhotonSource,
    reference: bool,
    first: u64,
    pulses: u64,
    (buf, codes): (&mut [Option<u32>], &mut [u32]),
) -> (f64, Option<f64>) {
    let cpu0 = thread_cpu_ns();
    let start = Instant::now();
    let mut detections = 0u64;
    let mut p = first;
    while p < first + pulses {
        let n = (first + pulses - p).min(buf.len() as u64) as usize;
        detections += if reference {
            source.fill_counted_reference(p, &mut buf[..n])
        } else {
            source.fill_counted_codes(p, &mut codes[..n])
        }
        .detections;
        p += n as u64;
    }
    let s = start.elapsed().as_secs_f64();
    std::hint::black_box(detections);
    let cpu = match (cpu0, thread_cpu_ns()) {
        (Some(a), Some(b)) if b > a => Some((b - a) as f64 * 1e-9),
        _ => None,
    };
    (s, cpu)
}

/// Times `pulses` pulses of each kernel through one thread: (batched, reference).
fn time_case(
    config: &Document,
    rho_s: f64,
    rho_b: f64,
    pulses: u64,
) -> Result<(Rates, Rates), BenchError> {
    let mut c = config.clone();
    c.sensor.signal_rate = rho_s;
    c.sensor.background_rate = rho_b;
    let source: PhotonSource = c
        .photon_source()
        .map_err(|source| tofprobe_design::DesignError::scene("bench scene", source))?;
    let mut buf = vec![None; CHUNK];
    let mut codes = vec![0u32; CHUNK];
    // Warm-up, then alternating halves of batched and reference over the same pulses.
    source.fill_codes(0, &mut codes);
    source.fill_reference(0, &mut buf);
    let half = pulses / 2;
    let mut acc = [(0.0, Some(0.0)); 2];
    for (first, n) in [(0, half), (half, pulses - half)] {
        for (k, reference) in [(0, false), (1, true)] {
            let (w, c) = run(&source, reference, first, n, (&mut buf, &mut codes));
            acc[k].0 += w;
            acc[k].1 = acc[k].1.zip(c).map(|(a, b)| a + b);
        }
    }
    let rates = |(w, c): (f64, Option<f64>)| Rates {
        wall: pulses as f64 / w.max(1e-9),
        cpu: c.map(|c| pulses as f64 / c.max(1e-9)),
    };
    Ok((rates(acc[0]), rates(acc[1])))
}

/// [`measure`] once per ISA in `isas`, each under that ISA (each row times its own
/// reference beside it, so each ratio is of one moment's load).
pub fn measure_isas(
    document: &Document,
    pulses: u64,
    isas: &[Isa],
) -> Result<IsaRows<SceneReport>, BenchError> {
    rows(isas, |_| measure(document, pulses))
}

/// Times both cases on the document's scene, `pulses` pulses each (≥ [`CHUNK`]), the
/// batched kernel on the current ISA.
pub fn measure(document: &Document, pulses: u64) -> Result<SceneReport, BenchError> {
    if pulses < CHUNK as u64 {
        return Err(BenchError::option(
            "pulses",
            pulses,
            format!("pulses >= {CHUNK}"),
        ));
    }
    let (a, ar) = time_case(document, 1.0, 0.0, pulses)?;
    let (b, br) = time_case(document, 0.3, 0.3, pulses)?;
    let speedup = (a.judged() / ar.judged(), b.judged() / br.judged());
    Ok(SceneReport {
        isa: Isa::current().name(),
        pulses,
        signal_only_pulses_per_s: a.wall,
        mixed_pulses_per_s: b.wall,
        signal_only_pulses_per_cpu_s: a.cpu,
        mixed_pulses_per_cpu_s: b.cpu,
        signal_only_reference_pulses_per_s: ar.wall,
        mixed_reference_pulses_per_s: br.wall,
        signal_only_reference_pulses_per_cpu_s: ar.cpu,
        mixed_reference_pulses_per_cpu_s: br.cpu,
        signal_only_speedup_vs_reference: speedup.0,
        mixed_speedup_vs_reference: speedup.1,
        speedup_target: TARGET_SPEEDUP,
        signal_only_target_pulses_per_s: TARGET_SIGNAL_ONLY,
        mixed_target_pulses_per_s: TARGET_MIXED,
        threads: 1,
        pass: a.judged() >= TARGET_SIGNAL_ONLY && b.judged() >= TARGET_MIXED,
        speedup_pass: speedup.0 >= TARGET_SPEEDUP && speedup.1 >= TARGET_SPEEDUP,
    })
}
