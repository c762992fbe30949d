//! The float references' speed: a 10^7-point Blackman FFT (target ≤ 1.5 s), one full
//! Table 2 row (Monte Carlo, hold, FFT, statistics; ≤ 3 s), every Table 2 row's DFT column
//! (≤ 60 s on 2 cores), and the selected-bin streaming DFT against the full FFT for
//! B = 1, 4, 16, 64 bins on the same record, showing where each is cheaper.

use std::time::Instant;

use serde::Serialize;
use tofprobe_dsp::Window;
use tofprobe_dsp::dft::amplitude_spectrum;
use tofprobe_dsp::selected_bins::SelectedBins;
use tofprobe_experiments::paper::table2;

use crate::BenchError;

/// Points of the FFT and the Table 2 record.
pub const N: usize = 10_000_000;
pub const FFT_TARGET_S: f64 = 1.5;
pub const ROW_TARGET_S: f64 = 3.0;
/// Issue target for every DFT row of Table 2 on 2 cores.
pub const ALL_ROWS_TARGET_S: f64 = 60.0;

/// One selected-bin timing.
#[derive(Debug, Clone, Serialize)]
pub struct BinsTiming {
    pub bins: usize,
    pub seconds: f64,
    /// FFT time / selected-bin time: > 1 means the selected bins are cheaper.
    pub speedup_vs_fft: f64,
}

/// The measured times.
#[derive(Debug, Clone, Serialize)]
pub struct DspReport {
    pub fft_points: usize,
    pub fft_seconds: f64,
    pub fft_target_seconds: f64,
    pub table2_row_seconds: f64,
    pub table2_row_target_seconds: f64,
    pub table2_row: String,
    pub table2_rows: usize,
    pub table2_all_rows_seconds: f64,
    pub table2_all_rows_target_seconds: f64,
    pub selected_bins: Vec<BinsTiming>,
    pub pass: bool,
}

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::internal("dsp", e)
}

/// Runs the measurements (the Table 2 rows on the current rayon pool).
pub fn measure() -> Result<DspReport, BenchError> {
    // A deterministic noisy record (the FFT's speed does not depend on the values).
    let x: Vec<f64> = (0..N)
        .map(|i| 30.0 + ((i as u64).wrapping_mul(2654435761) % 1000) as f64 * 1e-3)
        .collect();
    let t = Instant::now();
    let s = amplitude_spectrum(&x, Window::Blackman).map_err(err)?;
    let fft_seconds = t.elapsed().as_secs_f64();
    std::hint::black_box(&s);
    drop(s);

    let mut selected_bins = Vec::new();
    for b in [1usize, 4, 16, 64] {
        let bins: Vec<usize> = (0..b).map(|i| 4500 + 37 * i).collect();
        let t = Instant::now();
        let mut sb = SelectedBins::new(N as u64, &bins, Window::Blackman).map_err(err)?;
        for c in x.chunks(1 << 16) {
            sb.push(c).map_err(err)?;
        }
        std::hint::black_box(sb.amplitudes().map_err(err)?);
        let seconds = t.elapsed().as_secs_f64();
        selected_bins.push(BinsTiming {
            bins: b,
            seconds,
            speedup_vs_fft: fft_seconds / seconds,
        });
    }
    drop(x);

    // One full Table 2 row, DFT column only (seed 0): Monte Carlo, hold, FFT, statistics.
    let spec = table2::ROWS[12];
    let t = Instant::now();
    let setup = spec.setup();
    let source = setup.source(0).map_err(err)?;
    let det = source.record(N as u64);
    let rec = table2::RowRecord {
        spec: &spec,
        source: &source,
        detections: &det,
        probe: None,
    };
    let m = table2::dft_column(&rec).map_err(err)?;
    let table2_row_seconds = t.elapsed().as_secs_f64();
    std::hint::black_box(m);

    // Every Table 2 row, DFT column only (rayon across rows, seed-to-seed spread included):
    // the reproduction's DFT part as `tofprobe reproduce` runs it.
    let t = Instant::now();
    let rows = table2::run_all_with(N as u64, None, &table2::COLUMNS[..1]).map_err(err)?;
    let table2_all_rows_seconds = t.elapsed().as_secs_f64();
    let table2_rows = rows.len();
    drop(rows);

    Ok(DspReport {
        fft_points: N,
        fft_seconds,
        fft_target_seconds: FFT_TARGET_S,
        table2_row_seconds,
        table2_row_target_seconds: ROW_TARGET_S,
        table2_row: spec.label(),
        table2_rows,
        table2_all_rows_seconds,
        table2_all_rows_target_seconds: ALL_ROWS_TARGET_S,
        pass: fft_seconds <= FFT_TARGET_S
            && table2_row_seconds <= ROW_TARGET_S
            && table2_all_rows_seconds <= ALL_ROWS_TARGET_S,
        selected_bins,
    })
}
