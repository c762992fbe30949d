//! The subcommands: one file each. To add one, add a variant to [`Command`] and a line to
//! [`run`].

pub mod bench;
pub mod check_set;
pub mod config;
pub mod cosim;
pub mod flow;
pub mod layout;
pub mod merge;
pub mod replay;
pub mod reproduce;
pub mod rtl;
pub mod simulate;
pub mod size;
pub mod tile_arg;
pub mod tradeoff;
pub mod vectors;

use clap::Subcommand;

use crate::error::CliError;

/// Every `tofprobe` subcommand.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the photon/TDC Monte Carlo on a configuration and print a summary.
    Simulate(simulate::SimulateArgs),
    /// Join the tile sets of `simulate --shard i/n` into the array's output set.
    Merge(merge::MergeArgs),
    /// Print or check a configuration.
    Config(config::ConfigArgs),
    /// Measure the speed of one part of tofprobe.
    Bench(bench::BenchArgs),
    /// Re-measure the paper's numbers (Table 2, Fig. 4, eq. 12, 1NN bandwidths) against
    /// the paper and the closed forms; exits 1 if a row misses.
    Reproduce(reproduce::ReproduceArgs),
    /// Replay a real time-tagged record (PicoQuant PTU, B&H SPC) through the pixel.
    Replay(replay::ReplayArgs),
    /// Sizing report: widths, readout, area (yosys), timing (OpenSTA), sky130, sweeps.
    Size(size::SizeArgs),
    /// Render the pixel, probe ROM and top into Verilog-2005 (atomic; never overwrites
    /// files it did not generate).
    Rtl(rtl::RtlArgs),
    /// Write golden vectors (stimulus, ROM, readouts, write trace or digests, manifest).
    Vectors(vectors::VectorsArgs),
    /// Co-simulate the RTL against the model in Verilator: verdict and throughputs.
    Cosim(cosim::CosimArgs),
    /// The main flow: scene -> model -> RTL -> vectors -> co-simulation -> report.
    Flow(flow::FlowArgs),
    /// Place and route the pixel (qflow, magic, netgen, OpenSTA, klayout): DRC, LVS,
    /// post-route timing, a picture and bins per pitch from layout; exits 1 unless clean.
    Layout(layout::LayoutArgs),
    /// The speed/accuracy trade: every fidelity level timed and scored per scene.
    Tradeoff(tradeoff::TradeoffArgs),
    /// Check that a directory holds a whole output set (rtl, vectors, reproduce, flow,
    /// layout, an array's set, a tile set).
    CheckSet(check_set::CheckSetArgs),
}

/// Shows what a design ignores (`ResolvedDesign::ignored_warning`) on stderr: the CLI's
/// one place for it, so every command that loads a file warns alike.
fn warn_ignored(design: &tofprobe_design::ResolvedDesign) {
    if let Some(w) = design.ignored_warning() {
        eprintln!("warning: {w}");
    }
}

/// `tofprobe_design::load` (the pure resolution) with its warning shown.
pub fn load_design(
    path: Option<&std::path::Path>,
) -> Result<tofprobe_design::ResolvedDesign, tofprobe_design::DesignError> {
    let design = tofprobe_design::load(path)?;
    warn_ignored(&design);
    Ok(design)
}

/// `tofprobe_flow::adders::load` (the resolution with `adders = "auto"` decided) with its
/// warning shown.
pub fn load_for_hardware(
    path: Option<&std::path::Path>,
) -> Result<tofprobe_design::ResolvedDesign, tofprobe_flow::FlowError> {
    let design = tofprobe_flow::adders::load(path)?;
    warn_ignored(&design);
    Ok(design)
}

