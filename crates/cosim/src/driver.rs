//! One co-simulation: render (or take) the RTL, run the pixel crate's cycle model (the
//! judge) through the contract's sequencer for the golden vectors, build the harness (cached), replay, and on
//! a mismatch pin it down to the first cycle (re-running a digest window with its full
//! trace) and write a VCD around it.

use crate::check;
use crate::error::CosimError;
use crate::harness::{self, Mismatch, RunOutcome};
use crate::icarus;
use crate::verilator::{self, BuildProfile, HarnessBuild};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tofprobe_pixel::bench::thread_cpu_seconds;
use tofprobe_pixel::{DirectedOptions, Fault, Mode, PixelParams, directed_program};
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::{random_stimulus, sign_probe_rom};
use tofprobe_rtlgen::vectors::{VectorOptions, golden_run, write_vectors};
use tofprobe_rtlgen::write::write_generated;
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, module_names};

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

/// Steps the cycle model through the run's sequence with nothing recorded: (wall, CPU)
/// seconds.
fn time_bare_model(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    o: &VectorOptions,
) -> Result<(f64, Option<f64>), CosimError> {
    use tofprobe_rtlgen::golden;
    let (stim, program) = golden::stimuli_and_program(p, stim, o.frames, o.directed.as_ref())?;
    let image = golden::rom_image(p, rom);
    let seq = golden::sequence_for(p, &stim, image.as_ref(), o.frames, program)?;
    let mut model = tofprobe_pixel::CycleModel::new(p)?;
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    let mut sink = 0u64;
    for pins in seq {
        let out = model.step(&pins);
        sink = sink.wrapping_add(out.rd_data) ^ model.writes().len() as u64;
    }
    std::hint::black_box(sink);
    let seconds = t0.elapsed().as_secs_f64();
    Ok((seconds, c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a)))
}

