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
use serde::Serialize;

use tofprobe_design::ArrayLevel;
use tofprobe_experiments::tradeoff::array::{self as array_levels, ArrayTradeoff, measure_array};
use tofprobe_experiments::tradeoff::haar::{self, HaarSceneResult, measure_haar};
use tofprobe_experiments::tradeoff::imputation::{self, ImputationReport};
use tofprobe_experiments::tradeoff::imputation_cost::CellAreas;
use tofprobe_experiments::tradeoff::knobs::{self, DEFAULT_SWEEP, KnobSweep};
use tofprobe_experiments::tradeoff::skips::{self, SkipReport, measure_skips};
use tofprobe_experiments::tradeoff::{SceneResult, markdown, measure, plot::pareto_svg_text};

use crate::error::CliError;

/// Arguments of `tofprobe tradeoff`.
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

#[derive(Serialize)]
struct JsonOut<'a> {
    scenes: &'a [SceneResult],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    haar_scenes: &'a [HaarSceneResult],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    array_scenes: &'a [ArrayTradeoff],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    knobs: &'a [KnobSweep],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    skips: &'a [SkipReport],
    #[serde(skip_serializing_if = "Option::is_none")]
    imputation: Option<&'a ImputationReport>,
}

/// Runs the command.
pub fn run(args: &TradeoffArgs) -> Result<(), CliError> {
    let paths: Vec<Option<&std::path::Path>> = if args.configs.is_empty() {
        vec![None]
    } else {
        args.configs.iter().map(|p| Some(p.as_path())).collect()
    };
    let reps = usize::try_from(args.reps).unwrap_or(1);
    if let Some(bad) = args
        .only_knobs
        .iter()
        .find(|k| !DEFAULT_SWEEP.iter().any(|s| s.knob == k.as_str()))
    {
        let mut names: Vec<&str> = DEFAULT_SWEEP.iter().map(|s| s.knob).collect();
        names.dedup();
        return Err(CliError::option("knob", bad.clone(), names.join(", ")));
    }
    let mut scenes = Vec::new();
    let mut haar_scenes = Vec::new();
    let mut array_scenes = Vec::new();
    let mut sweeps = Vec::new();
    let mut skip_reports = Vec::new();
    let mut tables = Vec::new();
    for p in paths {
        let design = crate::commands::load_for_hardware(p)?;
        if design.array.is_some() && design.pixel.mode == tofprobe_pixel::Mode::Fourier {
            // An [array] configuration: its array levels against bit-true.
            let r = measure_array(&design, &ArrayLevel::ALL)?;
            tables.push(array_levels::markdown(&r));
            array_scenes.push(r);
            continue;
        }
        design.single_pixel("tradeoff")?;
        if design.pixel.mode == tofprobe_pixel::Mode::Haar {
            let h = measure_haar(&design, args.verilator)?;
            tables.push(haar::markdown(&h));
            if args.knobs || args.skips {
                tables.push(format!(
                    "(--knobs / --skips measure the Fourier pixel's knobs and stages: skipped for the Haar pixel of {})\n",
                    design.origin
                ));
            }
            haar_scenes.push(h);
            continue;
        }
        let scene = measure(&design, args.verilator)?;
        tables.push(markdown(&scene));
        scenes.push(scene);
        if args.knobs {
            let settings = knobs::select(DEFAULT_SWEEP, &args.only_knobs);
            let sw = knobs::sweep(&design, &settings, args.sweep_pulses, reps);
            tables.push(knobs::markdown(&sw));
            sweeps.push(sw);
        }
        if args.skips {
            let sk = measure_skips(&design, args.sweep_pulses, reps)?;
            tables.push(skips::markdown(&sk));
            skip_reports.push(sk);
        }
    }
    let imputation_report = if args.imputation {
        let cells = CellAreas::sky130()?;
        let seeds = usize::try_from(args.imputation_seeds).unwrap_or(2);
        let r = imputation::measure(args.imputation_pulses, seeds, cells.as_ref())?;
        tables.push(imputation::markdown(&r));
        Some(r)
    } else {
        None
    };
    let table = tables.join("\n");
    if let Some(dir) = &args.out {
        // One set, whole or absent (tofprobe_io::OutputSet), the table last.
        let io = |e: std::io::Error| CliError::output(dir.clone(), e.to_string());
        let svg = if scenes.is_empty() {
            None
        } else {
            Some(pareto_svg_text(&dir.join("pareto.svg"), &scenes)?)
        };
        let mut set = tofprobe_io::OutputSet::begin(dir).map_err(io)?;
        if let Some(svg) = svg {
            set.add("pareto.svg", svg.as_bytes()).map_err(io)?;
        }
        set.add("tradeoff.md", table.as_bytes()).map_err(io)?;
        set.commit(Some("tradeoff.md")).map_err(io)?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&JsonOut {
                scenes: &scenes,
                haar_scenes: &haar_scenes,
                array_scenes: &array_scenes,
                knobs: &sweeps,
                skips: &skip_reports,
                imputation: imputation_report.as_ref(),
            })?
        );
    } else {
        print!("{table}");
    }
    Ok(())
}
