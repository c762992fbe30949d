//! The steps of [`super::cosim`], one function each: the RTL taken or rendered and
//! checked, the stimulus, the golden run and its vectors, then the replay on Icarus or on
//! Verilator (with the refinement of a differing digest window, the VCD, the coverage and
//! the bare timing). What every replay needs is one [`Run`].

use std::path::PathBuf;
use std::time::Instant;

use tofprobe_io::cpu::thread_cpu_seconds;
use tofprobe_pixel::{Mode, PixelParams, directed_program};
use tofprobe_rtlgen::golden::Golden;
use tofprobe_rtlgen::stimulus::{random_stimulus, sign_probe_rom};
use tofprobe_rtlgen::vectors::{VectorOptions, golden_run, write_vectors};
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, module_names};

use super::{CosimOptions, CosimReport, ICARUS_MAX_CYCLES, Simulator, VCD_MARGIN, render_driven};
use crate::check;
use crate::error::CosimError;
use crate::harness::{self, BareRun, Mismatch, RunOutcome};
use crate::icarus;
use crate::verilator::{self, HarnessBuild};

/// The checked RTL of a run: absolute work and RTL directories, and the ROM read back.
pub(super) struct Rtl {
    work_dir: PathBuf,
    rtl_dir: PathBuf,
    rom: Vec<u64>,
}

/// A run's stimulus: the pulses' detections and their count.
pub(super) struct Stimulus {
    stim: Vec<Option<u32>>,
    pulses: u64,
}

/// Everything a replay needs: the RTL, the stimulus, the golden run and its vectors.
pub(super) struct Run<'a> {
    p: &'a PixelParams,
    o: &'a CosimOptions,
    rtl: Rtl,
    stim: Vec<Option<u32>>,
    pulses: u64,
    vopts: VectorOptions,
    golden: Golden,
    model_seconds: f64,
    model_cpu_seconds: Option<f64>,
    vec_dir: PathBuf,
    top: String,
}

/// What a replay adds to the report beyond its outcome.
#[derive(Default)]
struct Extras {
    vcd: Option<PathBuf>,
    coverage: Option<crate::coverage::Coverage>,
    bare: Option<BareRun>,
    bare_model: Option<(f64, Option<f64>)>,
}

/// The parameters, the work directory, the RTL (rendered unless given) and its checks:
/// exact and before any simulation — the header's parameters and hash, then the ROM image
/// against its manifest and the configuration's ROM, the X seed, the sequencer.
pub(super) fn checked_rtl(p: &PixelParams, o: &CosimOptions) -> Result<Rtl, CosimError> {
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
    Ok(Rtl {
        work_dir,
        rtl_dir,
        rom,
    })
}

/// The pulses of `o.frames` frames (of the directed program's loop when directed), their
/// detections (given or drawn, the leading misses and the program's frame leads missed),
/// and the Icarus length limit.
pub(super) fn stimulus(p: &PixelParams, o: &CosimOptions) -> Result<Stimulus, CosimError> {
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
    Ok(Stimulus { stim, pulses })
}

impl<'a> Run<'a> {
    /// The golden run of the cycle model (timed: the model's side of the speed-up) and
    /// its vector files in `vectors/`.
    pub(super) fn golden(
        p: &'a PixelParams,
        o: &'a CosimOptions,
        rtl: Rtl,
        s: Stimulus,
    ) -> Result<Self, CosimError> {
        let vopts = VectorOptions {
            frames: o.frames,
            seed: o.seed,
            digest_pulses: o.digest_pulses,
            trace_window: o.digest_only.then_some((0, 0)),
            directed: o.directed,
        };
        let c0 = thread_cpu_seconds();
        let t0 = Instant::now();
        let (golden, window) = golden_run(p, &s.stim, &rtl.rom, &vopts)?;
        let model_seconds = t0.elapsed().as_secs_f64();
        let model_cpu_seconds = c0.zip(thread_cpu_seconds()).map(|(a, b)| b - a);
        let vec_dir = rtl.work_dir.join("vectors");
        write_vectors(&vec_dir, p, &s.stim, &rtl.rom, &golden, window, &vopts)?;
        let vec_dir = std::fs::canonicalize(&vec_dir).map_err(|e| CosimError::io(&vec_dir, e))?;
        let (_, _, top) = module_names(DEFAULT_MODULE_PREFIX);
        Ok(Run {
            p,
            o,
            rtl,
            stim: s.stim,
            pulses: s.pulses,
            vopts,
            golden,
            model_seconds,
            model_cpu_seconds,
            vec_dir,
            top,
        })
    }

    fn passes(&self, outcome: &RunOutcome, first: &Option<Mismatch>) -> bool {
        let frames = self.golden.readouts.len() as u64;
        outcome.mismatches == 0 && outcome.frames == frames && first.is_none()
    }

    /// The replay on Icarus (full traces only): its wall time stands in the Verilator
    /// fields of the report.
    pub(super) fn icarus(self) -> Result<CosimReport, CosimError> {
        let work_dir = &self.rtl.work_dir;
        let t1 = Instant::now();
        let outcome = icarus::run(
            &self.rtl.rtl_dir,
            &self.vec_dir,
            &self.top,
            &work_dir.join("icarus"),
        )?;
        let seconds = t1.elapsed().as_secs_f64();
        let first = outcome.first.clone();
        let build = HarnessBuild {
            exe: work_dir.join("icarus").join("tb.vvp"),
            reused: false,
            seconds: 0.0,
        };
        Ok(self.report(outcome, first, build, seconds, Extras::default()))
    }