/// Runs one co-simulation.
pub fn cosim(p: &PixelParams, o: &CosimOptions) -> Result<CosimReport, CosimError> {
    p.validate()?;
    if p.registers() > 64 {
        return Err(CosimError::TooManyRegisters {
            value: p.registers(),
        });
    }
    std::fs::create_dir_all(&o.work_dir).map_err(|e| CosimError::io(&o.work_dir, e))?;
    // Absolute: the harness runs from the RTL directory (for `$readmemh`).
    let work_dir =
        std::fs::canonicalize(&o.work_dir).map_err(|e| CosimError::io(&o.work_dir, e))?;
    let rtl_dir = match &o.rtl_dir {
        Some(d) => d.clone(),
        None => {
            let d = work_dir.join("rtl");
            match &o.rom {
                Some(rom) => render_driven(p, rom, &d, o.mutation, o.directed)?,
                None => render_driven(p, &sign_probe_rom(p), &d, o.mutation, o.directed)?,
            }
            d
        }
    };
    let rtl_dir = std::fs::canonicalize(&rtl_dir).map_err(|e| CosimError::io(&rtl_dir, e))?;
    // Exact and checked before any simulation: the header's parameters and hash, then the
    // ROM image against its manifest and the configuration's ROM.
    check::check_header(p, &rtl_dir)?;
    let rom = check::read_rom(p, &rtl_dir)?;
    if let (Some(want), Mode::Fourier) = (&o.rom, p.mode) {
        check::compare_rom(p, &rtl_dir, &rom, want)?;
    }
    if o.x_seed == 0 {
        return Err(CosimError::Option {
            option: "x_seed",
            value: "0".into(),
            allowed: "1..=2^64-1 (0 lets Verilator choose, irreproducibly); use 1".into(),
        });
    }
    check::check_sequencer(&rtl_dir, o.directed.as_ref())?;
    let program = o
        .directed
        .as_ref()
        .map(|d| directed_program(p, d))
        .transpose()
        .map_err(tofprobe_rtlgen::RtlError::from)?;
    let (pulses, cycles_needed) = match &program {
        Some(prog) => (
            o.frames * prog.loop_pulses(),
            2 + o.frames * prog.loop_cycles() + 1,
        ),
        None => (
            o.frames * p.frame_pulses,
            2 + o.frames * (p.frame_pulses * p.cycles_per_pulse as u64 + p.registers() as u64 + 2)
                + 1,
        ),
    };
    let mut stim = match &o.stimulus {
        Some(s) if s.len() as u64 >= pulses => s[..pulses as usize].to_vec(),
        _ => random_stimulus(p, pulses, o.seed),
    };
    for d in stim.iter_mut().take(o.lead_misses as usize) {
        *d = None;
    }
    if let Some(prog) = &program {
        prog.miss_frame_leads(&mut stim);
    }
    if o.simulator == Simulator::Icarus && (o.digest_only || cycles_needed > ICARUS_MAX_CYCLES) {
        return Err(CosimError::Option {
            option: "simulator",
            value: format!("icarus for {cycles_needed} cycles"),
            allowed: format!(
                "Icarus replays full traces only, at most {ICARUS_MAX_CYCLES} cycles: use fewer frames, --frame-pulses, or --simulator verilator"
            ),
        });
    }
    let vopts = VectorOptions {
        frames: o.frames,
        seed: o.seed,
        digest_pulses: o.digest_pulses,
        trace_window: o.digest_only.then_some((0, 0)),
        directed: o.directed,
    };
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    let (golden, window) = golden_run(p, &stim, &rom, &vopts)?;
    let model_seconds = t0.elapsed().as_secs_f64();
    let model_cpu_seconds = c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a);
    let vec_dir = work_dir.join("vectors");
    write_vectors(&vec_dir, p, &stim, &rom, &golden, window, &vopts)?;
    let vec_dir = std::fs::canonicalize(&vec_dir).map_err(|e| CosimError::io(&vec_dir, e))?;
    let (_, _, top) = module_names(DEFAULT_MODULE_PREFIX);
    if o.simulator == Simulator::Icarus {
        let t1 = Instant::now();
        let outcome = icarus::run(&rtl_dir, &vec_dir, &top, &work_dir.join("icarus"))?;
        let seconds = t1.elapsed().as_secs_f64();
        let first = outcome.first.clone();
        let frames = golden.readouts.len() as u64;
        let pass = outcome.mismatches == 0 && outcome.frames == frames && first.is_none();
        return Ok(CosimReport {
            pass,
            verilator_seconds: seconds,
            verilator_cpu_seconds: outcome.cpu_seconds,
            outcome,
            first,
            build: HarnessBuild {
                exe: work_dir.join("icarus").join("tb.vvp"),
                reused: false,
                seconds: 0.0,
            },
            pulses,
            cycles: golden.cycles,
            frames,
            model_seconds,
            bare_seconds: None,
            model_cpu_seconds,
            bare_cpu_seconds: None,
            bare_model_seconds: None,
            bare_model_cpu_seconds: None,
            vcd: None,
            rtl_dir,
            vectors_dir: vec_dir,
            readout_end_cycles: golden.readout_end_cycles,
            readouts: golden.readouts,
            stimulus: stim,
            rom,
            simulator: o.simulator,
            x_seed: o.x_seed,
            coverage: None,
        });
    }
    let build = verilator::build(&rtl_dir, &top, false, o.profile)?;
    let outcome = harness::run(&build.exe, &rtl_dir, &vec_dir, None, None, o.x_seed)?;
    let mut first = outcome.first.clone();
    if let Some(d) = outcome.digest {
        // A digest differed: regenerate that window's full trace and replay it; the earlier
        // of its first mismatch and any other reported one (e.g. a readout word) wins.
        let wopts = VectorOptions {
            trace_window: Some((d.cycle_from, d.cycle_to)),
            ..vopts.clone()
        };
        let (gw, ww) = golden_run(p, &stim, &rom, &wopts)?;
        let wdir = work_dir.join("vectors-window");
        write_vectors(&wdir, p, &stim, &rom, &gw, ww, &wopts)?;
        let wdir = std::fs::canonicalize(&wdir).map_err(|e| CosimError::io(&wdir, e))?;
        let refined = harness::run(&build.exe, &rtl_dir, &wdir, Some(ww), None, o.x_seed)?.first;
        first = match (first, refined) {
            (Some(a), Some(b)) => Some(if b.cycle <= a.cycle { b } else { a }),
            (a, b) => b.or(a),
        };
    }
    let frames = golden.readouts.len() as u64;
    let pass = outcome.mismatches == 0 && outcome.frames == frames && first.is_none();
    let mut vcd = None;
    if o.trace || (o.vcd_on_mismatch && !pass) {
        let (lo, hi) = match &first {
            Some(m) => (m.cycle.saturating_sub(VCD_MARGIN), m.cycle + VCD_MARGIN),
            None => (0, golden.cycles.min(100_000)),
        };
        let tb = verilator::build(&rtl_dir, &top, true, o.profile)?;
        let f = work_dir.join("cosim.vcd");
        harness::run(
            &tb.exe,
            &rtl_dir,
            &vec_dir,
            None,
            Some((&f, lo, hi)),
            o.x_seed,
        )?;
        vcd = Some(f);
    }
    let coverage = if o.coverage {
        let (pixel, _, _) = module_names(DEFAULT_MODULE_PREFIX);
        Some(crate::coverage::measure(
            &rtl_dir,
            &vec_dir,
            &top,
            &work_dir.join("coverage"),
            o.x_seed,
            &format!("{pixel}.v"),
        )?)
    } else {
        None
    };
    let (bare, bare_model) = if o.measure_bare {
        (
            Some(harness::run_bare(&build.exe, &rtl_dir, &vec_dir)?),
            Some(time_bare_model(p, &stim, &rom, &vopts)?),
        )
    } else {
        (None, None)
    };
    Ok(CosimReport {
        pass,
        verilator_seconds: outcome.seconds,
        verilator_cpu_seconds: outcome.cpu_seconds,
        outcome,
        first,
        build,
        pulses,
        cycles: golden.cycles,
        frames,
        model_seconds,
        bare_seconds: bare.map(|b| b.seconds),
        model_cpu_seconds,
        bare_cpu_seconds: bare.and_then(|b| b.cpu_seconds),
        bare_model_seconds: bare_model.map(|b| b.0),
        bare_model_cpu_seconds: bare_model.and_then(|b| b.1),
        vcd,
        rtl_dir,
        vectors_dir: vec_dir,
        readout_end_cycles: golden.readout_end_cycles,
        readouts: golden.readouts,
        stimulus: stim,
        rom,
        simulator: o.simulator,
        x_seed: o.x_seed,
        coverage,
    })
}
