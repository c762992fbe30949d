//! Speed of the two fidelities (issue point 8), measured by `tofprobe bench pixel`: the
//! transaction model's pulses per second at B = 16 with the ROM read for every pulse, the
//! folded driver's on the same frame (issue 28; [`bench_fold`], checked bit-identical to
//! the transaction driver's readout), the segmented fold's ([`bench_segmented`], checked
//! the same way), and the cycle model's clock edges per second under
//! the reference sequencer. Both transaction-level drivers read the compact codes
//! ([`synthetic_codes`]), the form the Monte Carlo writes.

use std::time::Instant;
use tofprobe_io::cpu::thread_cpu_seconds;

use tofprobe_dsp::RomImage;

use crate::cycle::CycleModel;
use crate::error::PixelError;
use crate::fold::FoldModel;
use crate::params::PixelParams;
use crate::readout::Readout;
use crate::segments::SegmentedModel;
use crate::sequencer::Sequencer;
use crate::transaction::TransactionModel;

/// [`synthetic_stimuli`] in the drivers' compact form ([`crate::NO_DETECTION`] for none):
/// what the benchmarks stream, as the Monte Carlo hands it to the array.
pub fn synthetic_codes(pulses: usize, codes: u32) -> Vec<u32> {
    synthetic_stimuli(pulses, codes)
        .into_iter()
        .map(crate::detections::compact)
        .collect()
}

/// Stimuli the benchmark feeds: a deterministic mix of detections (≈ 90 %) spread over the
/// 80-code window and misses, so the hold and the prefilter do real work.
pub fn synthetic_stimuli(pulses: usize, codes: u32) -> Vec<Option<u32>> {
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    (0..pulses)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            if s.is_multiple_of(10) {
                None
            } else {
                Some(((s >> 8) % u64::from(codes.max(1))) as u32)
            }
        })
        .collect()
}

/// A synthetic ROM of `depth` entries for `registers` bits: a square-wave sign pattern per
/// register at a different period each, so every entry differs.
pub fn synthetic_rom(depth: usize, registers: usize) -> RomImage {
    RomImage::from_fn(depth, registers, |a, r| (a / (r + 1)) % 2 == 0)
}

/// Result of the transaction-model benchmark.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransactionBench {
    /// Pulses run.
    pub pulses: u64,
    /// Wall time of the frame, seconds.
    pub seconds: f64,
    /// CPU time of the frame on its thread, seconds (Linux; `None` elsewhere).
    pub cpu_seconds: Option<f64>,
    /// Pulses per second.
    pub pulses_per_s: f64,
    /// Real-time factor at `laser_rate_hz`: simulated time over wall time.
    pub realtime_factor: f64,
    /// Wall time of the same frame through `pulse` one call at a time, seconds.
    pub per_pulse_seconds: f64,
}

/// Times one frame of `pulses` through [`TransactionModel::run`] at `params` (B bins), and
/// the same through [`TransactionModel::pulse`]; checks both give the same readout.
pub fn bench_transaction(
    params: &PixelParams,
    pulses: usize,
    rom: &RomImage,
    laser_rate_hz: f64,
) -> Result<TransactionBench, PixelError> {
    let stimuli = synthetic_codes(pulses, 80);
    let mut tm = TransactionModel::new(params)?;
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    // Stream in chunks as the simulator does (the source fills a chunk at a time).
    for (i, chunk) in stimuli.chunks(1 << 16).enumerate() {
        tm.run(chunk, Some(rom), (i << 16) as u64)?;
    }
    let fast = tm.readout();
    let seconds = t0.elapsed().as_secs_f64();
    let cpu_seconds = c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a);

    let mut one = TransactionModel::new(params)?;
    let depth = rom.depth();
    let t1 = Instant::now();
    for (n, &d) in stimuli.iter().enumerate() {
        one.pulse(
            (d != crate::NO_DETECTION).then_some(d),
            rom.entry(n % depth),
        );
    }
    let slow = one.readout();
    let per_pulse_seconds = t1.elapsed().as_secs_f64();
    if fast != slow {
        return Err(PixelError::mismatch(
            "benchmark readouts of run() and pulse()",
            "different",
            "identical",
        ));
    }
    let seconds = seconds.max(1e-9);
    Ok(TransactionBench {
        pulses: pulses as u64,
        seconds,
        cpu_seconds,
        pulses_per_s: pulses as f64 / seconds,
        realtime_factor: pulses as f64 / laser_rate_hz / seconds,
        per_pulse_seconds,
    })
}

/// Result of the folded-driver benchmark ([`bench_fold`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FoldBench {
    /// Pulses run.
    pub pulses: u64,
    /// Wall time of the frame (run and readout), seconds.
    pub seconds: f64,
    /// CPU time of the frame on its thread, seconds (Linux; `None` elsewhere).
    pub cpu_seconds: Option<f64>,
    /// Pulses per second (wall time).
    pub pulses_per_s: f64,
    /// Real-time factor at `laser_rate_hz` (wall time).
    pub realtime_factor: f64,
    /// Real-time factor on the thread's CPU time (`None` where it is not measured).
    pub cpu_realtime_factor: Option<f64>,
}

impl FoldBench {
    /// How many times faster than the transaction driver on the same frame: the ratio of
    /// CPU times where both were measured, else of wall times.
    pub fn speedup_over(&self, transaction: &TransactionBench) -> f64 {
        match (transaction.cpu_seconds, self.cpu_seconds) {
            (Some(t), Some(f)) => t / f.max(1e-9),
            _ => transaction.seconds / self.seconds.max(1e-9),
        }
    }
}

