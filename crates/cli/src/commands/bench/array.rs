//! `tofprobe bench array [CONFIG] [--rows 64] [--cols 64] [--pulses 1000000,10000000]
//! [--json]`: the array model's speed, each `[array] level` side by side at the last N
//! (`tofprobe_bench::array` and `array_levels` measure; this prints).

use std::path::PathBuf;

use clap::Args;
use tofprobe_bench::array::ArrayReport;

use crate::error::CliError;

/// Arguments of `tofprobe bench array`.
#[derive(Debug, Args)]
pub struct ArrayBenchArgs {
    /// Configuration whose pixel, sensor and scene each array pixel gets (default: the
    /// embedded default); its own `[array]` maps are kept, the shape is `--rows × --cols`.
    config: Option<PathBuf>,
    /// Rows of the timed array.
    #[arg(long, default_value_t = 64)]
    rows: u32,
    /// Columns of the timed array.
    #[arg(long, default_value_t = 64)]
    cols: u32,
    /// Frame lengths to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1000000,10000000")]
    pulses: Vec<u64>,
    /// Instruction set of the vector kernels: scalar, avx2 or avx512 (default: every one
    /// this CPU runs, side by side, or the one TOFPROBE_ISA names).
    #[arg(long)]
    isa: Option<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs the benchmark.
pub fn run(args: &ArrayBenchArgs) -> Result<(), CliError> {
    let base = crate::commands::load_design(args.config.as_deref())?;
    let isas = tofprobe_bench::isa::isas_to_measure(args.isa.as_deref())?;
    let report =
        tofprobe_bench::array::measure_isas(&base, (args.rows, args.cols), &args.pulses, &isas)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        report.isas.iter().for_each(print_text);
    }
    Ok(())
}

fn print_text(r: &ArrayReport) {
    println!(
        "array model, {} × {} pixels of {} on {} threads, ISA {}",
        r.rows, r.cols, r.configuration, r.threads, r.isa
    );
    for run in &r.runs {
        println!(
            "N = {:>9}: {:.2} s, {:.1} M pixel-pulses/s{}; Monte Carlo alone {:.1} M pulses/CPU-s (model share {:.0} %)",
            run.pulses,
            run.seconds,
            run.pixel_pulses_per_s / 1e6,
            run.pixel_pulses_per_cpu_s
                .map(|c| format!(" ({:.1} M per CPU-s)", c / 1e6))
                .unwrap_or_default(),
            run.monte_carlo_pulses_per_cpu_s / 1e6,
            100.0 * run.model_share
        );
        if let Some(s) = run.seconds_on_2_idle_cores {
            println!("  64 × 64 at this N on 2 idle cores: {s:.1} s");
        }
        if let Some(m) = run.peak_memory_bytes {
            println!("  peak memory {:.1} MB", m as f64 / 1e6);
        }
    }
    println!(
        "target: 64 × 64, N = 10^7 in <= {:.0} s on 2 cores: projected {} s, {}",
        r.target_seconds,
        r.projected_64x64_1e7_seconds
            .map_or("?".to_string(), |s| format!("{s:.0}")),
        if r.pass { "pass" } else { "FAIL" }
    );
    if let Some(n) = r.levels.first().map(|l| l.pulses) {
        println!(
            "levels at N = {n} (each in the same run; 256 × 256 × 10^7 projected on 2 idle cores):"
        );
    }
    for l in &r.levels {
        let judged = match (l.target_seconds, l.pass) {
            (Some(t), Some(p)) => {
                format!(" (target {t:.0} s: {})", if p { "pass" } else { "FAIL" })
            }
            _ => String::new(),
        };
        println!(
            "  {:<12} {:>8.3} CPU-s ({:.3} model), {:.3e} pixel-pulses/CPU-s, {:>8.1}× bit-true, \
             {} bit-true pixels; projected {:.1} s{judged}",
            l.level,
            l.cpu_seconds,
            l.model_cpu_seconds,
            l.pixel_pulses_per_cpu_second,
            l.speedup_over_bit_true,
            l.bit_true_pixels,
            l.projected_256x256_1e7_seconds,
        );
    }
}
