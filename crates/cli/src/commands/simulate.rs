//! `tofprobe simulate [CONFIG] [--json] [--svg PATH]`: run the photon/TDC Monte Carlo and
//! summarise the record (pulses, detections, background wins, mean and σ of the measured
//! depth, run time), then run one frame through the bit-true pixel (transaction model) and
//! print its spectrum at the configured bins (amplitude µm, phase, the noise estimate);
//! `--svg` plots that spectrum. On a Haar pixel the frame's registers become the transient
//! analysis instead: coefficients, per-scale thresholds at a stated false-alarm rate,
//! events; `--json` carries the scalogram and the events, `--svg` draws the scalogram.
//! `tofprobe_experiments::simulation` computes; this shows the progress bar and prints.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use tofprobe_experiments::simulation::simulate;

use crate::error::CliError;

/// Arguments of `tofprobe simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML); without it the embedded default (paper Fig. 8) is used.
    config: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Write an SVG plot of the bit-true spectrum (Haar: the scalogram) here (atomically).
    #[arg(long, value_name = "PATH")]
    svg: Option<PathBuf>,
    /// An `[array]` configuration: write the array's set here (registers and maps as
    /// .npy, heat maps, the deflection animation, the UFF file, summary.json last).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// An `[array]` configuration with --out: run only tile i of n (0-based) and write its
    /// tile set (`tofprobe merge` joins the sets into the --out set of one run).
    #[arg(long, value_name = "I/N", requires = "out")]
    shard: Option<String>,
    /// With --out: the largest output set to write, in GiB (default 16); the set's size is
    /// estimated and checked, with the free disk space, before the model runs.
    #[arg(long, value_name = "GIB", requires = "out")]
    max_out_gib: Option<f64>,
}

/// `--max-out-gib` as the array's set limits: a finite number of GiB in (0, 2^20] (a
/// pebibyte is past any disk), the default 16.
pub fn set_limits(max_out_gib: Option<f64>) -> Result<tofprobe_array::output::SetLimits, CliError> {
    let Some(gib) = max_out_gib else {
        return Ok(tofprobe_array::output::SetLimits::default());
    };
    if !(gib.is_finite() && gib > 0.0 && gib <= (1u64 << 20) as f64) {
        return Err(CliError::option(
            "max-out-gib",
            tofprobe_io::text::number(gib),
            "0 < GiB <= 1048576 (default 16)",
        ));
    }
    Ok(tofprobe_array::output::SetLimits {
        max_set_bytes: (gib * (1u64 << 30) as f64) as u64,
    })
}

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let design = crate::commands::load_design(args.config.as_deref())?;
    if design.array.is_some() {
        return run_array(args, &design);
    }
    if let Some(shard) = &args.shard {
        return Err(CliError::option(
            "shard",
            shard,
            "an [array] configuration (a single pixel is one task)",
        ));
    }
    if let Some(out) = &args.out {
        return Err(CliError::option(
            "out",
            out.display(),
            "an [array] configuration (a single pixel's output is stdout and --svg)",
        ));
    }
    // The progress bar appears on a terminal only once the run has taken a second.
    let on_terminal = !args.json && std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(Some(design.pulses()), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} pulses ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = Instant::now();
    let mut shown = false;
    let sim = simulate(&design, |done| {
        if on_terminal && !shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            shown = true;
        }
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let sim = sim?;
    if let Some(path) = &args.svg {
        tofprobe_experiments::simulation::write_plot(&sim, &design, path)?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&sim)?);
        return Ok(());
    }
    let s = &sim.summary;
    let (bit_true, haar) = (&sim.bit_true, &sim.haar);
    println!("configuration      {}", design.origin);
    println!("analysis mode      {}", design.mode.line());
    for n in &design.notes {
        println!("note               {n}");
    }
    println!("pulses             {}", s.pulses);
    println!(
        "detections         {} ({:.4} per pulse)",
        s.detections, s.detection_rate
    );
    println!("background wins    {}", s.background_wins);
    let stat = |x: Option<f64>, none: &str| x.map_or(none.to_string(), |v| format!("{v:.4} mm"));
    println!(
        "mean depth         {}",
        stat(s.mean_depth_mm, "none (no detections)")
    );
    println!(
        "sigma depth        {}",
        stat(s.sigma_depth_mm, "none (fewer than 2 detections)")
    );
    println!(
        "run time           {:.3} s ({:.1} M pulses/s)",
        s.seconds,
        s.pulses as f64 / s.seconds.max(1e-9) / 1e6
    );
    match (bit_true, haar) {
        (_, Some(h)) => {
            println!(
                "bit-true Haar      W = {} bits, N = {} pulses, U = {} (model {:.2} s)",
                h.width_bits, h.frame_pulses, h.analysis.scalogram.scales, h.model_seconds
            );
            print!("{}", h.analysis.text());
        }
        (None, None) => {}
        (Some(b), None) => {
            println!(
                "bit-true spectrum  W = {} bits, N = {} pulses (ROM {:.2} s, model {:.2} s)",
                b.width_bits, b.frame_pulses, b.rom_seconds, b.model_seconds
            );
            let wrap = b
                .rom_wrap_summary
                .as_ref()
                .map(|w| format!(", {w}"))
                .unwrap_or_default();
            println!("  probe ROM {} L = {}{wrap}", b.rom_mode, b.rom_depth);
            match b.noise_estimate_um {
                None => println!("  spectrum           none (no detections in the frame)"),
                Some(noise) => {
                    println!("  frequency Hz   amplitude um    phase deg");
                    for bin in &b.bins {
                        println!(
                            "  {:>12.2} {:>14.4} {:>12.2}",
                            bin.frequency_hz,
                            bin.amplitude_um.unwrap_or(0.0),
                            bin.phase_deg.unwrap_or(0.0)
                        );
                    }
                    println!("  noise estimate {noise:.4} um (median over bins)");
                }
            }
        }
    }
    if let Some(p) = &args.svg {
        if haar.is_some() {
            println!("scalogram plot     {}", p.display());
        } else {
            println!("spectrum plot      {}", p.display());
        }
    }
    Ok(())
}

