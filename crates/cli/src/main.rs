//! The `tofprobe` command: one subcommand per capability (see `commands/`). Errors are
//! printed as `error: …` on stderr with exit status 2; no input makes it panic.

mod commands;
mod error;

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
    quiet_on_closed_pipe();
    let cli = Cli::parse();
    match commands::run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// `tofprobe … | head` closes stdout early; `println!` then panics with "failed printing to
/// stdout: Broken pipe". That is the reader's choice, not an error: exit quietly with the
/// shell's status for SIGPIPE (128 + 13) instead of printing a panic. Every other panic
/// keeps the default report.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}
