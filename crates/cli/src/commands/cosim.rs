//! `tofprobe cosim [CONFIG]`: co-simulates the generated RTL (or `--rtl DIR`) against the
//! reference model in Verilator and prints a one-line verdict with the throughput of
//! Verilator, the cycle model and the transaction model side by side.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;
use tofprobe_cosim::{BuildProfile, CosimOptions, CosimReport, Simulator, cosim};
use tofprobe_design::RtlOverrides;
use tofprobe_design::{Chip, RomPurpose};
use tofprobe_pixel::{DirectedOptions, PixelParams};

use crate::error::CliError;

mod array;

/// Runs longer than this many cycles compare digests of this many pulses instead of every
/// pulse's (a 10^7-pulse frame then has ~10^4 digest lines).
pub(crate) const LONG_RUN_CYCLES: u64 = 2_000_000;
pub(crate) const LONG_RUN_DIGEST_PULSES: u64 = 1024;

/// Arguments of `tofprobe cosim`.
#[derive(Debug, Args)]
pub struct CosimArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Co-simulate this RTL directory (e.g. a hand-edited ECO) instead of fresh RTL.
    #[arg(long)]
    pub rtl: Option<PathBuf>,
    /// Frames to run.
    #[arg(long, default_value_t = 1)]
    pub frames: u64,
    /// Stimulus seed (default 1). An array's detections come from its scene's own seed
    /// (`[acquisition] seed`): refused there.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write a VCD (around the first mismatch, else of the first 10^5 cycles).
    #[arg(long)]
    pub trace: bool,
    /// No VCD on a mismatch (by default one is written around the first, which costs a
    /// second, traced Verilator build): the verdict and the first mismatch only, as a
    /// mutation campaign or a CI gate wants them.
    #[arg(long, conflicts_with = "trace")]
    pub no_vcd: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Override N (pulses per frame).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
    /// Override L (ROM depth; forces the sign-of-cosine probe ROM).
    #[arg(long)]
    pub rom_depth: Option<usize>,
    /// Work directory for RTL, vectors and VCD.
    #[arg(long, default_value = "cosim-out")]
    pub out: PathBuf,
    /// Also time the bare Verilator model (no checking) to measure the harness overhead.
    #[arg(long)]
    pub bare: bool,
    /// Simulator replaying the vectors (same stimuli, same report, same JSON).
    #[arg(long, value_enum, default_value_t = SimulatorArg::Verilator)]
    pub simulator: SimulatorArg,
    /// Seed of Verilator's randomised initial register values (≥ 1; recorded in the
    /// report). Default: 1 for the pixel; an array runs seeds 1, 2 and 3 unless one is given.
    #[arg(long)]
    pub x_seed: Option<u64>,
    /// Directed stimulus: the first K pulses are misses (the priming rule).
    #[arg(long, default_value_t = 0)]
    pub lead_misses: u64,
    /// Also measure line coverage of the pixel module (Verilator `--coverage-line`) and
    /// list the lines never hit.
    #[arg(long)]
    pub coverage: bool,
    /// Drive the contract's directed sequencer instead of the reference one (refused
    /// pulses, the refused counter to saturation, ignored readouts, a long frame:
    /// docs/pixel-contract.md "The directed sequencer"); --frames counts its loops, three
    /// frames each.
    #[arg(long)]
    pub directed: bool,
    /// With --directed: the long frame presents M·N pulses (registers sized for N wrap).
    #[arg(long, default_value_t = 1, requires = "directed")]
    pub long_frame: u64,
    /// Soak: co-simulate N random valid configurations (both modes, every knob, width drawn
    /// or "auto"), drawn from --seed, instead of CONFIG.
    #[arg(long)]
    pub random: Option<u64>,
    /// With --random N: run only share i of n (0-based) of the N configurations, so the n
    /// tasks of a job array cover exactly the configurations of one run.
    #[arg(long, value_name = "I/N", requires = "random")]
    pub shard: Option<String>,
    /// An `[array]` configuration too large to build whole: co-simulate the tile of ROWS ×
    /// COLS pixels from (ROW, COL), with the whole array's sequencer, broadcast and readout.
    #[arg(long, value_name = "ROW,COL,ROWS,COLS", conflicts_with = "random")]
    pub tile: Option<String>,
    /// Also write a JUnit XML report: one test case per frame and configuration, the first
    /// mismatch as the failure message (written whole; an existing file is replaced only if
    /// tofprobe wrote it).
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
}

