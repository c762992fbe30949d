//! The `tofprobe` command: one subcommand per capability (see `commands/`). Errors are
//! printed as `error: …` on stderr with exit status 2; no input makes it panic. An interrupt
//! (SIGINT, SIGTERM) removes the run's temporaries and exits with 130.

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
    remove_temporaries_on_interrupt();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    // The ISA the environment forces is checked before any kernel runs (a kernel cannot
    // return the refusal).
    if let Err(e) = tofprobe_io::isa::from_env() {
        eprintln!("error: {}", error::CliError::from(e));
        return ExitCode::from(2);
    }
    let result = commands::run(cli.command);
    // Output still buffered (a `print!` without newline) fails here, not silently at exit.
    if let Err(e) = std::io::Write::flush(&mut std::io::stdout()) {
        return stdout_failed(&e.to_string());
    }
    match result {
        Ok(commands::Verdict::Done) => ExitCode::SUCCESS,
        Ok(commands::Verdict::Fail) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// SIGINT (Ctrl-C), SIGTERM or SIGHUP: remove every temporary the run registered (staged
/// output sets, atomic-write temporaries, Verilator builds in progress; see
/// `tofprobe_io::live`) and exit with 130, the shell's status for an interrupt. The old
/// output set stays whole. The handler runs on ctrlc's own thread, not in signal context.
fn remove_temporaries_on_interrupt() {
    if let Err(e) = ctrlc::set_handler(|| {
        eprintln!("tofprobe: interrupted; removing temporaries");
        tofprobe_io::live::remove_all_and_exit(130)
    }) {
        // Without the handler a signal still ends the run; the next run cleans the
        // temporaries (tofprobe_io::stale). Say so rather than fail.
        eprintln!(
            "warning: no interrupt handler ({e}); temporaries of an interrupted run are removed by the next run"
        );
    }
}

/// What clap ends the run with: `--help` and `--version` printed on standard output
/// (and checked: into a full disk they are an error, exit 2, not a silent 0), usage
/// errors on standard error with clap's status (2).
fn clap_exit(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    use std::io::Write;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        let mut out = std::io::stdout().lock();
        let text = e.render().to_string();
        return match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(err) if err.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::from(141),
            Err(err) => stdout_failed(&err.to_string()),
        };
    }
    let _ = e.print();
    ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
}

/// Standard output cannot be written (`> /dev/full`, a full disk): an error, exit status 2.
/// A set the command committed before is whole on disk, and the message names it: the
/// set is the command's result, its summary on standard output a report of it.
fn stdout_failed(message: &str) -> ExitCode {
    eprintln!(
        "error: cannot write to standard output: {message}{}",
        written_note()
    );
    ExitCode::from(2)
}

/// "; the output set(s) … were written whole before" for the sets this run committed.
fn written_note() -> String {
    let sets = tofprobe_io::committed_sets();
    if sets.is_empty() {
        return String::new();
    }
    let names: Vec<String> = sets.iter().map(|p| p.display().to_string()).collect();
    format!(
        "; the output set {} was written whole before (only its summary is missing)",
        names.join(", ")
    )
}

/// `tofprobe … | head` closes stdout early; `println!` then panics with "failed printing to
/// stdout: Broken pipe". That is the reader's choice, not an error: exit quietly with the
/// shell's status for SIGPIPE (128 + 13) instead of printing a panic. Any other failure to
/// print (`> /dev/full`) is an error like any other: `error: …`, exit status 2, no panic
/// report. Every other panic keeps the default report.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") {
            if msg.contains("Broken pipe") {
                std::process::exit(141);
            }
            let reason = msg.split(": ").skip(1).collect::<Vec<_>>().join(": ");
            eprintln!(
                "error: cannot write to standard output: {reason}{}",
                written_note()
            );
            std::process::exit(2);
        }
        default(info);
    }));
}
