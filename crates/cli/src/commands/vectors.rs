//! `tofprobe vectors [CONFIG] --out DIR`: golden vectors (testbench/README.md) for the
//! configuration: stimulus, ROM image, expected readouts, the register-write trace (or, for
//! long runs, per-window digests only) and a TOML manifest. The ROM is the configuration's
//! ΣΔ probe ROM when the simulated frame can hold it, else the sign probe (`probe_rom`).

use std::path::PathBuf;

use clap::Args;
use tofprobe_design::RtlOverrides;
use tofprobe_design::{Chip, RomPurpose};
use tofprobe_rtlgen::stimulus::random_stimulus;
use tofprobe_rtlgen::vectors::golden_run;
use tofprobe_rtlgen::vectors::{VectorOptions, write_vectors};

use crate::error::CliError;

/// Arguments of `tofprobe vectors`.
#[derive(Debug, Args)]
pub struct VectorsArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Frames.
    #[arg(long, default_value_t = 2)]
    pub frames: u64,
    /// Stimulus seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Override the pulses per frame N (short frames).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
    /// Override the ROM depth L (forces the sign-of-cosine probe ROM).
    #[arg(long)]
    pub rom_depth: Option<usize>,
    /// Pulses per digest window.
    #[arg(long, default_value_t = 1)]
    pub digest_pulses: u64,
}

/// Runs `tofprobe vectors`.
pub fn run(a: &VectorsArgs) -> Result<(), CliError> {
    let overrides = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    let (design, _) = super::simulated_design(a.frames, a.config.as_deref(), &overrides)?;
    let chip = Chip::of(&design, &overrides, RomPurpose::Replayed)?;
    let (p, rom, note) = (chip.pixel, chip.rom.words, chip.rom.note);
    let stim = random_stimulus(&p, a.frames * p.frame_pulses, a.seed);
    let o = VectorOptions {
        frames: a.frames,
        seed: a.seed,
        digest_pulses: a.digest_pulses.max(1),
        trace_window: None,
        directed: None,
    };
    let (g, w) =
        golden_run(&p, &stim, &rom, &o).map_err(tofprobe_experiments::ExperimentError::from)?;
    let m = write_vectors(&a.out, &p, &stim, &rom, &g, w, &o)?;
    println!(
        "vectors: {} frames, {} pulses, {} cycles, {} trace events, {} digest windows, hash {} -> {}; {note}",
        m.frames,
        m.pulses,
        m.cycles,
        m.trace_events,
        m.digest_windows,
        m.config_hash,
        a.out.display()
    );
    Ok(())
}