/// The configuration's name in the JUnit report: the configuration file's stem, `default`
/// for the embedded default.
pub(crate) fn junit_name(a: &CosimArgs) -> String {
    a.config
        .as_deref()
        .and_then(|c| c.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "default".to_string())
}

/// Writes `--junit FILE` if asked (the command line, sanitised, goes into its header).
pub(crate) fn write_junit(
    a: &CosimArgs,
    suites: &[tofprobe_cosim::junit::Suite],
) -> Result<(), CliError> {
    if let Some(path) = &a.junit {
        let command: Vec<String> = std::iter::once("tofprobe".to_string())
            .chain(std::env::args().skip(1))
            .collect();
        tofprobe_cosim::junit::write(path, suites, &command.join(" "))?;
    }
    Ok(())
}

/// `--simulator`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SimulatorArg {
    Verilator,
    Icarus,
}

impl From<SimulatorArg> for Simulator {
    fn from(s: SimulatorArg) -> Self {
        match s {
            SimulatorArg::Verilator => Simulator::Verilator,
            SimulatorArg::Icarus => Simulator::Icarus,
        }
    }
}

#[derive(Debug, Serialize)]
struct Json {
    pass: bool,
    frames: u64,
    pulses: u64,
    cycles: u64,
    mismatches: u64,
    first_mismatch_cycle: Option<u64>,
    first_mismatch_pulse: Option<u64>,
    first_mismatch_signal: Option<String>,
    first_mismatch_expected: Option<String>,
    first_mismatch_actual: Option<String>,
    simulator: &'static str,
    x_seed: u64,
    coverage_percent: Option<f64>,
    uncovered_lines: Option<Vec<String>>,
    verilator_seconds: f64,
    verilator_cycles_per_s: f64,
    bare_verilator_seconds: Option<f64>,
    harness_overhead_ratio: Option<f64>,
    cycle_model_seconds: f64,
    cycle_model_cycles_per_s: f64,
    /// CPU times (Linux) and the rates on them: the cycle model's golden run on its thread,
    /// the harness's replay in its process.
    cycle_model_cpu_seconds: Option<f64>,
    verilator_cpu_seconds: Option<f64>,
    cycle_model_cycles_per_cpu_s: Option<f64>,
    verilator_cycles_per_cpu_s: Option<f64>,
    /// Cycle model ÷ Verilator on the same sequence in this run (CPU times where both are
    /// measured, else wall), both checking: the golden run against the checking harness.
    cycle_model_vs_verilator: f64,
    /// With `--bare`: the cycle model stepped with nothing recorded, and its ratio to the
    /// bare Verilator model.
    bare_cycle_model_seconds: Option<f64>,
    bare_cycle_model_vs_verilator: Option<f64>,
    transaction_model_seconds: f64,
    transaction_model_pulses_per_s: f64,
    build_seconds: f64,
    build_reused: bool,
    vcd: Option<String>,
    rom: String,
}

