//! One co-simulation: render (or take) the RTL, run the pixel crate's cycle model (the
//! judge) through the contract's sequencer for the golden vectors, build the harness (cached), replay, and on
//! a mismatch pin it down to the first cycle (re-running a digest window with its full
//! trace) and write a VCD around it.

mod steps;

use crate::check;
use crate::error::CosimError;
use crate::harness::{Mismatch, RunOutcome};
use crate::verilator::{BuildProfile, HarnessBuild};
use std::path::{Path, PathBuf};
use tofprobe_pixel::{DirectedOptions, Fault, PixelParams};
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;

/// Cycles either side of a mismatch that the VCD covers.
pub const VCD_MARGIN: u64 = 64;

/// What to co-simulate.
#[derive(Debug, Clone)]
pub struct CosimOptions {
    pub frames: u64,
    pub seed: u64,
    /// Co-simulate this RTL directory instead of freshly rendered RTL.
    pub rtl_dir: Option<PathBuf>,
    /// Where the RTL, vectors and VCD are written.
    pub work_dir: PathBuf,
    /// Write a VCD (of the mismatch window, or of the first cycles when all match).
    pub trace: bool,
    /// Write a VCD around a mismatch even without `trace`.
    pub vcd_on_mismatch: bool,
    /// Render deliberately broken RTL (mutation tests).
    pub mutation: Option<Fault>,
    /// Pulses per digest window.
    pub digest_pulses: u64,
    pub profile: BuildProfile,
    /// Also time the bare Verilator model (no checking) for the overhead figure.
    pub measure_bare: bool,
    /// Compare digests only (no full trace) even on a short run: exercises the long-frame
    /// path, whose first digest mismatch is re-run with that window's full trace.
    pub digest_only: bool,
    /// Per-pulse detections to replay (e.g. from the scene); `None` = random from `seed`.
    pub stimulus: Option<Vec<Option<u32>>>,
    /// Probe ROM image to render (L × ceil(R/64) words, e.g. the configuration's ΣΔ ROM);
    /// `None` = the sign-of-cosine probe of `stimulus::sign_probe_rom`. With `rtl_dir` it is
    /// the configuration's ROM that the image in the directory must equal (checked before
    /// simulating, `check::compare_rom`).
    pub rom: Option<Vec<u64>>,
    /// Which simulator replays the vectors.
    pub simulator: Simulator,
    /// Seed of Verilator's randomised initial register values (`+verilator+rand+reset+2`,
    /// `+verilator+seed+`): a forgotten reset shows as a mismatch. Must be ≥ 1 (0 would let
    /// Verilator pick a seed, and the run would not be reproducible).
    pub x_seed: u64,
    /// Leading pulses of the first frame forced to misses (directed stimulus: priming).
    pub lead_misses: u64,
    /// Also measure line/toggle coverage of the pixel module (Verilator `--coverage`).
    pub coverage: bool,
    /// Drive the contract's directed sequencer instead of the reference one: `frames`
    /// loops of its program (refusals, the refused counter to saturation, readouts ignored,
    /// a long frame), rendered into the top and walked by the model alike.
    pub directed: Option<DirectedOptions>,
}

/// The simulator of a co-simulation: both replay the same vectors, report the first
/// mismatch in the same form and end with the same completion line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Simulator {
    #[default]
    Verilator,
    Icarus,
}

impl Simulator {
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Verilator => "verilator",
            Simulator::Icarus => "icarus",
        }
    }
}

/// Icarus replays full traces only: runs longer than this many cycles are refused.
pub const ICARUS_MAX_CYCLES: u64 = 2_000_000;

impl CosimOptions {
    /// Defaults for a short co-simulation in `work_dir`.
    pub fn new(work_dir: impl Into<PathBuf>) -> Self {
        CosimOptions {
            frames: 2,
            seed: 1,
            rtl_dir: None,
            work_dir: work_dir.into(),
            trace: false,
            vcd_on_mismatch: true,
            mutation: None,
            digest_pulses: 1,
            profile: BuildProfile::Check,
            measure_bare: false,
            stimulus: None,
            digest_only: false,
            rom: None,
            simulator: Simulator::Verilator,
            x_seed: 1,
            lead_misses: 0,
            coverage: false,
            directed: None,
        }
    }
}

