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
/// The command line that regenerates an array's vectors (recorded in their headers), paths
/// as typed from the working directory.
fn regen_command(a: &VectorsArgs) -> String {
    use tofprobe_io::text::path_as_typed;
    let mut s = String::from("tofprobe vectors");
    if let Some(c) = &a.config {
        s.push_str(&format!(" {}", path_as_typed(c)));
    }
    s.push_str(&format!(
        " --out {} --frames {}",
        path_as_typed(&a.out),
        a.frames
    ));
    if let Some(n) = a.frame_pulses {
        s.push_str(&format!(" --frame-pulses {n}"));
    }
    if let Some(l) = a.rom_depth {
        s.push_str(&format!(" --rom-depth {l}"));
    }
    s
}

pub fn run(a: &VectorsArgs) -> Result<(), CliError> {
    let overrides = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    let design = super::load_for_hardware(a.config.as_deref())?;
    if design.array.is_some() {
        // An array's vectors: every pixel's own scene stream (not --seed's random one).
        let v = tofprobe_flow::array::write_array_vectors(
            &design,
            &overrides,
            a.frames,
            None,
            None,
            &a.out,
            &regen_command(a),
        )?;
        println!(
            "vectors: {} x {} array, {} frames, N = {}, {} cycles, {} beats per frame -> {}; {}",
            v.readout.rows,
            v.readout.cols,
            a.frames,
            v.readout.frame_pulses,
            v.run.cycles(),
            v.readout.beats_per_frame(),
            a.out.display(),
            v.chip.rom.note
        );
        return Ok(());
    }
    if a.frames == 0 || a.frames > 1000 {
        return Err(CliError::option("frames", a.frames, "1..=1000"));
    }
    let (design, _) = super::simulated_design_of(design, &overrides)?;
    let chip = Chip::of(&design, &overrides, RomPurpose::Replayed)?;
    let (p, rom, note) = (chip.pixel, chip.rom.words, chip.rom.note);
    super::check_stimulus(a.frames, p.frame_pulses, a.frame_pulses.is_some())?;
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
