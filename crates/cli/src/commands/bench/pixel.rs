//! `tofprobe bench pixel`: speed of the bit-true pixel at the configuration's `[pixel]`
//! (`tofprobe_bench::pixel` measures; this prints). With `--verilator`, the cycle model
//! and Verilator also run one frame of `--cycle-pulses` of the design's RTL side by side
//! (a co-simulation: the same sequence, both checked), and the ratio is printed.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;
use tofprobe_bench::isa::IsaRows;
use tofprobe_bench::pixel::PixelReport;
use tofprobe_cosim::{BuildProfile, CosimOptions, cosim};
use tofprobe_design::{Chip, RomPurpose, RtlOverrides};

use crate::error::CliError;

/// Arguments of `tofprobe bench pixel`.
#[derive(Debug, Args)]
pub struct PixelBenchArgs {
    /// Configuration whose `[pixel]` and sensor are used (default: the embedded default).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Pulses in the transaction-model frame.
    #[arg(long, default_value_t = 10_000_000)]
    pulses: u64,
    /// Pulses through the cycle model (one frame under the reference sequencer).
    #[arg(long, default_value_t = 200_000)]
    cycle_pulses: u64,
    /// Also co-simulate a `--cycle-pulses` frame of the design's RTL in Verilator (builds
    /// the harness once, cached) and print the cycle model's rate beside Verilator's.
    #[arg(long)]
    verilator: bool,
    /// Instruction set of the vector kernels: scalar, avx2 or avx512 (default: every one
    /// this CPU runs, side by side, or the one TOFPROBE_ISA names).
    #[arg(long)]
    isa: Option<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// The cycle model against Verilator on one frame of the design's RTL (`--verilator`).
#[derive(Debug, Serialize)]
struct VsVerilator {
    cosim_cycles: u64,
    cosim_pass: bool,
    /// The golden run (cycle model, digests) and the checking harness, CPU time.
    cycle_model_cycles_per_cpu_s: Option<f64>,
    verilator_cycles_per_cpu_s: Option<f64>,
    cycle_model_vs_verilator: f64,
    /// The two models stepped with nothing observed.
    bare_cycle_model_vs_verilator: Option<f64>,
}

#[derive(Debug, Serialize)]
struct Json<'a> {
    #[serde(flatten)]
    report: &'a IsaRows<PixelReport>,
    #[serde(flatten)]
    verilator: Option<VsVerilator>,
}

/// Co-simulates one `pulses`-pulse frame of the design's RTL (the ROM the simulating
/// commands replay) in a temporary directory, with the bare models timed too.
fn vs_verilator(args: &PixelBenchArgs, pulses: u64) -> Result<VsVerilator, CliError> {
    let overrides = RtlOverrides {
        frame_pulses: Some(pulses),
        rom_depth: None,
    };
    let (design, _) = super::super::simulated_design(1, args.config.as_deref(), &overrides)?;
    let chip = Chip::of(&design, &overrides, RomPurpose::Replayed)?;
    let work = std::env::temp_dir().join(format!("tofprobe-bench-pixel-{}", std::process::id()));
    let mut o = CosimOptions::new(&work);
    o.frames = 1;
    o.rom = Some(chip.rom.words);
    // As `tofprobe cosim` sets a run of this length (so both share one harness build).
    if pulses * chip.pixel.cycles_per_pulse as u64 > super::super::cosim::LONG_RUN_CYCLES {
        o.profile = BuildProfile::Speed;
        o.digest_pulses = super::super::cosim::LONG_RUN_DIGEST_PULSES;
    }
    o.measure_bare = true;
    o.vcd_on_mismatch = false;
    let r = cosim(&chip.pixel, &o);
    let _ = std::fs::remove_dir_all(&work);
    let r = r?;
    let rate = |s: f64| r.cycles as f64 / s.max(1e-9);
    Ok(VsVerilator {
        cosim_cycles: r.cycles,
        cosim_pass: r.pass,
        cycle_model_cycles_per_cpu_s: r.model_cpu_seconds.map(rate),
        verilator_cycles_per_cpu_s: r.verilator_cpu_seconds.map(rate),
        cycle_model_vs_verilator: r.model_speedup(),
        bare_cycle_model_vs_verilator: r.bare_model_speedup(),
    })
}

