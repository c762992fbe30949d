//! `tofprobe rtl [CONFIG] --out DIR`: renders the pixel, probe ROM and top of the resolved
//! design into DIR, atomically, refusing to overwrite files it did not generate. The probe
//! ROM is the design's ΣΔ ROM (for the default, periodic L = 20,000, 32 bitstreams)
//! whenever it is at most 2^16 entries deep; a windowed ROM of a long frame (L = N) or
//! `--rom-depth` renders the sign-of-cosine probe instead, and the command says which
//! (`tofprobe_design::rom_policy`). Beside the RTL it writes the FuseSoC core
//! (`<prefix>.core`: `lint`, `synth`, and `sim` with `--core-vectors`/`--core-testbench`)
//! and the core's yosys script, in the same atomic set; an array's set also carries its
//! verification kit (`--kit-frames`, `tofprobe_rtlgen::kit`).

use std::path::PathBuf;

use clap::Args;
use tofprobe_design::{ResolvedDesign, RtlOverrides};
use tofprobe_flow::array::{ArrayKit, render_array_design};
use tofprobe_flow::rtl::{CoreSimPaths, render_design};

use crate::error::CliError;

/// Arguments of `tofprobe rtl`.
#[derive(Debug, Args)]
pub struct RtlArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Override the ROM depth L and render the sign-of-cosine probe ROM instead of the ΣΔ
    /// ROM (default: the configuration's ΣΔ ROM; 4096 sign entries when that exceeds 65536).
    #[arg(long)]
    pub rom_depth: Option<usize>,
    /// Override the pulses per frame N (e.g. short frames for co-simulation).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
    /// Give the FuseSoC core a `sim` target replaying these golden vectors (from `tofprobe
    /// vectors` with the same configuration and overrides); recorded relative to DIR.
    #[arg(long, value_name = "VECDIR", requires = "core_testbench")]
    pub core_vectors: Option<PathBuf>,
    /// The testbench the core's `sim` target compiles (the repository's testbench/tb.v);
    /// recorded relative to DIR.
    #[arg(long, value_name = "FILE", requires = "core_vectors")]
    pub core_testbench: Option<PathBuf>,
    /// An `[array]` configuration's set carries its verification kit (the self-checking
    /// testbench and the golden vectors of this many frames, beside the RTL; the core's
    /// `sim` and `sim_verilator` targets run it): 0..=100, 0 for none (default 2).
    #[arg(long, value_name = "K")]
    pub kit_frames: Option<u64>,
}

/// The command line that regenerates `out` (recorded in every header): paths as the user
/// would type them from the working directory, canonical and sanitised
/// (`tofprobe_io::text::path_as_typed`), so no text of the command line reaches a header
/// raw, `X`, `./X/` and `/abs/X` give the same bytes, and no machine's absolute path is
/// recorded.
pub fn regen_command(a: &RtlArgs) -> String {
    use tofprobe_io::text::path_as_typed as canonical_path;
    let mut s = String::from("tofprobe rtl");
    if let Some(c) = &a.config {
        s.push_str(&format!(" {}", canonical_path(c)));
    }
    s.push_str(&format!(" --out {}", canonical_path(&a.out)));
    if let Some(n) = a.frame_pulses {
        s.push_str(&format!(" --frame-pulses {n}"));
    }
    if let Some(l) = a.rom_depth {
        s.push_str(&format!(" --rom-depth {l}"));
    }
    if let Some(k) = a.kit_frames {
        s.push_str(&format!(" --kit-frames {k}"));
    }
    if let (Some(v), Some(t)) = (&a.core_vectors, &a.core_testbench) {
        s.push_str(&format!(
            " --core-vectors {} --core-testbench {}",
            canonical_path(v),
            canonical_path(t)
        ));
    }
    s
}

/// Runs `tofprobe rtl`.
pub fn run(a: &RtlArgs) -> Result<(), CliError> {
    let design = crate::commands::load_for_hardware(a.config.as_deref())?;
    if design.array.is_some() {
        return rtl_array(a, &design);
    }
    if a.kit_frames.is_some() {
        return Err(CliError::option(
            "kit-frames",
            "given",
            "an [array] configuration only (the pixel's core replays vectors given by \
             --core-vectors/--core-testbench)",
        ));
    }
    let overrides = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    let sim = match (&a.core_vectors, &a.core_testbench) {
        (Some(v), Some(t)) => Some(CoreSimPaths {
            vectors_dir: v.clone(),
            testbench: t.clone(),
        }),
        _ => None,
    };
    let r = render_design(&design, &overrides, &a.out, regen_command(a), sim.as_ref())?;
    let p = &r.params;
    println!(
        "rtl: {:?} pixel, {} registers x {} bits, {} adder(s), {} cycles/pulse, N = {}, L = {}, hash {} -> {} ({}); {}",
        p.mode,
        p.registers(),
        p.width,
        p.adders,
        p.cycles_per_pulse,
        p.frame_pulses,
        p.rom_depth,
        tofprobe_rtlgen::config_hash(p),
        a.out.display(),
        r.files.join(", "),
        r.rom_note
    );
    Ok(())
}

/// `tofprobe rtl` on an array design.
fn rtl_array(a: &RtlArgs, design: &ResolvedDesign) -> Result<(), CliError> {
    if a.core_vectors.is_some() {
        return Err(CliError::option(
            "core-vectors",
            "given",
            "the pixel's top only (an array is co-simulated by `tofprobe cosim`)",
        ));
    }
    let o = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    let kit_frames = a
        .kit_frames
        .unwrap_or(tofprobe_rtlgen::kit::KIT_DEFAULT_FRAMES);
    let (chip, files, kit) = render_array_design(design, &o, &a.out, regen_command(a), kit_frames)?;
    let p = &chip.pixel;
    let ro = chip.readout.as_ref();
    println!(
        "rtl: {} x {} array of {:?} pixels ({} registers x {} bits), N = {}, L = {}; readout {} bits x {} beat(s) per word, slot {} cycles, {} cycles per readout -> {} ({}); {}",
        chip.rows,
        chip.cols,
        p.mode,
        p.registers(),
        p.width,
        p.frame_pulses,
        p.rom_depth,
        ro.map(|r| r.bits).unwrap_or(0),
        ro.map(|r| r.beats_per_word).unwrap_or(0),
        ro.map(|r| r.slot_cycles()).unwrap_or(0),
        ro.map(|r| r.readout_cycles()).unwrap_or(0),
        a.out.display(),
        files.join(", "),
        chip.rom.note
    );
    match kit {
        ArrayKit::Written { frames, cycles } => println!(
            "rtl: verification kit: {} with {frames} frame(s) of golden vectors ({cycles} cycles) in the set; \
             run it with its core's `sim`/`sim_verilator` targets or testbench/README.md's commands",
            tofprobe_rtlgen::kit::KIT_TESTBENCH
        ),
        ArrayKit::Omitted(why) => println!("rtl: {why}"),
    }
    Ok(())
}
