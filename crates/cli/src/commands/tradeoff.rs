//! `tofprobe tradeoff [CONFIG...] [--json] [--out DIR] [--verilator] [--knobs] [--skips]
//! [--imputation]`:
//! every fidelity level on each configuration (the embedded default without one), timed
//! per simulated second and scored against the float DFT and the scene's truth (a Haar
//! pixel: float Haar, bit-true, cycle-accurate, Verilator, scored by the coefficient error
//! against the float Haar and the event time error, `tradeoff::haar`; an `[array]`
//! configuration: each `[array] level` timed and scored against the bit-true array,
//! `tradeoff::array`, JSON key `array_scenes`); with
//! `--knobs` the bit-true knob sweep ([`tofprobe_experiments::tradeoff::knobs::DEFAULT_SWEEP`]) and with
//! `--skips` the skipped-stage speedups, both on a frame of at most `--sweep-pulses` and
//! timed as the median of `--reps` runs; with `--imputation` the motion-model imputation
//! (Kalman, α-β) against the 1NN hold on Table 2's scenes and its pixel cost
//! ([`tofprobe_experiments::tradeoff::imputation`], once, not per configuration; JSON key
//! `imputation`). Markdown tables on stdout (or one JSON object),
//! and with `--out` the tables (`tradeoff.md`) and the Pareto plot (`pareto.svg`),
//! written atomically.

use std::path::PathBuf;

use clap::Args;

use tofprobe_experiments::tradeoff::imputation;
use tofprobe_experiments::tradeoff::study::{self, StudyRequest};

use crate::error::CliError;

#[derive(Debug, Args)]
pub struct TradeoffArgs {
    /// Configuration files (TOML); none = the embedded default.
    configs: Vec<PathBuf>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
    /// Also time the Verilator RTL on a shortened frame (builds the harness; needs
    /// verilator).
    #[arg(long)]
    verilator: bool,
    /// Also sweep the bit-true knobs (W, F, G, prefilter rounding, S, ROM mode and L, ΣΔ
    /// order, OSR, B).
    #[arg(long)]
    knobs: bool,
    /// With `--knobs`: sweep only this knob (repeatable; names as in the table: W, F, G,
    /// "prefilter rounding", S, "ROM mode, L", "ΣΔ order", OSR, B); the baseline row is
    /// always run.
    #[arg(long = "knob", value_name = "NAME")]
    only_knobs: Vec<String>,
    /// Also time the skipped stages (background, hold, selected bins, full DFT).
    #[arg(long)]
    skips: bool,
    /// Pulses per frame of the knob sweep and the skip timings (scenes with more are
    /// shortened; 10^6 = 0.1 s at 10 MHz, so the default 4.5 kHz tone sits on a bin).
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(64..))]
    sweep_pulses: u64,
    /// Timing runs per knob setting and per skip measurement (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=100))]
    reps: u64,
    /// Also compare the motion-model imputation (Kalman filter, its α-β form) with the
    /// 1NN hold on Table 2's scenes at ρ_s 0.03–0.3, with its pixel cost (sky130 cells).
    #[arg(long)]
    imputation: bool,
    /// Pulses per record of `--imputation` (Table 2's 10^7 by default; ≈ 2 s of CPU per
    /// record and method).
    #[arg(long, default_value_t = 10_000_000, value_parser = clap::value_parser!(u64).range(1_048_576..))]
    imputation_pulses: u64,
    /// Seeds per scene of `--imputation`.
    #[arg(long, default_value_t = imputation::DEFAULT_SEEDS as u64, value_parser = clap::value_parser!(u64).range(2..=64))]
    imputation_seeds: u64,
    /// Write tradeoff.md and pareto.svg into this directory.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Runs the command: the study is the library's (`tofprobe_experiments::tradeoff::study`);
/// this parses, loads each configuration, writes the set and prints.
pub fn run(args: &TradeoffArgs) -> Result<(), CliError> {
    let paths: Vec<Option<&std::path::Path>> = if args.configs.is_empty() {
        vec![None]
    } else {
        args.configs.iter().map(|p| Some(p.as_path())).collect()
    };
    let designs = paths
        .into_iter()
        .map(crate::commands::load_for_hardware)
        .collect::<Result<Vec<_>, _>>()?;
    let request = StudyRequest {
        verilator: args.verilator,
        knobs: args.knobs,
        only_knobs: args.only_knobs.clone(),
        skips: args.skips,
        sweep_pulses: args.sweep_pulses,
        reps: usize::try_from(args.reps).unwrap_or(1),
        imputation: args.imputation.then(|| {
            (
                args.imputation_pulses,
                usize::try_from(args.imputation_seeds).unwrap_or(2),
            )
        }),
    };
    let result = study::run(&designs, &request)?;
    if let Some(dir) = &args.out {
        // One set, whole or absent (tofprobe_io::OutputSet), the table last.
        let io = |e: std::io::Error| CliError::output(dir.clone(), e.to_string());
        let files = result.files(dir)?;
        let mut set = tofprobe_io::OutputSet::begin(dir).map_err(io)?;
        for (name, text) in &files {
            set.add(name, text.as_bytes()).map_err(io)?;
        }
        set.commit(Some("tradeoff.md")).map_err(io)?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&result)?);
    } else {
        print!("{}", result.markdown());
    }
    Ok(())
}