    /// The replay on the (cached) Verilator harness, a differing digest window pinned down,
    /// then the VCD, the coverage and the bare timing when asked.
    pub(super) fn verilator(self) -> Result<CosimReport, CosimError> {
        let (o, rtl_dir) = (self.o, &self.rtl.rtl_dir);
        let build = verilator::build(rtl_dir, &self.top, false, o.profile)?;
        let outcome = harness::run(&build.exe, rtl_dir, &self.vec_dir, None, None, o.x_seed)?;
        let first = self.refine(&build, &outcome)?;
        let pass = self.passes(&outcome, &first);
        let vcd = if o.trace || (o.vcd_on_mismatch && !pass) {
            Some(self.vcd(first.as_ref())?)
        } else {
            None
        };
        let coverage = if o.coverage {
            Some(self.coverage()?)
        } else {
            None
        };
        let (bare, bare_model) = if o.measure_bare {
            (
                Some(harness::run_bare(&build.exe, rtl_dir, &self.vec_dir)?),
                Some(time_bare_model(
                    self.p,
                    &self.stim,
                    &self.rtl.rom,
                    &self.vopts,
                )?),
            )
        } else {
            (None, None)
        };
        let seconds = outcome.seconds;
        let extras = Extras {
            vcd,
            coverage,
            bare,
            bare_model,
        };
        Ok(self.report(outcome, first, build, seconds, extras))
    }

    /// The first mismatch: when a digest differed, that window's full trace is regenerated
    /// and replayed, and the earlier of its first mismatch and any other reported one (e.g.
    /// a readout word) wins.
    fn refine(
        &self,
        build: &HarnessBuild,
        outcome: &RunOutcome,
    ) -> Result<Option<Mismatch>, CosimError> {
        let first = outcome.first.clone();
        let Some(d) = &outcome.digest else {
            return Ok(first);
        };
        let (p, rom) = (self.p, &self.rtl.rom);
        let wopts = VectorOptions {
            trace_window: Some((d.cycle_from, d.cycle_to)),
            ..self.vopts.clone()
        };
        let (gw, ww) = golden_run(p, &self.stim, rom, &wopts)?;
        let wdir = self.rtl.work_dir.join("vectors-window");
        write_vectors(&wdir, p, &self.stim, rom, &gw, ww, &wopts)?;
        let wdir = std::fs::canonicalize(&wdir).map_err(|e| CosimError::io(&wdir, e))?;
        let refined = harness::run(
            &build.exe,
            &self.rtl.rtl_dir,
            &wdir,
            Some(ww),
            None,
            self.o.x_seed,
        )?
        .first;
        Ok(match (first, refined) {
            (Some(a), Some(b)) => Some(if b.cycle <= a.cycle { b } else { a }),
            (a, b) => b.or(a),
        })
    }

    /// `cosim.vcd`: the cycles around the first mismatch, or the first cycles when all
    /// match, from a tracing build of the harness.
    fn vcd(&self, first: Option<&Mismatch>) -> Result<PathBuf, CosimError> {
        let (lo, hi) = match first {
            Some(m) => (m.cycle.saturating_sub(VCD_MARGIN), m.cycle + VCD_MARGIN),
            None => (0, self.golden.cycles.min(100_000)),
        };
        let rtl_dir = &self.rtl.rtl_dir;
        let tb = verilator::build(rtl_dir, &self.top, true, self.o.profile)?;
        let f = self.rtl.work_dir.join("cosim.vcd");
        harness::run(
            &tb.exe,
            rtl_dir,
            &self.vec_dir,
            None,
            Some((&f, lo, hi)),
            self.o.x_seed,
        )?;
        Ok(f)
    }

    /// The pixel module's line and toggle coverage over the run's vectors.
    fn coverage(&self) -> Result<crate::coverage::Coverage, CosimError> {
        let (pixel, _, _) = module_names(DEFAULT_MODULE_PREFIX);
        crate::coverage::measure(
            &self.rtl.rtl_dir,
            &self.vec_dir,
            &self.top,
            &self.rtl.work_dir.join("coverage"),
            self.o.x_seed,
            &format!("{pixel}.v"),
        )
    }

    /// The report of a replay whose simulator took `sim_seconds` (wall).
    fn report(
        self,
        outcome: RunOutcome,
        first: Option<Mismatch>,
        build: HarnessBuild,
        sim_seconds: f64,
        x: Extras,
    ) -> CosimReport {
        let pass = self.passes(&outcome, &first);
        CosimReport {
            pass,
            verilator_seconds: sim_seconds,
            verilator_cpu_seconds: outcome.cpu_seconds,
            outcome,
            first,
            build,
            pulses: self.pulses,
            cycles: self.golden.cycles,
            frames: self.golden.readouts.len() as u64,
            model_seconds: self.model_seconds,
            bare_seconds: x.bare.map(|b| b.seconds),
            model_cpu_seconds: self.model_cpu_seconds,
            bare_cpu_seconds: x.bare.and_then(|b| b.cpu_seconds),
            bare_model_seconds: x.bare_model.map(|b| b.0),
            bare_model_cpu_seconds: x.bare_model.and_then(|b| b.1),
            vcd: x.vcd,
            rtl_dir: self.rtl.rtl_dir,
            vectors_dir: self.vec_dir,
            readout_end_cycles: self.golden.readout_end_cycles,
            readouts: self.golden.readouts,
            stimulus: self.stim,
            rom: self.rtl.rom,
            simulator: self.o.simulator,
            x_seed: self.o.x_seed,
            coverage: x.coverage,
        }
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
