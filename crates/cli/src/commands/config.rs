//! `tofprobe config`: print the embedded default configuration, or check a file (the
//! analysis mode, and why when `pixel.mode = "auto"` picked it, and the resolution's notes).
//! The check is the pure resolution: no tool runs unless `--time-adders` asks for the
//! `adders = "auto"` choice.

use std::path::PathBuf;

use clap::Args;

use tofprobe_design::DEFAULT_TOML;

use crate::error::CliError;

/// Arguments of `tofprobe config`.
#[derive(Debug, Args)]
pub struct ConfigArgs {
    /// Print the embedded default configuration (TOML) and exit.
    #[arg(long)]
    print_default: bool,
    /// Decide `adders = "auto"` now (synthesis and static timing, cached) instead of leaving
    /// it to the hardware commands: checking a configuration runs no tool otherwise.
    #[arg(long)]
    time_adders: bool,
    /// A configuration file to validate (without it: the embedded default).
    config: Option<PathBuf>,
}

/// Prints the default, or resolves the configuration (the one resolution every command
/// uses) and reports its key numbers.
pub fn run(args: &ConfigArgs) -> Result<(), CliError> {
    if args.print_default {
        print!("{DEFAULT_TOML}");
        return Ok(());
    }
    let design = if args.time_adders {
        crate::commands::load_for_hardware(args.config.as_deref())?
    } else {
        crate::commands::load_design(args.config.as_deref())?
    };
    let c = &design.document;
    println!(
        "{}: ok ({} pulses at {} Hz, {} TDC codes of {} ps = {} bits, jitter {} mm)",
        design.origin,
        c.pulses(),
        c.sensor.laser_rate_hz,
        c.sensor.tdc_codes(),
        c.sensor.tdc_lsb_ps,
        c.sensor.tdc_bits(),
        c.sensor.jitter_mm()
    );
    println!("analysis mode: {}", design.mode.line());
    if design.pixel.mode == tofprobe_pixel::Mode::Haar {
        println!(
            "Haar pixel: N = {} pulses, U = {} ({} registers), W = {} bits",
            design.pixel.frame_pulses,
            design.pixel.haar_scales,
            design.pixel.registers(),
            design.pixel.width
        );
    }
    for n in &design.notes {
        println!("note: {n}");
    }
    Ok(())
}
