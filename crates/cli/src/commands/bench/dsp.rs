//! `tofprobe bench dsp [--json]`: the float references' speed. A 10^7-point Blackman FFT
//! (target ≤ 1.5 s), one full Table 2 row (Monte Carlo, hold, FFT, statistics; ≤ 3 s), and
//! the selected-bin streaming DFT against the full FFT for B = 1, 4, 16, 64 bins on the
//! same record, showing where each is cheaper.

use std::time::Instant;

use clap::Args;
use serde::Serialize;
use tofprobe_dsp::Window;
use tofprobe_dsp::bins::SelectedBins;
use tofprobe_dsp::dft::amplitude_spectrum;

use crate::error::CliError;
use tofprobe_experiments::paper::table2;

/// Arguments of `tofprobe bench dsp`.
#[derive(Debug, Args)]
pub struct DspBenchArgs {
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

const N: usize = 10_000_000;
const FFT_TARGET_S: f64 = 1.5;
const ROW_TARGET_S: f64 = 3.0;
/// Issue target for every DFT row of Table 2 on 2 cores.
const ALL_ROWS_TARGET_S: f64 = 60.0;

#[derive(Debug, Serialize)]
struct BinsTiming {
    bins: usize,
    seconds: f64,
    /// FFT time / selected-bin time: > 1 means the selected bins are cheaper.
    speedup_vs_fft: f64,
}

#[derive(Debug, Serialize)]
struct Report {
    fft_points: usize,
    fft_seconds: f64,
    fft_target_seconds: f64,
    table2_row_seconds: f64,
    table2_row_target_seconds: f64,
    table2_row: String,
    table2_rows: usize,
    table2_all_rows_seconds: f64,
    table2_all_rows_target_seconds: f64,
    selected_bins: Vec<BinsTiming>,
    pass: bool,
}

fn err(e: impl std::fmt::Display) -> CliError {
    CliError::option(
        "bench dsp",
        e.to_string(),
        "an internal computation that succeeds",
    )
}

/// Runs the benchmark.
pub fn run(args: &DspBenchArgs) -> Result<(), CliError> {
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

    let report = Report {
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
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!("10^7-point Blackman FFT: {fft_seconds:.3} s (target ≤ {FFT_TARGET_S} s)");
        println!(
            "one Table 2 row ({}): {table2_row_seconds:.3} s (target ≤ {ROW_TARGET_S} s)",
            report.table2_row
        );
        println!(
            "all {table2_rows} Table 2 rows, DFT column: {table2_all_rows_seconds:.3} s (target ≤ {ALL_ROWS_TARGET_S} s)"
        );
        for b in &report.selected_bins {
            println!(
                "selected-bin DFT, B = {:>2}: {:.3} s ({:.2}× the FFT's speed)",
                b.bins, b.seconds, b.speedup_vs_fft
            );
        }
        println!("pass: {}", report.pass);
    }
    Ok(())
}