/// Times the pixel crate's transaction model (`pp`: the pixel of `p`) on the same stimulus
/// (seconds).
pub fn time_transaction(pp: &tofprobe_pixel::PixelParams, p: &PixelParams, r: &CosimReport) -> f64 {
    let Ok(mut m) = tofprobe_pixel::TransactionModel::new(pp) else {
        return f64::NAN;
    };
    let words = p.registers().div_ceil(64);
    let l = p.rom_depth.max(1);
    let t0 = Instant::now();
    for (i, d) in r.stimulus.iter().enumerate() {
        let n = i as u64 % p.frame_pulses;
        let a = (n as usize % l) * words;
        let entry = r.rom.get(a..a + words).unwrap_or(&[]);
        m.pulse(*d, entry);
        if n + 1 == p.frame_pulses {
            std::hint::black_box(m.readout());
        }
    }
    t0.elapsed().as_secs_f64()
}

/// Co-simulation options for a configuration: digests for long runs, speed build for them.
pub fn options(p: &PixelParams, a: &CosimArgs) -> CosimOptions {
    let mut o = CosimOptions::new(&a.out);
    o.frames = a.frames;
    o.seed = a.seed.unwrap_or(1);
    o.rtl_dir = a.rtl.clone();
    o.trace = a.trace;
    o.vcd_on_mismatch = !a.no_vcd;
    o.measure_bare = a.bare;
    o.simulator = a.simulator.into();
    o.x_seed = a.x_seed.unwrap_or(1);
    o.lead_misses = a.lead_misses;
    o.coverage = a.coverage;
    o.directed = a.directed.then(|| DirectedOptions {
        long_frame: a.long_frame,
        ..DirectedOptions::default()
    });
    let cycles = a.frames * p.frame_pulses * p.cycles_per_pulse as u64;
    if cycles > LONG_RUN_CYCLES {
        o.digest_pulses = LONG_RUN_DIGEST_PULSES;
        o.profile = BuildProfile::Speed;
    }
    o
}

