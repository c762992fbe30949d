//! The lane speed runs of the `sd` and `fullband` benchmarks: the full-band prober's
//! modulator steps per second on one thread (f64 and f32 lanes, on this CPU's instruction
//! path and on the x86-64 baseline, whose sums must agree bit for bit) and the scalar
//! reference loop's, measured in the same run so their ratio holds on a busy machine.

use std::time::Instant;

use tofprobe_dsp::sd::fullband_check::naive_sums;
use tofprobe_dsp::sd::{FullBandProber, Isa, LanePrecision, ProbeDesign};

use crate::BenchError;

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::internal("lane rates", e)
}

/// Samples of the full-band speed runs (64 bins) and of the scalar reference (1 bin).
const N_FULLBAND: u64 = 1 << 20;

/// Modulator steps/s on one thread: the scalar reference, and the full-band prober's f64
/// and f32 lanes on this CPU's path and on the baseline.
#[derive(Debug)]
pub struct FullBandRates {
    pub scalar: f64,
    pub path: Isa,
    /// [f64, f32] on `path`.
    pub fast: [f64; 2],
    /// [f64, f32] on the baseline.
    pub baseline: [f64; 2],
}

/// The depth record of the speed runs: a slow sine on 30 mm.
pub fn speed_record(n: u64) -> Vec<f64> {
    (0..n).map(|n| 30.0 + (n as f64 * 0.001).sin()).collect()
}

/// The scalar reference (`Modulator::run` and direct accumulation, one bin's I and Q)
/// over `x`, on the calling thread: modulator steps per second.
pub fn scalar_reference_rate(design: &ProbeDesign, x: &[f64]) -> Result<f64, BenchError> {
    let frame = x.len() as u64;
    let bin = (frame as f64 / (4.0 * design.config.osr)) as u64;
    let t0 = Instant::now();
    let naive = naive_sums(design, frame, &[bin], x).map_err(err)?;
    let rate = 2.0 * frame as f64 / t0.elapsed().as_secs_f64();
    drop(naive);
    Ok(rate)
}

pub fn fullband_rates(design: &ProbeDesign) -> Result<FullBandRates, BenchError> {
    let x = speed_record(N_FULLBAND);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(err)?;
    let scalar = scalar_reference_rate(design, &x)?;
    let bins: Vec<u64> = (1..=64).map(|i| 70 * i).collect();
    let run = |p: LanePrecision, path: Isa| -> Result<(f64, Vec<(f64, f64)>), BenchError> {
        let t0 = Instant::now();
        let mut prober =
            FullBandProber::on_path(design, N_FULLBAND, &bins, p, path).map_err(err)?;
        pool.install(|| prober.push(&x)).map_err(err)?;
        Ok((
            prober.steps() as f64 / t0.elapsed().as_secs_f64(),
            prober.sums(),
        ))
    };
    let path = Isa::current();
    let mut fast = [0.0; 2];
    let mut baseline = [0.0; 2];
    for (i, p) in [LanePrecision::F64, LanePrecision::F32]
        .into_iter()
        .enumerate()
    {
        let (rate, sums) = run(p, Isa::Scalar)?;
        baseline[i] = rate;
        fast[i] = if path == Isa::Scalar {
            rate
        } else {
            let (rate, fast_sums) = run(p, path)?;
            // The paths differ in width only: a lane's sums must be the same bits.
            if let Some(b) = (0..sums.len()).find(|&b| {
                let (x, y) = (sums[b], fast_sums[b]);
                x.0.to_bits() != y.0.to_bits() || x.1.to_bits() != y.1.to_bits()
            }) {
                return Err(err(format!(
                    "the {} and baseline {} paths differ at bin {}: {:?} vs {:?}",
                    path.name(),
                    p.name(),
                    bins[b],
                    fast_sums[b],
                    sums[b]
                )));
            }
            rate
        };
    }
    Ok(FullBandRates {
        scalar,
        path,
        fast,
        baseline,
    })
}