/// Runs the benchmark.
pub fn run(args: &PixelBenchArgs) -> Result<(), CliError> {
    let design = crate::commands::load_design(args.config.as_deref())?;
    design.single_pixel("bench pixel")?;
    let isas = tofprobe_bench::isa::isas_to_measure(args.isa.as_deref())?;
    let report =
        tofprobe_bench::pixel::measure_isas(&design, args.pulses, args.cycle_pulses, &isas)?;
    let verilator = if args.verilator {
        Some(vs_verilator(args, args.cycle_pulses)?)
    } else {
        None
    };
    let mismatch = verilator.as_ref().is_some_and(|v| !v.cosim_pass);
    if args.json {
        let j = Json {
            report: &report,
            verilator,
        };
        println!("{}", serde_json::to_string(&j)?);
    } else {
        report.isas.iter().for_each(print_text);
        if let Some(v) = &verilator {
            let m = |r: Option<f64>| r.map_or("-".to_string(), |r| format!("{:.1}", r / 1e6));
            println!(
                "cycle model vs Verilator, {} cycles of the design's RTL ({}): cycle model {} M cycles per CPU-s, Verilator {} M: {:.1}x (bare models {})",
                v.cosim_cycles,
                if v.cosim_pass {
                    "bit-exact"
                } else {
                    "MISMATCH"
                },
                m(v.cycle_model_cycles_per_cpu_s),
                m(v.verilator_cycles_per_cpu_s),
                v.cycle_model_vs_verilator,
                v.bare_cycle_model_vs_verilator
                    .map_or("-".to_string(), |b| format!("{b:.1}x"))
            );
        }
    }
    if mismatch {
        return Err(CliError::option(
            "verilator",
            "a co-simulation mismatch",
            "a bit-exact RTL (run `tofprobe cosim` for the first mismatch)",
        ));
    }
    Ok(())
}

fn print_text(r: &PixelReport) {
    println!(
        "bit-true pixel, B = {} ({} registers, W = {} bits), one thread, ISA {}",
        r.bins, r.registers, r.width_bits, r.isa
    );
    println!(
        "transaction model  {} pulses in {:.4} s = {:.1} M pulses/s, {:.1}x real time (target <= {:.3} s)",
        r.pulses,
        r.transaction_seconds,
        r.transaction_pulses_per_s / 1e6,
        r.realtime_factor,
        r.target_seconds
    );
    if let (Some(cpu), Some(f)) = (r.transaction_cpu_seconds, r.cpu_realtime_factor) {
        println!(
            "  on its core      {cpu:.4} s of CPU time ({f:.1}x real time; wall time includes waiting for a shared core)"
        );
    }
    println!(
        "  pulse by pulse   {:.4} s (the per-pulse reference path)",
        r.pulse_by_pulse_seconds
    );
    println!(
        "folded driver      {:.4} s = {:.1} M pulses/s, {:.1}x real time{}; {:.2}x the transaction driver (L = {}, {})",
        r.fold_seconds,
        r.fold_pulses_per_s / 1e6,
        r.fold_realtime_factor,
        r.fold_cpu_realtime_factor
            .map(|f| format!(" ({f:.1}x on CPU time)"))
            .unwrap_or_default(),
        r.fold_speedup_vs_transaction,
        r.rom_depth,
        if r.fold_chosen {
            "chosen for this frame"
        } else {
            "not chosen: the transaction driver runs"
        }
    );
    println!(
        "segmented fold     {:.4} s = {:.1} M pulses/s, {:.1}x real time{}; {:.2}x the transaction driver, {:.2}x the fold ({} pulses repaired, {})",
        r.segmented_fold_seconds,
        r.segmented_fold_pulses_per_s / 1e6,
        r.segmented_fold_realtime_factor,
        r.segmented_fold_cpu_realtime_factor
            .map(|f| format!(" ({f:.1}x on CPU time)"))
            .unwrap_or_default(),
        r.segmented_speedup_vs_transaction,
        r.segmented_speedup_vs_fold,
        r.segmented_repaired_pulses,
        if r.segmented_chosen {
            "chosen for this frame"
        } else {
            "not chosen for this frame"
        }
    );
    println!(
        "real time          the chosen driver {} the {:.0}x target",
        if r.realtime_pass { "reaches" } else { "misses" },
        r.realtime_target
    );
    println!(
        "cycle model        {} cycles in {:.4} s = {:.1} M cycles/s ({:.3}x real time at {} cycles/pulse)",
        r.cycle_cycles,
        r.cycle_seconds,
        r.cycle_cycles_per_s / 1e6,
        r.cycle_realtime_factor,
        r.cycles_per_pulse
    );
    println!("pass               {}", r.pass);
}
