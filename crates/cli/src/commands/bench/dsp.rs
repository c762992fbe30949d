//! `tofprobe bench dsp [--json]`: the float references' speed (`tofprobe_bench::dsp`
//! measures; this prints).

use clap::Args;
use tofprobe_bench::dsp::{ALL_ROWS_TARGET_S, FFT_TARGET_S, ROW_TARGET_S};

use crate::error::CliError;

/// Arguments of `tofprobe bench dsp`.
#[derive(Debug, Args)]
pub struct DspBenchArgs {
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the benchmark.
pub fn run(args: &DspBenchArgs) -> Result<(), CliError> {
    let r = tofprobe_bench::dsp::measure()?;
    if args.json {
        println!("{}", serde_json::to_string(&r)?);
        return Ok(());
    }
    println!(
        "10^7-point Blackman FFT: {:.3} s (target ≤ {FFT_TARGET_S} s)",
        r.fft_seconds
    );
    println!(
        "one Table 2 row ({}): {:.3} s (target ≤ {ROW_TARGET_S} s)",
        r.table2_row, r.table2_row_seconds
    );
    println!(
        "all {} Table 2 rows, DFT column: {:.3} s (target ≤ {ALL_ROWS_TARGET_S} s)",
        r.table2_rows, r.table2_all_rows_seconds
    );
    for b in &r.selected_bins {
        println!(
            "selected-bin DFT, B = {:>2}: {:.3} s ({:.2}× the FFT's speed)",
            b.bins, b.seconds, b.speedup_vs_fft
        );
    }
    println!("pass: {}", r.pass);
    Ok(())
}