/// The simulating RTL commands' start (`vectors`, `cosim`): `frames` checked (1..=1000),
/// the configuration resolved, the generator's parameters for the overrides.
pub fn simulated_design(
    frames: u64,
    config: Option<&std::path::Path>,
    overrides: &tofprobe_design::RtlOverrides,
) -> Result<(tofprobe_design::ResolvedDesign, tofprobe_pixel::PixelParams), CliError> {
    if frames == 0 || frames > 1000 {
        return Err(CliError::option("frames", frames, "1..=1000"));
    }
    let design = crate::commands::load_for_hardware(config)?;
    simulated_design_of(design, overrides)
}

/// [`simulated_design`] of a design already loaded (refused for an `[array]`).
pub fn simulated_design_of(
    design: tofprobe_design::ResolvedDesign,
    overrides: &tofprobe_design::RtlOverrides,
) -> Result<(tofprobe_design::ResolvedDesign, tofprobe_pixel::PixelParams), CliError> {
    design.single_pixel("vectors and cosim")?;
    let p = tofprobe_design::rtl_params(&design, overrides)?;
    Ok((design, p))
}

/// Most pulses a single pixel's golden stimulus may hold (`vectors`, `cosim`: frames × N),
/// each kept in memory (8 to 16 bytes a pulse): 2^26 pulses stay within 1 GiB. `--frame-pulses 2^32` once
/// asked for 64 GiB and aborted; 2^63 overflowed the capacity and panicked.
pub const MAX_STIMULUS_PULSES: u64 = 1 << 26;

/// Refuses a stimulus of `frames` frames of `frame_pulses` pulses beyond
/// [`MAX_STIMULUS_PULSES`], naming `--frame-pulses` (or the frame N of the configuration)
/// and the largest N that fits.
pub fn check_stimulus(frames: u64, frame_pulses: u64, overridden: bool) -> Result<(), CliError> {
    let total = frames.checked_mul(frame_pulses);
    if total.is_some_and(|t| t <= MAX_STIMULUS_PULSES) {
        return Ok(());
    }
    let fits = MAX_STIMULUS_PULSES / frames.max(1);
    let allowed = format!(
        "--frames × N ≤ 2^26 = {MAX_STIMULUS_PULSES} pulses (the golden stimulus is held in \
         memory, 8 to 16 bytes a pulse): N ≤ {fits} with --frames {frames}"
    );
    Err(if overridden {
        CliError::option("frame-pulses", frame_pulses, allowed)
    } else {
        CliError::option(
            "frames",
            frames,
            format!(
                "{allowed} (N = {frame_pulses}, the configuration's frame; --frame-pulses sets a shorter one)"
            ),
        )
    })
}

/// What a command that ran to its end concludes (README "Exit codes"): `Fail` is a
/// verdict command's FAIL (a co-simulation mismatch, a paper row missed, a failing flow),
/// exit status 1 after its output; errors are `CliError`s (status 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Done; for a verdict command, PASS (exit status 0).
    Done,
    /// The verdict is FAIL (exit status 1).
    Fail,
}

impl Verdict {
    /// PASS when `pass`, else FAIL.
    pub fn of(pass: bool) -> Verdict {
        if pass { Verdict::Done } else { Verdict::Fail }
    }
}

/// Runs one subcommand.
pub fn run(command: Command) -> Result<Verdict, CliError> {
    let done = |r: Result<(), CliError>| r.map(|()| Verdict::Done);
    match command {
        Command::Simulate(a) => done(simulate::run(&a)),
        Command::Merge(a) => done(merge::run(&a)),
        Command::Config(a) => done(config::run(&a)),
        Command::Bench(a) => done(bench::run(a)),
        Command::Reproduce(a) => reproduce::run(&a),
        Command::Replay(a) => done(replay::run(&a)),
        Command::Size(a) => done(size::run(&a)),
        Command::Rtl(a) => done(rtl::run(&a)),
        Command::Vectors(a) => done(vectors::run(&a)),
        Command::Cosim(a) => cosim::run(&a),
        Command::Flow(a) => flow::run(&a),
        Command::Layout(a) => layout::run(&a),
        Command::Tradeoff(a) => done(tradeoff::run(&a)),
        Command::CheckSet(a) => done(check_set::run(&a)),
    }
}
