//! `tofprobe check-set DIR`: whether DIR holds a whole output set (`rtl`, `vectors`,
//! `reproduce`, `flow`, `layout`, an array's `simulate --out` or `merge` set, a tile set of
//! `simulate --shard`): its completion marker (`tofprobe-set.toml`, or a vector set's
//! `manifest.toml`) is there and every file it lists has the recorded FNV-1a-64 hash
//! (`tofprobe_io::check_set`, the check `cosim --rtl` and `flow` make). For users of the
//! FuseSoC core and scripts: exit 0 and one line when whole, exit 2 naming what is missing
//! or changed when not (a set killed mid-commit has no marker: the message names the files
//! the cut commit moved in beside the old set's and those still staged).

use std::path::PathBuf;

use clap::Args;

use crate::error::CliError;

/// Arguments of `tofprobe check-set`.
#[derive(Debug, Args)]
pub struct CheckSetArgs {
    /// The set's directory.
    pub dir: PathBuf,
}

/// The marker completing the set in `dir`: the generic one when present, else a vector
/// set's manifest when present, else the generic one (whose absence the check reports).
pub fn marker_of(dir: &std::path::Path) -> &'static str {
    if !dir.join(tofprobe_io::SET_MARKER).exists() && dir.join("manifest.toml").exists() {
        "manifest.toml"
    } else {
        tofprobe_io::SET_MARKER
    }
}

/// Checks the set in `dir` strictly (every listed file with its recorded hash); the error
/// says why it is not whole.
pub fn check(dir: &std::path::Path) -> Result<Vec<String>, CliError> {
    tofprobe_io::check_set(dir, marker_of(dir)).map_err(CliError::IncompleteSet)
}

/// The check of a reader that runs what it finds (`cosim --rtl`): a set without its marker
/// or missing a listed file (killed mid-commit) is refused; files edited since the commit (a
/// deliberately mutated RTL) are named in a warning on stderr and read as they are.
pub fn check_reader(dir: &std::path::Path) -> Result<(), CliError> {
    let s = tofprobe_io::inspect_set(dir, marker_of(dir)).map_err(CliError::IncompleteSet)?;
    if !s.changed.is_empty() {
        eprintln!(
            "warning: {}: changed since it was written: {}; using them as they are",
            dir.display(),
            s.changed.join(", ")
        );
    }
    Ok(())
}

/// Runs `tofprobe check-set`.
pub fn run(a: &CheckSetArgs) -> Result<(), CliError> {
    let files = check(&a.dir)?;
    println!(
        "{}: whole output set, {} file(s) as {} lists them",
        a.dir.display(),
        files.len(),
        marker_of(&a.dir)
    );
    Ok(())
}