/// Times one frame of `pulses` through the folded driver ([`FoldModel`], streamed in the
/// same chunks as [`bench_transaction`], readout included) on the same stimuli, then
/// checks its readout against [`TransactionModel::run`]'s (untimed): a mismatch is an
/// error. `rom` must have the depth L = `params.rom_depth`.
pub fn bench_fold(
    params: &PixelParams,
    pulses: usize,
    rom: &RomImage,
    laser_rate_hz: f64,
) -> Result<FoldBench, PixelError> {
    let mut fm = FoldModel::new(params, rom)?;
    let stimuli = synthetic_codes(pulses, 80);
    let (readout, bench) = timed(&stimuli, laser_rate_hz, |chunk, first| match chunk {
        Some(chunk) => {
            fm.run(chunk, first);
            None
        }
        None => Some(fm.readout()),
    });
    check_against_transaction(
        params,
        &stimuli,
        rom,
        &readout,
        "benchmark readouts of the folded and transaction drivers",
    )?;
    Ok(bench)
}

/// [`bench_fold`] for the segmented fold ([`SegmentedModel`], the frame driver's choice
/// for a long frame): the same stimuli in the same chunks, readout included, the same
/// check. Also returns the pulses its repairs stepped again.
pub fn bench_segmented(
    params: &PixelParams,
    pulses: usize,
    rom: &RomImage,
    laser_rate_hz: f64,
) -> Result<(FoldBench, u64), PixelError> {
    let mut sm = SegmentedModel::new(params, rom)?;
    let stimuli = synthetic_codes(pulses, 80);
    let (readout, bench) = timed(&stimuli, laser_rate_hz, |chunk, first| match chunk {
        Some(chunk) => {
            sm.run(chunk, first);
            None
        }
        None => Some(sm.readout()),
    });
    check_against_transaction(
        params,
        &stimuli,
        rom,
        &readout,
        "benchmark readouts of the segmented and transaction drivers",
    )?;
    Ok((bench, sm.repaired_pulses()))
}

/// Times a driver over `stimuli` in chunks of 2^16 pulses (`drive(Some(chunk), its first
/// pulse's ROM address)`), then its readout (`drive(None, 0)`).
fn timed(
    stimuli: &[u32],
    laser_rate_hz: f64,
    mut drive: impl FnMut(Option<&[u32]>, u64) -> Option<Readout>,
) -> (Readout, FoldBench) {
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    for (i, chunk) in stimuli.chunks(1 << 16).enumerate() {
        drive(Some(chunk), (i << 16) as u64);
    }
    let readout = drive(None, 0).unwrap_or_default();
    let seconds = t0.elapsed().as_secs_f64().max(1e-9);
    let cpu_seconds = c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a);
    let pulses = stimuli.len();
    let simulated = pulses as f64 / laser_rate_hz;
    let bench = FoldBench {
        pulses: pulses as u64,
        seconds,
        cpu_seconds,
        pulses_per_s: pulses as f64 / seconds,
        realtime_factor: simulated / seconds,
        cpu_realtime_factor: cpu_seconds.map(|c| simulated / c.max(1e-9)),
    };
    (readout, bench)
}

/// The transaction driver's readout of `stimuli` (in the benchmark's chunks) must be
/// `readout`: a mismatch is an error, `what` naming the pair.
fn check_against_transaction(
    params: &PixelParams,
    stimuli: &[u32],
    rom: &RomImage,
    readout: &Readout,
    what: &'static str,
) -> Result<(), PixelError> {
    let mut tm = TransactionModel::new(params)?;
    for (i, chunk) in stimuli.chunks(1 << 16).enumerate() {
        tm.run(chunk, Some(rom), (i << 16) as u64)?;
    }
    if tm.readout() != *readout {
        return Err(PixelError::mismatch(what, "different", "identical"));
    }
    Ok(())
}

/// Result of the cycle-model benchmark.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleBench {
    /// Clock edges stepped.
    pub cycles: u64,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Edges per second.
    pub cycles_per_s: f64,
    /// CPU time of the run on its thread, seconds (Linux; `None` elsewhere): the work "on
    /// one core" that wall time inflates on a shared machine.
    pub cpu_seconds: Option<f64>,
    /// Edges per second of CPU time (`None` where it is not measured).
    pub cpu_cycles_per_s: Option<f64>,
}

/// Times the cycle model under the reference sequencer for `frames` frames.
pub fn bench_cycle(
    params: &PixelParams,
    rom: &RomImage,
    frames: usize,
) -> Result<CycleBench, PixelError> {
    let n = usize::try_from(params.frame_pulses).unwrap_or(usize::MAX);
    let stimuli = synthetic_stimuli(n.saturating_mul(frames), 80);
    let seq = Sequencer::new(params, &stimuli, Some(rom))?;
    let mut cm = CycleModel::new(params)?;
    let cycles = seq.total_cycles();
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    let mut sink = 0u64;
    for pins in seq {
        let o = cm.step(&pins);
        sink = sink.wrapping_add(o.rd_data);
    }
    let seconds = t0.elapsed().as_secs_f64().max(1e-9);
    let cpu_seconds = c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a);
    std::hint::black_box(sink);
    Ok(CycleBench {
        cycles,
        seconds,
        cycles_per_s: cycles as f64 / seconds,
        cpu_seconds,
        cpu_cycles_per_s: cpu_seconds.map(|c| cycles as f64 / c.max(1e-9)),
    })
}
