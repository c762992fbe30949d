//! `tofprobe tradeoff [CONFIG...] [--json] [--out DIR] [--verilator]`: every fidelity level on each
//! configuration (the embedded default without one), timed per simulated second and
//! scored against the float DFT and the scene's truth; a Markdown table on stdout (or one
//! JSON object), and with `--out` the table (`tradeoff.md`) and the Pareto plot
//! (`pareto.svg`), written atomically.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;

use crate::commands::spectrum_svg::write_atomic;
use crate::config::Config;
use crate::error::CliError;
use crate::tradeoff::{SceneResult, markdown, measure, plot::pareto_svg};

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
    /// Write tradeoff.md and pareto.svg into this directory.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Serialize)]
struct JsonOut<'a> {
    scenes: &'a [SceneResult],
}

/// Runs the command.
pub fn run(args: &TradeoffArgs) -> Result<(), CliError> {
    let paths: Vec<Option<&std::path::Path>> = if args.configs.is_empty() {
        vec![None]
    } else {
        args.configs.iter().map(|p| Some(p.as_path())).collect()
    };
    let mut scenes = Vec::new();
    for p in paths {
        let loaded = Config::load(p)?;
        scenes.push(measure(&loaded.config, &loaded.origin, args.verilator)?);
    }
    let table: String = scenes.iter().map(markdown).collect::<Vec<_>>().join("\n");
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| CliError::Output {
            path: dir.clone(),
            message: e.to_string(),
        })?;
        write_atomic(&dir.join("tradeoff.md"), table.as_bytes())?;
        pareto_svg(&dir.join("pareto.svg"), &scenes)?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&JsonOut { scenes: &scenes })?);
    } else {
        print!("{table}");
    }
    Ok(())
}
