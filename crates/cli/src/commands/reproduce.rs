//! `tofprobe reproduce [--quick] [--json] [--out DIR]`: the paper's numbers, re-measured.
//! Prints a Markdown table (paper | corrected | measured | closed form | same-record DFT |
//! tolerance | pass), writes the paper's figures (Fig. 2–9 and 12) and Table 2's plots as
//! SVG to DIR (one set, whole or absent), and exits with status 1 if any row misses its
//! tolerance. The full run simulates 1 s records (10^7 pulses) for every Table 2 row;
//! `--quick` uses 2^20-pulse records (the paper's values are shown, not compared). Table 2
//! has three columns — the DFT, the float ΣΔ and the bit-true pixel — each on its own seeds
//! (`paper::table2::seeds_for_set`), each with its noise, "A meas." and SNR rows beside the
//! paper's printed value (`crates/experiments/data/paper/table2.tsv`): a row is the mean
//! over its seeds, judged |closed form − mean| ≤ 3·se with z-scores of the paper and the
//! closed form (`paper::stats`), the probe rows also against the same records' DFT;
//! `--json` carries the seeds, bands, z-scores and `same_record_dft` per row, and how many
//! rows carry a paper value. All rows share one probe ROM generated once; the run prints
//! its total time and the ROM / Table 2 split.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use tofprobe_experiments::paper::reproduce::reproduce;
use tofprobe_experiments::paper::{self, Row, table2};

use crate::error::CliError;

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
    /// Fig. 7/8's full-band ΣΔ probing and DFT.
    band_seconds: f64,
    rows: &'a [Row],
    /// Rows that show a value the paper prints.
    rows_with_paper_value: usize,
    /// Every SVG written.
    plots: Vec<String>,
    /// The paper's figures among them, by figure ("Fig. 4" → path).
    figures: std::collections::BTreeMap<String, String>,
    rows_failed: usize,
    pass: bool,
}

/// Runs the command. Internal failures are `error: reproduce: …` (exit 2); missed rows
/// are the FAIL verdict (exit 1) after the table.
pub fn run(args: &ReproduceArgs) -> Result<super::Verdict, CliError> {
    let start = Instant::now();
    let r = reproduce(args.quick, &args.out).map_err(CliError::reproduce)?;
    let (rows, plots, n) = (r.rows, r.plots, r.table2_pulses);
    let seconds = start.elapsed().as_secs_f64();
    let failed = rows.iter().filter(|r| !r.pass).count();
    if args.json {
        let report = Report {
            quick: args.quick,
            table2_pulses: n,
            seconds,
            rom_seconds: r.rom_seconds,
            table2_seconds: r.table2_seconds,
            band_seconds: r.band_seconds,
            rows: &rows,
            rows_with_paper_value: rows.iter().filter(|r| r.paper.is_some()).count(),
            figures: r.figures.iter().cloned().collect(),
            plots,
            rows_failed: failed,
            pass: failed == 0,
        };
        println!("{}", serde_json::to_string(&report)?);
    } else {
        if args.quick {
            println!(
                "**QUICK RUN**: short records (Table 2: {n} pulses); the paper's values are shown, not compared.\n"
            );
        }
        println!(
            "Assumptions: f_s = 10 MHz; static depth at the window centre (δ0 = 30 mm in a 60 mm window \
             where ρ_b > 0; window max(60, 12σ_s) mm when ρ_b = 0 so the jitter is not clipped); TDC LSB 1 mm, \
             jitter σ_I = sqrt(σ_s² − LSB²/12); DFT of the raw held depth (1NN hold, no prefilter); \
             ΣΔ column: records of its own, prefiltered (α = 1/32) and probed by one windowed Blackman ROM \
             (order 3, OSR 32, H_inf 1.5, A_p 0.5) at the tone bin and {} bins over 1–10 kHz (the DFT's band), read out \
             normalised by 2/N, G, A_p and |H_pre(f_k)|; bit-true: records of its own through the \
             transaction model (F = 8, S = 5, W from the ROM's sign counts); each probe record also read by the DFT \
             on the same bins (same-record DFT); Blackman; noise floor = mean |Y| over 1–10 kHz without DC and ±8 \
             bins around the tone; \"A meas.\" = log-quadratic interpolation of the tone, or of the largest value \
             over {}–{} Hz without one; SNR = 20·log10(A meas./noise) per seed; every row: mean ± sd over its \
             column's own seeds (≥ {}), judged |closed form − mean| ≤ 3·se (the paper's value where there is no \
             closed form; paper z shown; ERRATUM where |z| > 3), probe rows also against the same-record DFT.\n",
            paper::sigma_delta::NOISE_BINS,
            table2::PEAK_BAND.0,
            table2::PEAK_BAND.1,
            table2::SEEDS.len()
        );
        print!("{}", paper::markdown(&rows));
        println!("\nfigures:");
        for (fig, path) in &r.figures {
            println!("  {fig}: {path}");
        }
        println!("plots: {}", plots.join(", "));
        println!(
            "{} rows ({} with the paper's value), {failed} failed, {seconds:.1} s (ΣΔ ROM {:.1} s, \
             Table 2 rows {:.1} s, Fig. 7/8 band {:.1} s)",
            rows.len(),
            rows.iter().filter(|r| r.paper.is_some()).count(),
            r.rom_seconds,
            r.table2_seconds,
            r.band_seconds
        );
    }
    Ok(super::Verdict::of(failed == 0))
}
