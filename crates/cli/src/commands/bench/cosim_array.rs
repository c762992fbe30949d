//! `tofprobe bench cosim-array CONFIG [--rows 16] [--cols 16] [--frame-pulses N]
//! [--rom-depth L] [--layouts flat,hierarchical] [--json]`: the whole array co-simulated, each Verilator
//! layout built cold side by side (`tofprobe_flow::array::cosim_bench` measures; this
//! prints).

use std::path::PathBuf;

use clap::Args;
use tofprobe_cosim::array::Layout;
use tofprobe_flow::array::cosim_bench::{CosimBenchReport, CosimBenchSpec, measure};

use crate::error::CliError;

/// Arguments of `tofprobe bench cosim-array`.
#[derive(Debug, Args)]
pub struct CosimArrayBenchArgs {
    /// An `[array]` configuration (e.g. scenes/sensor-64x64.toml); its shape is replaced by
    /// `--rows × --cols`.
    config: PathBuf,
    /// Rows of the co-simulated array.
    #[arg(long, default_value_t = 16)]
    rows: u32,
    /// Columns of the co-simulated array.
    #[arg(long, default_value_t = 16)]
    cols: u32,
    /// Pulses per frame N (default: the configuration's).
    #[arg(long)]
    frame_pulses: Option<u64>,
    /// A sign-probe ROM of this depth instead of the configuration's (as `rtl --rom-depth`).
    #[arg(long)]
    rom_depth: Option<usize>,
    /// Layouts to build, comma-separated: `flat`, `hierarchical`.
    #[arg(long, value_delimiter = ',', default_value = "flat,hierarchical")]
    layouts: Vec<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

fn layout(name: &str) -> Result<Layout, CliError> {
    match name {
        "flat" => Ok(Layout::Flat),
        "hierarchical" => Ok(Layout::Hierarchical),
        other => Err(tofprobe_flow::error::FlowError::option(
            "layouts",
            other,
            "flat, hierarchical (comma-separated)",
        )
        .into()),
    }
}

/// Runs the benchmark.
pub fn run(args: &CosimArrayBenchArgs) -> Result<(), CliError> {
    let layouts = args
        .layouts
        .iter()
        .map(|n| layout(n))
        .collect::<Result<Vec<_>, _>>()?;
    let base = crate::commands::load_design(Some(&args.config))?;
    let spec = CosimBenchSpec {
        rows: args.rows,
        cols: args.cols,
        frame_pulses: args.frame_pulses,
        rom_depth: args.rom_depth,
    };
    let report = measure(&base, spec, &layouts)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_text(r: &CosimBenchReport) {
    println!(
        "whole-array co-simulation, {} × {} pixels of {}, N = {}, one frame and its readout",
        r.rows, r.cols, r.configuration, r.frame_pulses
    );
    for t in &r.layouts {
        println!(
            "{:>12}: build {:.1} s (tools {} CPU-s), run {:.2} s, {} cycles, {} mismatches: {}",
            t.layout,
            t.build_seconds,
            t.tools_cpu_seconds
                .map_or("?".to_string(), |c| format!("{c:.1}")),
            t.run_seconds,
            t.cycles,
            t.mismatches,
            if t.pass { "PASS" } else { "FAIL" }
        );
    }
    if let Some(x) = r.flat_over_hierarchical_build_cpu {
        println!("flat / hierarchical tools CPU: {x:.2}");
    }
}