/// `simulate` of an `[array]` configuration: the array's set into `--out`, the summary
/// printed.
fn run_array(
    args: &SimulateArgs,
    design: &tofprobe_design::ResolvedDesign,
) -> Result<(), CliError> {
    if let Some(svg) = &args.svg {
        return Err(CliError::option(
            "svg",
            svg.display(),
            "no --svg for an [array] configuration: its maps are written with --out DIR",
        ));
    }
    if let (Some(shard), Some(dir)) = (&args.shard, &args.out) {
        let shard = tofprobe_array::shard::Shard::parse(shard)
            .map_err(|e| CliError::option("shard", shard, e))?;
        let m = tofprobe_array::shard::run_shard(design, shard, dir)?;
        if args.json {
            println!(
                "{}",
                serde_json::json!({
                    "shard": shard.to_string(), "rows": m.rows, "cols": m.cols,
                    "design_hash": m.design_hash, "seed": m.seed,
                    "model_seconds": m.model_seconds, "tile_set": dir,
                })
            );
        } else {
            println!(
                "tile set           {} (shard {shard}: rows {:?} × cols {:?} of {} × {}, seed {}, design {}; model {:.3} s)",
                dir.display(),
                m.rows,
                m.cols,
                m.array_rows,
                m.array_cols,
                m.seed,
                m.design_hash,
                m.model_seconds
            );
        }
        return Ok(());
    }
    let summary = match &args.out {
        Some(dir) => {
            tofprobe_array::output::run_and_write(design, dir, set_limits(args.max_out_gib)?)?
        }
        None => tofprobe_array::output::simulate(design)?.2,
    };
    print_array(&summary, args.out.as_deref(), args.json)
}

/// Prints an array run's summary (`simulate` of an array, `merge`).
pub fn print_array(
    summary: &tofprobe_array::output::ArraySummary,
    out: Option<&std::path::Path>,
    json: bool,
) -> Result<(), CliError> {
    if json {
        println!("{}", serde_json::to_string(&summary)?);
        return Ok(());
    }
    println!("configuration      {}", summary.configuration);
    println!(
        "array              {} × {} pixels{}, pitch {} um, {:.4} mm per pixel on the scene",
        summary.rows,
        summary.cols,
        match summary.superpixel {
            1 => String::new(),
            g => format!(" (superpixels of {g} × {g} SPADs, their detections averaged)"),
        },
        summary.pitch_um,
        summary.mm_per_pixel
    );
    println!(
        "frame              {} pulses per pixel, {} mode, {:.1} detections per pixel",
        summary.frame_pulses, summary.mode, summary.mean_detections_per_pixel
    );
    println!(
        "array model        {:.3} s ({:.1} M pixel-pulses/s)",
        summary.model_seconds,
        summary.pixel_pulses_per_s / 1e6
    );
    if !summary.bins.is_empty() {
        println!("  bin  frequency Hz  mean um    max um");
        for b in &summary.bins {
            println!(
                "  {:>3} {:>13.2} {:>8.4} {:>9.4}",
                b.index, b.frequency_hz, b.mean_amplitude_um, b.max_amplitude_um
            );
        }
    }
    if let (Some(b), Some(f)) = (summary.dominant_bin, summary.dominant_frequency_hz) {
        println!("dominant bin       {b} ({f:.2} Hz)");
    }
    if let Some(dir) = out {
        println!(
            "output set         {} ({} files)",
            dir.display(),
            summary.files.len()
        );
    }
    Ok(())
}