/// Runs `tofprobe cosim`.
pub fn run(a: &CosimArgs) -> Result<super::Verdict, CliError> {
    let overrides = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    if let Some(path) = &a.junit {
        // A foreign file there is refused now, not after the simulation.
        tofprobe_cosim::junit::check_target(path)?;
    }
    if let Some(n) = a.random {
        return run_random(a, n);
    }
    if let Some(dir) = &a.rtl {
        // A set killed mid-commit is refused; edited files are named (and co-simulated).
        super::check_set::check_reader(dir)?;
    }
    if a.frames == 0 || a.frames > 1000 {
        return Err(CliError::option("frames", a.frames, "1..=1000"));
    }
    let design = super::load_for_hardware(a.config.as_deref())?;
    if design.array.is_some() {
        return array::cosim(a, &design);
    }
    // A --tile on a single pixel is refused, not ignored.
    super::tile_arg::tile_for(&design, a.tile.as_deref())?;
    let (design, _) = super::simulated_design_of(design, &overrides)?;
    // With --rtl, the chip `tofprobe rtl` renders for this configuration (the image in DIR
    // must be its ROM); else the chip the simulating commands replay.
    let purpose = if a.rtl.is_some() {
        RomPurpose::Rendered
    } else {
        RomPurpose::Replayed
    };
    let chip = Chip::of(&design, &overrides, purpose)?;
    let p = chip.pixel;
    super::check_stimulus(a.frames, p.frame_pulses, a.frame_pulses.is_some())?;
    let rom_note = if a.rtl.is_some() {
        format!(
            "ROM of --rtl checked against the configuration's: {}",
            chip.rom.note
        )
    } else {
        chip.rom.note
    };
    let sd_rom = Some(chip.rom.words);
    let mut o = options(&p, a);
    o.rom = sd_rom;
    let r = cosim(&p, &o)?;
    // The pixel crate's parameters of the simulated frame (N and L as simulated).
    let mut pp = design.pixel.clone();
    pp.frame_pulses = p.frame_pulses;
    pp.rom_depth = p.rom_depth;
    let tx = time_transaction(&pp, &p, &r);
    let rate = |n: u64, s: f64| if s > 0.0 { n as f64 / s } else { 0.0 };
    let j = Json {
        pass: r.pass,
        frames: r.frames,
        pulses: r.pulses,
        cycles: r.cycles,
        mismatches: r.outcome.mismatches,
        first_mismatch_cycle: r.first.as_ref().map(|m| m.cycle),
        first_mismatch_pulse: r.first.as_ref().map(|m| m.pulse),
        first_mismatch_signal: r.first.as_ref().map(|m| m.signal.clone()),
        first_mismatch_expected: r.first.as_ref().map(|m| m.expected.clone()),
        first_mismatch_actual: r.first.as_ref().map(|m| m.actual.clone()),
        simulator: r.simulator.name(),
        x_seed: r.x_seed,
        coverage_percent: r.coverage.as_ref().map(|c| c.percent()),
        uncovered_lines: r.coverage.as_ref().map(|c| {
            c.uncovered
                .iter()
                .map(|(n, t)| format!("{}:{n}: {t}", c.file))
                .collect()
        }),
        verilator_seconds: r.verilator_seconds,
        verilator_cycles_per_s: rate(r.cycles, r.verilator_seconds),
        bare_verilator_seconds: r.bare_seconds,
        harness_overhead_ratio: r
            .bare_seconds
            .filter(|b| *b > 0.0)
            .map(|b| r.verilator_seconds / b),
        cycle_model_seconds: r.model_seconds,
        cycle_model_cycles_per_s: rate(r.cycles, r.model_seconds),
        cycle_model_cpu_seconds: r.model_cpu_seconds,
        verilator_cpu_seconds: r.verilator_cpu_seconds,
        cycle_model_cycles_per_cpu_s: r.model_cpu_seconds.map(|s| rate(r.cycles, s)),
        verilator_cycles_per_cpu_s: r.verilator_cpu_seconds.map(|s| rate(r.cycles, s)),
        cycle_model_vs_verilator: r.model_speedup(),
        bare_cycle_model_seconds: r.bare_model_seconds,
        bare_cycle_model_vs_verilator: r.bare_model_speedup(),
        transaction_model_seconds: if tx.is_finite() { tx } else { 0.0 },
        transaction_model_pulses_per_s: if tx.is_finite() {
            rate(r.pulses, tx)
        } else {
            0.0
        },
        build_seconds: r.build.seconds,
        build_reused: r.build.reused,
        vcd: r.vcd.as_ref().map(|v| v.display().to_string()),
        rom: rom_note,
    };
    if a.json {
        println!("{}", serde_json::to_string(&j)?);
    } else {
        let verdict = match &r.first {
            None if r.pass => "PASS".to_string(),
            None => format!("FAIL ({} mismatches)", r.outcome.mismatches),
            Some(m) => format!(
                "FAIL at cycle {} (pulse {}): {} expected {} actual {}",
                m.cycle, m.pulse, m.signal, m.expected, m.actual
            ),
        };
        println!(
            "cosim {verdict}: {} frame(s), {} pulses, {} cycles, {} mismatches | {} {:.2} Mcycles/s ({:.2} s{}, x-seed {}), cycle model {:.2} Mcycles/s ({:.2} s), cycle model / {} {:.1}x{}{}, transaction model {:.2} Mpulses/s ({:.3} s){}{}; {}",
            j.frames,
            j.pulses,
            j.cycles,
            j.mismatches,
            j.simulator,
            j.verilator_cycles_per_s / 1e6,
            j.verilator_seconds,
            j.bare_verilator_seconds
                .map(|b| format!(", bare model {b:.2} s"))
                .unwrap_or_default(),
            j.x_seed,
            j.cycle_model_cycles_per_s / 1e6,
            j.cycle_model_seconds,
            j.simulator,
            j.cycle_model_vs_verilator,
            if j.verilator_cpu_seconds.is_some() && j.cycle_model_cpu_seconds.is_some() {
                " on CPU time"
            } else {
                " on wall time"
            },
            j.bare_cycle_model_vs_verilator
                .map(|b| format!(" (bare models {b:.1}x)"))
                .unwrap_or_default(),
            j.transaction_model_pulses_per_s / 1e6,
            j.transaction_model_seconds,
            if j.build_reused {
                ", build reused"
            } else {
                ", built"
            },
            j.vcd
                .as_ref()
                .map(|v| format!(", VCD {v}"))
                .unwrap_or_default(),
            j.rom,
        );
    }
    if let (false, Some(c)) = (a.json, &r.coverage) {
        println!(
            "coverage of {}: {} of {} lines with coverage points hit ({:.1}%)",
            c.file,
            c.covered,
            c.lines,
            c.percent()
        );
        for (n, t) in &c.uncovered {
            println!("  not hit: {}:{n}: {t}", c.file);
        }
    }
    let suite = tofprobe_cosim::junit::suite(&junit_name(a), &tofprobe_rtlgen::config_hash(&p), &r);
    write_junit(a, &[suite])?;
    Ok(super::Verdict::of(r.pass))
}

