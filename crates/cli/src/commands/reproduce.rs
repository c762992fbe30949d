//! `tofprobe reproduce [--quick] [--json] [--out DIR]`: the paper's numbers, re-measured.
//! Prints a Markdown table (paper | corrected | measured | closed form | tolerance | pass),
//! writes SVG plots to DIR, and exits with status 1 if any row misses its tolerance.
//! The full run simulates 1 s records (10^7 pulses) for every Table 2 row; `--quick`
//! uses 2^20-pulse records (the paper columns are then left out of the noise tests,
//! which compare with the closed form only, at 10%). Table 2 also has the float ΣΔ and
//! bit-true columns (`paper::sigma_delta`), all rows sharing one probe ROM generated once;
//! the run prints its total time and the ROM / Table 2 split.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;

use crate::error::CliError;
use crate::paper::{self, PaperError, Row, bandwidth, fig4, table2};

/// Arguments of `tofprobe reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// Short records for a smoke test (the table says so).
    #[arg(long)]
    quick: bool,
    /// Print one JSON object instead of the Markdown table.
    #[arg(long)]
    json: bool,
    /// Directory for the SVG plots (default: reproduce-out).
    #[arg(long, default_value = "reproduce-out")]
    out: PathBuf,
}

#[derive(Debug, Serialize)]
struct Report<'a> {
    quick: bool,
    table2_pulses: u64,
    seconds: f64,
    /// Generating the shared ΣΔ probe ROM (design sweep included).
    rom_seconds: f64,
    /// All Table 2 rows (every column, every seed).
    table2_seconds: f64,
    rows: &'a [Row],
    plots: Vec<String>,
    rows_failed: usize,
    pass: bool,
}

/// Wall-clock split of a run (s).
struct Timings {
    rom: f64,
    table2: f64,
}

fn compute(args: &ReproduceArgs) -> Result<(Vec<Row>, Vec<String>, u64, Timings), PaperError> {
    let (n_t2, n_f4, n_bw) = if args.quick {
        (1 << 20, 1 << 17, 1 << 21)
    } else {
        (10_000_000, fig4::N, bandwidth::N)
    };
    let t_rom = Instant::now();
    // Generated once here; every row's ΣΔ columns share it (`ProbeSetup::shared`).
    paper::sigma_delta::ProbeSetup::shared(n_t2)?;
    let rom_seconds = t_rom.elapsed().as_secs_f64();
    let t_rows = Instant::now();
    let results = table2::run_all(n_t2)?;
    let rows_seconds = t_rows.elapsed().as_secs_f64();
    paper::sigma_delta::ProbeSetup::release(n_t2);
    let mut rows: Vec<Row> = results
        .iter()
        .flat_map(|r| table2::rows_of(r, args.quick))
        .collect();
    rows.extend(table2::eq12_row(&results, n_t2, args.quick));
    rows.extend(fig4::rows(n_f4)?);
    rows.extend(bandwidth::rows(n_bw)?);
    let plots = paper::plots::write_all(&args.out, &results)?;
    Ok((
        rows,
        plots,
        n_t2,
        Timings {
            rom: rom_seconds,
            table2: rows_seconds,
        },
    ))
}

/// Runs the command. Internal failures print `error: …` and exit 2 (CliError has no
/// variant for dsp/plot errors yet); missed rows exit 1 after the table.
pub fn run(args: &ReproduceArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let (rows, plots, n, timings) = match compute(args) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: reproduce: {e}");
            std::process::exit(2);
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let failed = rows.iter().filter(|r| !r.pass).count();
    if args.json {
        let report = Report {
            quick: args.quick,
            table2_pulses: n,
            seconds,
            rom_seconds: timings.rom,
            table2_seconds: timings.table2,
            rows: &rows,
            plots,
            rows_failed: failed,
            pass: failed == 0,
        };
        println!("{}", serde_json::to_string(&report)?);
    } else {
        if args.quick {
            println!(
                "**QUICK RUN**: short records (Table 2: {n} pulses); paper columns not tested for noise.\n"
            );
        }
        println!(
            "Assumptions: f_s = 10 MHz; static depth at the window centre (δ0 = 30 mm in a 60 mm window \
             where ρ_b > 0; window max(60, 12σ_s) mm when ρ_b = 0 so the jitter is not clipped); TDC LSB 1 mm, \
             jitter σ_I = sqrt(σ_s² − LSB²/12); DFT of the raw held depth (1NN hold, no prefilter); \
             ΣΔ columns: the same held record, prefiltered (α = 1/32) and probed by one windowed Blackman ROM \
             (order 3, OSR 32, H_inf 1.5, A_p 0.5) at the tone bin and {} bins over 1–150 kHz, read out \
             normalised by 2/N, G, A_p and |H_pre(f_k)|; bit-true: the same detections through the \
             transaction model (F = 8, S = 5, W from the ROM's sign counts); \
             Blackman; noise floor = mean |Y| over 1–10 kHz without DC and ±8 bins around the tone; \
             amplitude = log-quadratic peak interpolation; amplitude spread from {} seeds.\n",
            paper::sigma_delta::NOISE_BINS,
            table2::SEEDS
        );
        print!("{}", paper::markdown(&rows));
        println!("\nplots: {}", plots.join(", "));
        println!(
            "{} rows, {failed} failed, {seconds:.1} s (ΣΔ ROM {:.1} s, Table 2 rows {:.1} s)",
            rows.len(),
            timings.rom,
            timings.table2
        );
    }
    if failed > 0 {
        std::process::exit(1);
    }
    Ok(())
}
