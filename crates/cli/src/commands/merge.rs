//! `tofprobe merge SET... --out DIR`: joins the tile sets that `tofprobe simulate CONFIG
//! --out SET --shard i/n` wrote (one per task of a batch job array) into the array's output
//! set, the one `simulate CONFIG --out DIR` writes in one run (the same files, byte for
//! byte; `summary.json`'s timing sums the tiles'). Refuses, naming the set: a directory
//! that is not a whole tile set (its completion marker, every file's hash, a manifest that
//! agrees with the design it carries), sets of different designs (maps included) or seeds,
//! overlapping tiles, and pixels no set covers (`tofprobe_array::shard::merge_sets`).

use std::path::PathBuf;

use clap::Args;

use crate::error::CliError;

/// Arguments of `tofprobe merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The tile sets (`simulate --shard i/n --out SET`), in any order.
    #[arg(required = true, value_name = "SET")]
    sets: Vec<PathBuf>,
    /// Write the array's output set here (whole or absent, summary.json last).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Print the summary as one JSON object.
    #[arg(long)]
    json: bool,
    /// The largest output set to write, in GiB (default 16); checked, with the free disk
    /// space, before any tile is read.
    #[arg(long, value_name = "GIB")]
    max_out_gib: Option<f64>,
}

/// Runs the command.
pub fn run(args: &MergeArgs) -> Result<(), CliError> {
    let limits = super::simulate::set_limits(args.max_out_gib)?;
    let summary = tofprobe_array::shard::merge_sets(&args.sets, &args.out, limits)?;
    super::simulate::print_array(&summary, Some(&args.out), args.json)
}