/// One line (or JSON object) of a soak.
#[derive(Debug, Serialize)]
struct SoakCase {
    case: u64,
    pass: bool,
    mode: String,
    registers: usize,
    width: u32,
    width_choice: String,
    frame_pulses: u64,
    seed: u64,
    first_mismatch: Option<String>,
}

/// `tofprobe cosim --random N --seed S`: N random valid configurations, each co-simulated
/// over --frames frames (`tofprobe_cosim::soak`); FAIL if any fails.
fn run_random(a: &CosimArgs, n: u64) -> Result<super::Verdict, CliError> {
    if n == 0 || n > 100_000 {
        return Err(CliError::option("random", n, "1..=100000"));
    }
    let t0 = Instant::now();
    let o = tofprobe_cosim::soak::SoakOptions {
        seed: a.seed.unwrap_or(1),
        frames: a.frames,
        simulator: a.simulator.into(),
        x_seed: a.x_seed.unwrap_or(1),
        out: &a.out,
    };
    let mut printed: Result<(), CliError> = Ok(());
    let cases = match &a.shard {
        Some(s) => tofprobe_array::shard::share(
            n,
            tofprobe_array::shard::Shard::parse(s).map_err(|e| CliError::option("shard", s, e))?,
        ),
        None => 0..n,
    };
    let ran = cases.end - cases.start;
    let report = tofprobe_cosim::soak::run(cases, &o, |c| {
        let p = &c.case.params;
        let line = SoakCase {
            case: c.index,
            pass: c.report.pass,
            mode: format!("{:?}", p.mode),
            registers: p.registers(),
            width: p.width,
            width_choice: format!("{:?}", c.case.width),
            frame_pulses: p.frame_pulses,
            seed: c.case.seed,
            first_mismatch: c.first_mismatch(),
        };
        if a.json {
            match serde_json::to_string(&line) {
                Ok(j) => println!("{j}"),
                Err(e) => printed = Err(e.into()),
            }
        } else {
            println!(
                "case {}: {} {:?} ({:?}, width {:?}) seed {}{}",
                c.index,
                if c.report.pass { "PASS" } else { "FAIL" },
                p,
                p.mode,
                c.case.width,
                c.case.seed,
                line.first_mismatch
                    .as_ref()
                    .map(|m| format!(": {m}"))
                    .unwrap_or_default()
            );
        }
        Ok(())
    })?;
    printed?;
    let (failed, suites) = (report.failed, report.suites);
    println!(
        "cosim soak: {} of {ran} configuration(s) passed ({}, --seed {}, {} frame(s) each) in {:.1} s",
        ran - failed,
        a.simulator
            .to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default(),
        a.seed.unwrap_or(1),
        a.frames,
        t0.elapsed().as_secs_f64()
    );
    write_junit(a, &suites)?;
    Ok(super::Verdict::of(failed == 0))
}
