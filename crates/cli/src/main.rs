//! The `tofprobe` command: one subcommand per capability (see `commands/`). Errors are
//! printed as `error: …` on stderr with exit status 2; no input makes it panic.

mod commands;
mod config;
mod error;
mod paper;
mod tradeoff;

use std::process::ExitCode;

use clap::Parser;

/// One-bit frequency probing in a direct time-of-flight pixel: simulate, model, generate
/// and verify the pixel.
#[derive(Debug, Parser)]
#[command(name = "tofprobe", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: commands::Command,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match commands::run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