/// The result of a co-simulation.
#[derive(Debug, Clone)]
pub struct CosimReport {
    pub pass: bool,
    pub outcome: RunOutcome,
    /// The first mismatch, refined to a cycle when only a digest differed.
    pub first: Option<Mismatch>,
    pub build: HarnessBuild,
    pub pulses: u64,
    pub cycles: u64,
    /// Frames read out (status words): `frames` of the reference sequencer, three per loop
    /// of the directed one.
    pub frames: u64,
    /// Seconds of the reference cycle model (golden run, digests included).
    pub model_seconds: f64,
    /// Seconds of the Verilator harness run.
    pub verilator_seconds: f64,
    pub bare_seconds: Option<f64>,
    /// CPU seconds of the same three (Linux; the harness's own report): the figures a
    /// shared machine does not inflate by waiting for a core.
    pub model_cpu_seconds: Option<f64>,
    pub verilator_cpu_seconds: Option<f64>,
    pub bare_cpu_seconds: Option<f64>,
    /// With `measure_bare`: the cycle model stepped through the same sequence with nothing
    /// recorded (the counterpart of the bare Verilator model), wall and CPU seconds.
    pub bare_model_seconds: Option<f64>,
    pub bare_model_cpu_seconds: Option<f64>,
    pub vcd: Option<PathBuf>,
    pub rtl_dir: PathBuf,
    pub vectors_dir: PathBuf,
    /// The stimulus replayed and the ROM image used.
    pub stimulus: Vec<Option<u32>>,
    pub rom: Vec<u64>,
    /// The golden readouts, per frame (R words then the status word, raw W bits).
    pub readouts: Vec<Vec<u64>>,
    /// Per frame: the cycle its readout ends (the golden run's status word), which closes
    /// the frame when a mismatch is attributed to one ([`crate::junit`]).
    pub readout_end_cycles: Vec<u64>,
    pub simulator: Simulator,
    /// The Verilator random-reset seed used (recorded so a failure can be re-run).
    pub x_seed: u64,
    /// Coverage of the pixel module, when asked for.
    pub coverage: Option<crate::coverage::Coverage>,
}

/// Reads the probe ROM image back from an RTL directory, strictly (`check::read_rom`).
pub fn rom_from_rtl(p: &PixelParams, dir: &Path) -> Result<Vec<u64>, CosimError> {
    check::read_rom(p, dir)
}

/// Renders the configuration's RTL (optionally with a fault) into `dir`, with the
/// sign-of-cosine probe ROM.
pub fn render_into(p: &PixelParams, dir: &Path, mutation: Option<Fault>) -> Result<(), CosimError> {
    render_with_rom(p, &sign_probe_rom(p), dir, mutation)
}

/// Renders like [`render_with_rom`], the top driven by the directed sequencer when
/// `directed` is given.
pub fn render_driven(
    p: &PixelParams,
    rom: &[u64],
    dir: &Path,
    mutation: Option<Fault>,
    directed: Option<DirectedOptions>,
) -> Result<(), CosimError> {
    let files = tofprobe_rtlgen::render(
        p,
        rom,
        &RenderOptions {
            mutation,
            directed,
            ..RenderOptions::default()
        },
    )?;
    let pairs: Vec<(String, String)> = files.into_iter().map(|f| (f.name, f.contents)).collect();
    write_generated(dir, &pairs)?;
    Ok(())
}

/// Renders the configuration's RTL with the given probe ROM image (L × ceil(R/64) words).
pub fn render_with_rom(
    p: &PixelParams,
    rom: &[u64],
    dir: &Path,
    mutation: Option<Fault>,
) -> Result<(), CosimError> {
    render_driven(p, rom, dir, mutation, None)
}

impl CosimReport {
    /// How many times faster the cycle model (the golden run: model, digests and the
    /// recording) ran than the checking Verilator harness on the same sequence: the ratio
    /// of CPU times where both were measured, else of wall times.
    pub fn model_speedup(&self) -> f64 {
        speedup(
            (self.verilator_seconds, self.verilator_cpu_seconds),
            (self.model_seconds, self.model_cpu_seconds),
        )
    }

    /// The same for the bare pair (`measure_bare`): the Verilator model and the cycle model
    /// stepped through the sequence with nothing observed.
    pub fn bare_model_speedup(&self) -> Option<f64> {
        Some(speedup(
            (self.bare_seconds?, self.bare_cpu_seconds),
            (self.bare_model_seconds?, self.bare_model_cpu_seconds),
        ))
    }
}

/// `reference` time over `fast` time, on CPU times when both are known.
fn speedup(reference: (f64, Option<f64>), fast: (f64, Option<f64>)) -> f64 {
    match (reference.1, fast.1) {
        (Some(r), Some(f)) => r / f.max(1e-9),
        _ => reference.0 / fast.0.max(1e-9),
    }
}

/// Runs one co-simulation.
pub fn cosim(p: &PixelParams, o: &CosimOptions) -> Result<CosimReport, CosimError> {
    let rtl = steps::checked_rtl(p, o)?;
    let stimulus = steps::stimulus(p, o)?;
    let run = steps::Run::golden(p, o, rtl, stimulus)?;
    match o.simulator {
        Simulator::Icarus => run.icarus(),
        Simulator::Verilator => run.verilator(),
    }
}
