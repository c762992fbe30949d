//! The hardware flow of an `[array]` design: its RTL (`tofprobe_rtlgen::render_array`: R × C
//! of the one pixel, the broadcast ROM and sequencer, the readout of
//! `tofprobe_design::readout`) with its FuseSoC core; its co-simulation at the array's
//! ports (the array model `tofprobe_array::rtl` against Verilator or Icarus, the first
//! mismatch named by pixel (r, c), register, cycle and pulse); and the flow's report (the
//! verdict, the per-pixel digests' count, the readout's figures at the configured frame and
//! the comparison with reading every timestamp out).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use tofprobe_array::rtl::{ArrayModel, ArrayRun, mid_frame_reset, run_with_reset};
use tofprobe_array::rtl_vectors::{exercise, scene_detections, vector_files};
use tofprobe_cosim::RunOutcome;
use tofprobe_design::readout::{ArrayTile, Readout};
use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::render::{HEADER_MARK, RenderOptions};
use tofprobe_rtlgen::write::write_generated;

use crate::error::FlowError;

/// Which simulator replays the array's vectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArraySimulator {
    Verilator,
    Icarus,
}

/// How to co-simulate an array.
#[derive(Debug, Clone)]
pub struct ArrayCosimOptions {
    /// Output directory: `rtl/` and `vectors/` are written under it.
    pub out: PathBuf,
    /// Pulses per frame N (`None`: the design's).
    pub frame_pulses: Option<u64>,
    /// ROM depth override (the sign probe, as `tofprobe rtl --rom-depth`).
    pub rom_depth: Option<usize>,
    /// Frames.
    pub frames: u64,
    pub simulator: ArraySimulator,
    /// Verilator's build profile.
    pub profile: tofprobe_cosim::BuildProfile,
    /// A deliberate fault of the array RTL (mutation tests); the model runs without it.
    pub fault: Option<ArrayFault>,
    /// Per-pixel detections (row-major over the pixels present; `None`: the array
    /// scene's).
    pub detections: Option<Vec<Vec<Option<u32>>>>,
    /// Co-simulate only this tile of the array, with the whole array's sequencer, broadcast
    /// and readout (an array too large to build whole under Verilator).
    pub tile: Option<ArrayTile>,
    /// The regeneration command recorded in the headers.
    pub command: String,
    /// Co-simulate this array set (written by `tofprobe rtl`, perhaps edited since)
    /// instead of rendering one: its header must name this configuration's pixel, its
    /// array module the ports the testbenches drive.
    pub rtl: Option<PathBuf>,
    /// Seeds of Verilator's randomised power-up state, one run each (every one ≥ 1; three
    /// by default, so a register the reset forgets shows under some seed);
    /// Icarus starts from X instead.
    pub x_seeds: Vec<u64>,
    /// The first K pulses of every pixel (or SPAD) present no detection (the priming
    /// rule, array-wide).
    pub lead_misses: u64,
    /// Thin the scene's detections (`tofprobe_array::rtl_vectors::exercise`) so every
    /// count of valid SPADs, the hold and the priming are reached (default on; given
    /// `detections` are replayed as they are).
    pub exercise: bool,
    /// How Verilator builds the pixel (`None`: by the pixel count,
    /// `tofprobe_cosim::array::Layout::for_pixels`).
    pub layout: Option<tofprobe_cosim::array::Layout>,
    /// Another build cache root (`None`: the user's; an empty directory: a cold build).
    pub cache: Option<PathBuf>,
    /// A test option: one cycle of `rst` in the middle of the first frame, while the
    /// pixels accumulate a pulse (`tofprobe_array::rtl::mid_frame_reset`); model and RTL
    /// restart and the frames follow it (default off).
    pub mid_frame_reset: bool,
    /// A test option: registers W bits wide, narrower than the configuration's sizing
    /// (which `[pixel] width` refuses), so the words reach their sign bit and the top
    /// bit of W and a frame overflows and wraps (`None`: the design's W).
    pub width: Option<u32>,
}

impl ArrayCosimOptions {
    /// Verilator, one frame of the design's N, the scene's detections, no fault.
    pub fn new(out: &Path) -> Self {
        ArrayCosimOptions {
            out: out.to_path_buf(),
            frame_pulses: None,
            rom_depth: None,
            frames: 1,
            simulator: ArraySimulator::Verilator,
            profile: tofprobe_cosim::BuildProfile::Check,
            fault: None,
            detections: None,
            tile: None,
            command: "tofprobe cosim".into(),
            rtl: None,
            x_seeds: vec![1, 2, 3],
            lead_misses: 0,
            exercise: true,
            layout: None,
            cache: None,
            mid_frame_reset: false,
            width: None,
        }
    }
}

/// The ports `testbench/array_harness.cpp` and `array_tb.v` drive and read, in order.
pub const ARRAY_PORTS: [&str; 8] = [
    "clk", "rst", "valid", "tdc", "pulse_o", "ready", "ro_valid", "ro_data",
];

/// Checks that the array module in `dir` still has the ports the testbenches connect (an
/// edited set may rename or drop one): the first missing or foreign port is named.
fn check_array_ports(dir: &Path, top: &str) -> Result<(), FlowError> {
    let path = dir.join(format!("{top}.v"));
    let text = tofprobe_io::read_bounded_text(&path, 64 << 20)
        .map_err(|e| FlowError::output(path.clone(), e.to_string()))?;
    let bad = |what: String| {
        FlowError::option(
            "rtl",
            path.display(),
            &format!(
                "{what}: the array module `{top}` must keep the ports {ARRAY_PORTS:?} that the testbenches drive"
            ),
        )
    };
    let start = text
        .find(&format!("module {top}"))
        .ok_or_else(|| bad(format!("no `module {top}`")))?;
    // The port list: after the parameter list's `) (`, or the module name's `(`.
    let rest = &text[start..];
    let end = rest
        .find(");")
        .ok_or_else(|| bad("no end of the port list".into()))?;
    let header = &rest[..end];
    let list = match header.find(") (") {
        Some(i) => &header[i + 3..],
        None => header.split_once('(').map_or("", |(_, l)| l),
    };
    let ports: Vec<&str> = list
        .split(',')
        .filter_map(|d| d.split_whitespace().last())
        .collect();
    if let Some(p) = ARRAY_PORTS.iter().find(|p| !ports.contains(p)) {
        return Err(bad(format!("port `{p}` is missing")));
    }
    if let Some(p) = ports.iter().find(|p| !ARRAY_PORTS.contains(p)) {
        return Err(bad(format!("port `{p}` is not one of them")));
    }
    Ok(())
}

/// What an array co-simulation found.
#[derive(Debug, Clone)]
pub struct ArrayCosimReport {
    pub pass: bool,
    /// The readout the RTL and the model follow (N as simulated).
    pub readout: Readout,
    /// The pixel's parameters as simulated (N, L overridden).
    pub pixel: tofprobe_pixel::PixelParams,
    pub cycles: u64,
    pub mismatches: u64,
    /// The first mismatch: signal, expected, actual and what the array was doing then
    /// (pixel (r, c), register, cycle, pulse), from the model.
    pub first: Option<String>,
    /// The first mismatch's cycle.
    pub first_cycle: Option<u64>,
    /// The frame whose readout holds the first mismatch (the first frame whose last beat
    /// is at or after it; the last frame past every readout).
    pub first_frame: Option<u64>,
    /// The Verilator power-up seed of the reported run (the first that failed, else the
    /// last), `None` under Icarus (X).
    pub x_seed: Option<u64>,
    /// The model's run (its stream and per-pixel words).
    pub run: ArrayRun,
    /// Harness build seconds (0 for Icarus) and whether the cached build was reused.
    pub build_seconds: f64,
    pub reused: bool,
    /// How Verilator built the pixel (`None`: Icarus).
    pub layout: Option<tofprobe_cosim::array::Layout>,
    /// Simulation and model seconds.
    pub sim_seconds: f64,
    pub model_seconds: f64,
    /// Detections over all pixels and frames.
    pub detections: u64,
}

/// The array chip of `design` for the overrides `o` (refused for a design without
/// `[array]`); a superpixel array (G > 1) renders and co-simulates its SPAD inputs, each
/// pixel behind one averaging front end.
fn chip(design: &ResolvedDesign, o: &RtlOverrides, purpose: RomPurpose) -> Result<Chip, FlowError> {
    Ok(Chip::array_of(design, o, purpose)?)
}

/// Renders the array chip into `out` (the RTL and its FuseSoC core, one set; with `kit`,
/// the set's verification kit too: the vector files of [`array_vector_files`] for this chip
/// beside the RTL, the testbench `tofprobe_rtlgen::kit` copies, and the core's simulation
/// targets); returns the file names.
pub fn render_array_to(
    chip: &Chip,
    out: &Path,
    command: String,
    fault: Option<ArrayFault>,
    tile: Option<ArrayTile>,
    kit: Option<Vec<(String, String)>>,
) -> Result<Vec<String>, FlowError> {
    let spec = chip
        .array_spec(fault, tile)
        .ok_or_else(|| FlowError::option("array", "none", "a chip with an [array] readout"))?;
    let options = RenderOptions {
        command,
        rom_note: chip.rom.note.clone(),
        ..RenderOptions::default()
    };
    let mut files = tofprobe_rtlgen::render_array(&chip.pixel, &chip.rom.words, &options, &spec)?;
    let core = tofprobe_rtlgen::core::render_array_core(
        &chip.pixel,
        &files,
        &options,
        chip.rows,
        chip.cols,
        kit.is_some(),
    )?;
    files.extend(core);
    if kit.is_some() {
        files.push(tofprobe_rtlgen::kit::render_kit_testbench(
            &chip.pixel,
            &options,
        ));
    }
    let mut pairs: Vec<(String, String)> =
        files.into_iter().map(|f| (f.name, f.contents)).collect();
    pairs.extend(kit.into_iter().flatten());
    write_generated(out, &pairs)?;
    Ok(pairs.into_iter().map(|(n, _)| n).collect())
}

/// What `tofprobe rtl` put in an array set besides the RTL: its verification kit's frames
/// and cycles, or why it has none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ArrayKit {
    /// The testbench and `frames` frames of golden vectors, `cycles` cycles.
    Written { frames: u64, cycles: u64 },
    /// No kit (`--kit-frames 0`, or more cycles than [`tofprobe_rtlgen::kit::KIT_MAX_CYCLES`]):
    /// the reason, naming the option that gives one.
    Omitted(String),
}

/// `tofprobe rtl` on an array design: the chip ROM policy's ROM, N and L as overridden; with
/// `kit_frames` > 0 the set carries its verification kit ([`render_array_to`]): the golden
/// vectors of `tofprobe vectors` for `kit_frames` frames (the same code path,
/// [`array_vector_files`], on the ROM rendered into the set, as `tofprobe cosim --rtl`
/// replays), unless they would exceed `KIT_MAX_CYCLES` cycles.
pub fn render_array_design(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    out: &Path,
    command: String,
    kit_frames: u64,
) -> Result<(Chip, Vec<String>, ArrayKit), FlowError> {
    let max = tofprobe_rtlgen::kit::KIT_MAX_CYCLES;
    if kit_frames > 100 {
        return Err(FlowError::option(
            "kit-frames",
            kit_frames,
            "0..=100 (0: no verification kit)",
        ));
    }
    let chip = chip(design, o, RomPurpose::Rendered)?;
    let ro = chip
        .readout
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    // The run's length, bounded before the model runs: every frame and one readout more.
    let estimate = ro
        .frame_cycles()
        .saturating_mul(kit_frames)
        .saturating_add(ro.readout_cycles());
    let (kit, status) = if kit_frames == 0 {
        (
            None,
            ArrayKit::Omitted("--kit-frames 0: no verification kit".into()),
        )
    } else if estimate > max {
        (
            None,
            ArrayKit::Omitted(format!(
                "no verification kit: {kit_frames} frame(s) of N = {} replay about {estimate} cycles,                  over the kit's {max} (render with a shorter --frame-pulses or fewer --kit-frames,                  or re-verify with `tofprobe cosim --rtl`)",
                chip.pixel.frame_pulses
            )),
        )
    } else {
        let stimulus = ArrayStimulus {
            frames: kit_frames,
            detections: None,
            tile: None,
            lead_misses: 0,
            exercise: false,
            mid_frame_reset: false,
            purpose: RomPurpose::Rendered,
        };
        let (v, files) = array_vector_files(design, chip.clone(), stimulus, &command)?;
        let cycles = v.run.cycles();
        (
            Some(files),
            ArrayKit::Written {
                frames: kit_frames,
                cycles,
            },
        )
    };
    let files = render_array_to(&chip, out, command, None, None, kit)?;
    Ok((chip, files, status))
}

/// The array's golden vectors written (`tofprobe vectors` on an array design): the chip
/// for the overrides (the simulating commands' ROM), the array model run on `detections`
/// (`None`: the array scene's), the files of `tofprobe_array::rtl_vectors` in `vec_dir`.
#[derive(Debug)]
pub struct ArrayVectors {
    pub chip: Chip,
    pub readout: Readout,
    pub run: ArrayRun,
    pub detections: Vec<Vec<Option<u32>>>,
    pub model_seconds: f64,
}

/// Runs the array model of `design` and writes its vectors into `vec_dir`.
pub fn write_array_vectors(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    frames: u64,
    detections: Option<Vec<Vec<Option<u32>>>>,
    tile: Option<ArrayTile>,
    vec_dir: &Path,
    command: &str,
) -> Result<ArrayVectors, FlowError> {
    let stimulus = ArrayStimulus {
        frames,
        detections,
        tile,
        lead_misses: 0,
        exercise: false,
        mid_frame_reset: false,
        purpose: RomPurpose::Replayed,
    };
    write_vectors(design, o, stimulus, vec_dir, command)
}

/// What the array's golden vectors replay: frames, detections (`None`: the scene's), the
/// tile present, the lead misses and the ROM the chip carries.
struct ArrayStimulus {
    frames: u64,
    detections: Option<Vec<Vec<Option<u32>>>>,
    tile: Option<ArrayTile>,
    lead_misses: u64,
    /// Thin the scene's detections (`rtl_vectors::exercise`).
    exercise: bool,
    /// One cycle of `rst` in the middle of the first frame (`rtl::mid_frame_reset`).
    mid_frame_reset: bool,
    purpose: RomPurpose,
}

fn write_vectors(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    stimulus: ArrayStimulus,
    vec_dir: &Path,
    command: &str,
) -> Result<ArrayVectors, FlowError> {
    if stimulus.frames == 0 || stimulus.frames > 100 {
        return Err(FlowError::option("frames", stimulus.frames, "1..=100"));
    }
    let chip = chip(design, o, stimulus.purpose)?;
    let (v, files) = array_vector_files(design, chip, stimulus, command)?;
    write_generated(vec_dir, &files)?;
    Ok(v)
}

/// The array model of `chip` run on the stimulus, and the vector files
/// (`tofprobe_array::rtl_vectors::vector_files`, headers naming `command`): what `tofprobe
/// vectors` writes into its directory and `tofprobe rtl` into an array set's verification
/// kit.
fn array_vector_files(
    design: &ResolvedDesign,
    chip: Chip,
    stimulus: ArrayStimulus,
    command: &str,
) -> Result<(ArrayVectors, Vec<(String, String)>), FlowError> {
    let ArrayStimulus {
        frames,
        detections,
        tile,
        lead_misses: v_lead,
        exercise: thin,
        mid_frame_reset: reset,
        purpose: _,
    } = stimulus;
    let ro = chip
        .readout
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    let p = &chip.pixel;
    let mut detections = match detections {
        Some(d) => d,
        None => {
            // The pulses before a mid-frame reset take the first detections: one frame more.
            let drawn = frames + u64::from(reset);
            let mut d = scene_detections(design, p.frame_pulses, drawn, tile)?;
            if thin {
                let cols = tile.map_or(ro.cols, |t| t.cols);
                exercise(&mut d, cols, chip.superpixel);
            }
            d
        }
    };
    for d in &mut detections {
        d.iter_mut()
            .take(usize::try_from(v_lead).unwrap_or(usize::MAX))
            .for_each(|x| *x = None);
    }
    let t0 = std::time::Instant::now();
    let mut model = ArrayModel::tile(&ro, p, &chip.rom.words, None, tile)?
        .with_superpixel(chip.superpixel, p)?;
    let reset_at = reset.then(|| mid_frame_reset(&ro));
    let r = run_with_reset(&mut model, &detections, frames, reset_at)?;
    let model_seconds = t0.elapsed().as_secs_f64();
    let top = tofprobe_rtlgen::array::array_module_name(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX);
    let header = format!(
        "{HEADER_MARK} {} (array vectors): {} x {} {:?} pixels, N = {}, {} frame(s); `{}`. DO NOT EDIT.",
        env!("CARGO_PKG_VERSION"),
        ro.rows,
        ro.cols,
        p.mode,
        p.frame_pulses,
        frames,
        tofprobe_io::text::sanitize(command)
    );
    let files = vector_files(&r, &detections, p, &top, &header);
    Ok((
        ArrayVectors {
            chip,
            readout: ro,
            run: r,
            detections,
            model_seconds,
        },
        files,
    ))
}

/// Renders the array of `design`, runs the array model on its scene (or the given
/// detections), writes the golden vectors and replays them under the simulator.
pub fn cosim_array(
    design: &ResolvedDesign,
    a: &ArrayCosimOptions,
) -> Result<ArrayCosimReport, FlowError> {
    let narrowed = narrow_width(design, a)?;
    let design = narrowed.as_ref().unwrap_or(design);
    let o = RtlOverrides {
        frame_pulses: a.frame_pulses,
        rom_depth: a.rom_depth,
    };
    let vec_dir = a.out.join("vectors");
    // An existing set carries the ROM `tofprobe rtl` renders; fresh RTL the replayed one.
    let purpose = if a.rtl.is_some() {
        RomPurpose::Rendered
    } else {
        RomPurpose::Replayed
    };
    if a.x_seeds.is_empty() || a.x_seeds.contains(&0) {
        return Err(FlowError::option(
            "x-seed",
            format!("{:?}", a.x_seeds),
            "one or more seeds, each ≥ 1",
        ));
    }
    let stimulus = ArrayStimulus {
        frames: a.frames,
        detections: a.detections.clone(),
        tile: a.tile,
        lead_misses: a.lead_misses,
        exercise: a.exercise,
        mid_frame_reset: a.mid_frame_reset,
        purpose,
    };
    let v = write_vectors(design, &o, stimulus, &vec_dir, &a.command)?;
    let top = tofprobe_rtlgen::array::array_module_name(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX);
    let rtl_dir = match &a.rtl {
        Some(dir) => {
            tofprobe_cosim::check::check_header(&v.chip.pixel, dir)?;
            check_array_ports(dir, &top)?;
            dir.clone()
        }
        None => {
            let dir = a.out.join("rtl");
            render_array_to(&v.chip, &dir, a.command.clone(), a.fault, a.tile, None)?;
            dir
        }
    };
    let (ro, r, detections, model_seconds) = (v.readout, v.run, v.detections, v.model_seconds);
    let p = &v.chip.pixel;
    let rtl_abs = std::fs::canonicalize(&rtl_dir)
        .map_err(|e| FlowError::output(rtl_dir.clone(), e.to_string()))?;
    // The pixels the RTL holds: the tile's, or the whole array's.
    let pixels = a.tile.map_or(ro.pixels(), |t| t.rows * t.cols);
    let layout = a
        .layout
        .unwrap_or_else(|| tofprobe_cosim::array::Layout::for_pixels(pixels));
    let (outcome, build_seconds, reused, x_seed) = simulate(a, &rtl_abs, &vec_dir, &top, layout)?;
    let first = outcome.first.as_ref().map(|m| {
        format!(
            "{} expected {} actual {} at {}",
            m.signal,
            m.expected,
            m.actual,
            r.explain(m.cycle)
        )
    });
    let count: u64 = detections
        .iter()
        .map(|d| {
            d.iter()
                .take((a.frames * p.frame_pulses) as usize)
                .filter(|x| x.is_some())
                .count() as u64
        })
        .sum();
    Ok(ArrayCosimReport {
        pass: outcome.mismatches == 0 && outcome.cycles == r.cycles(),
        readout: ro,
        pixel: p.clone(),
        cycles: outcome.cycles,
        mismatches: outcome.mismatches,
        first,
        first_cycle: outcome.first.as_ref().map(|m| m.cycle),
        first_frame: outcome.first.as_ref().map(|m| {
            let last =
                |k: u64| r.beat_cycle(k, ro.pixels() - 1, ro.registers, ro.beats_per_word - 1);
            (0..a.frames)
                .find(|&k| m.cycle <= last(k))
                .unwrap_or(a.frames - 1)
        }),
        x_seed,
        run: r,
        build_seconds,
        reused,
        layout: (a.simulator == ArraySimulator::Verilator).then_some(layout),
        sim_seconds: outcome.seconds,
        model_seconds,
        detections: count,
    })
}

/// The design with the test option [`ArrayCosimOptions::width`] applied: W narrower than
/// its sizing, at least the operand's bits and at most the design's W; refused with an
/// existing set (`--rtl`: its width is the set's).
fn narrow_width(
    design: &ResolvedDesign,
    a: &ArrayCosimOptions,
) -> Result<Option<ResolvedDesign>, FlowError> {
    let Some(w) = a.width else {
        return Ok(None);
    };
    let p = &design.pixel;
    let lo = p.operand_bits().max(2);
    if a.rtl.is_some() || !(lo..=p.width).contains(&w) {
        let allowed = match a.rtl {
            Some(_) => "none with an existing set (--rtl: the set's width)".to_string(),
            None => format!("{lo}..={} (the operand's bits to the design's W)", p.width),
        };
        return Err(FlowError::option("width", w, &allowed));
    }
    let mut d = design.clone();
    d.pixel.width = w;
    Ok(Some(d))
}

/// Replays the vectors under the simulator: Verilator once per power-up seed (the first
/// run that fails is the one reported), Icarus once (from X). Returns the outcome, the build
/// seconds and whether the build was reused.
fn simulate(
    a: &ArrayCosimOptions,
    rtl: &Path,
    vec_dir: &Path,
    top: &str,
    layout: tofprobe_cosim::array::Layout,
) -> Result<(RunOutcome, f64, bool, Option<u64>), FlowError> {
    match a.simulator {
        ArraySimulator::Verilator => {
            let b = tofprobe_cosim::array::build(rtl, top, a.profile, layout, a.cache.as_deref())?;
            let mut last = None;
            for &seed in &a.x_seeds {
                let o = tofprobe_cosim::array::run_verilator(&b.exe, rtl, vec_dir, seed)?;
                let failed = o.mismatches > 0;
                last = Some((o, seed));
                if failed {
                    break;
                }
            }
            let (o, seed) = last.ok_or_else(|| FlowError::option("x-seed", "none", "≥ 1 seed"))?;
            Ok((o, b.seconds, b.reused, Some(seed)))
        }
        ArraySimulator::Icarus => {
            let work = a.out.join("icarus");
            let o = tofprobe_cosim::array::run_icarus(rtl, vec_dir, &work)?;
            let _ = std::fs::remove_dir_all(&work);
            Ok((o, 0.0, false, None))
        }
    }
}

/// The report's readout section: the configured frame's figures and the comparison with
/// reading every timestamp out (T bits per pixel per laser pulse).
pub fn readout_section(design: &ResolvedDesign, md: &mut String) -> Result<(), FlowError> {
    let Some(ro) = design.readout()? else {
        return Ok(());
    };
    let f_laser = design.sensor().laser_rate_hz;
    let stamps = ro.pixels() as f64 * f_laser * f64::from(design.pixel.tdc_bits);
    let regs = ro.payload_bits_per_frame() as f64 * ro.frame_rate_hz();
    let _ = writeln!(md, "## Readout (docs/pixel-contract.md \"Array\")\n");
    let _ = writeln!(
        md,
        "At the configured frame (N = {} pulses): {} × {} pixels × {} words × {} beat(s) of {} bits = {} bits per frame ({} payload), read in {} cycles = {:.3e} s at f_clk = {:.3e} Hz (one beat every {} cycle(s), {:.3e} bit/s while streaming); a frame every {} cycles: {:.6} Hz, the pixels see {:.4} % of the laser's pulses{}.\n",
        ro.frame_pulses,
        ro.rows,
        ro.cols,
        ro.words_per_pixel(),
        ro.beats_per_word,
        ro.bits,
        ro.stream_bits_per_frame(),
        ro.payload_bits_per_frame(),
        ro.readout_cycles(),
        ro.readout_seconds(),
        ro.clock_hz,
        ro.beat_cycles,
        ro.port_bits_per_s(),
        ro.frame_cycles(),
        ro.frame_rate_hz(),
        100.0 * ro.duty(),
        if ro.double_buffer {
            ", double-buffered"
        } else {
            ""
        }
    );
    let _ = writeln!(
        md,
        "Reading every timestamp out instead: {} pixels × {:.3e} pulses/s × T = {} bits = {:.3e} bit/s ({:.3e} B per pixel per second); the registers need {:.3e} bit/s on average, {:.1}x less.\n",
        ro.pixels(),
        f_laser,
        design.pixel.tdc_bits,
        stamps,
        f_laser * f64::from(design.pixel.tdc_bits) / 8.0,
        regs,
        stamps / regs
    );
    Ok(())
}

/// The array flow's default frame: one period of a periodic ΣΔ ROM (the default's 20,000
/// pulses), else 4096 pulses (a power of two for Haar), never beyond the design's N.
pub fn array_short_frame(design: &ResolvedDesign) -> u64 {
    let probe = &design.document.probe;
    let n = if design.pixel.mode == tofprobe_pixel::Mode::Fourier
        && probe.rom_mode == tofprobe_dsp::sd::RomMode::Periodic
    {
        probe.rom_depth as u64
    } else {
        4096
    };
    n.min(design.pixel.frame_pulses)
}

/// `tofprobe flow` on an `[array]` design: renders the array, co-simulates it under
/// Verilator at its ports against the array model, and writes `report.md` (verdict, the
/// first mismatch named by pixel, register, cycle and pulse, per-pixel digests, the
/// readout at the configured frame and its comparison with reading every timestamp out);
/// the directory is one output set, as the pixel's flow.
pub fn run_array_flow(
    design: &ResolvedDesign,
    a: &crate::flow::FlowOptions,
) -> Result<crate::flow::FlowOutcome, FlowError> {
    if a.signoff {
        return Err(FlowError::option(
            "signoff",
            "true",
            "the pixel's flow (an array is co-simulated here; its synthesis and timing are `tofprobe size`)",
        ));
    }
    if a.frames == 0 || a.frames > 100 {
        return Err(FlowError::option("frames", a.frames, "1..=100"));
    }
    crate::flow::refuse_foreign_report(&a.out.join("report.md"))?;
    let created = crate::flowset::open(&a.out)?;
    let r = array_flow_in(design, a);
    if r.is_err() {
        crate::flowset::discard(&a.out, created);
    }
    r
}

fn array_flow_in(
    design: &ResolvedDesign,
    a: &crate::flow::FlowOptions,
) -> Result<crate::flow::FlowOutcome, FlowError> {
    let t0 = std::time::Instant::now();
    let n = match (a.full_frame, a.frame_pulses) {
        (_, Some(n)) => Some(n),
        (true, None) => None,
        (false, None) => Some(array_short_frame(design)),
    };
    let mut o = ArrayCosimOptions::new(&a.out);
    o.frame_pulses = n;
    o.frames = a.frames;
    o.command = format!(
        "tofprobe flow {} --out {}",
        tofprobe_io::text::sanitize(&design.origin),
        tofprobe_io::text::path_as_typed(&a.out)
    );
    let r = cosim_array(design, &o)?;
    let ro = &r.readout;
    let mut md = String::new();
    let _ = writeln!(md, "{}\n", crate::flow::REPORT_TITLE);
    let _ = writeln!(
        md,
        "Configuration: {}, a {} × {} array of {:?} pixels ({} registers × W = {} bits), N = {} pulses/frame (simulated), {} frame(s), probe ROM: {}.\n",
        tofprobe_io::text::sanitize(&design.origin),
        ro.rows,
        ro.cols,
        design.pixel.mode,
        ro.registers,
        ro.width,
        ro.frame_pulses,
        a.frames,
        Chip::array_of(
            design,
            &RtlOverrides {
                frame_pulses: n,
                rom_depth: None
            },
            RomPurpose::Replayed
        )?
        .rom
        .note
    );
    let _ = writeln!(md, "## Verdict\n");
    let _ = writeln!(
        md,
        "Co-simulation at the array's ports (Verilator vs the array model `tofprobe_array::rtl`): **{}**, {} cycles, {} mismatches; build {:.1} s{}, Verilator {:.2} s, model {:.2} s; {} detections over the {}.{}\n",
        if r.pass { "PASS" } else { "FAIL" },
        r.cycles,
        r.mismatches,
        r.build_seconds,
        if r.reused { " (cached)" } else { "" },
        r.sim_seconds,
        r.model_seconds,
        r.detections,
        match design.array.as_ref().map_or(1, |a| a.superpixel) {
            1 => "pixels".to_string(),
            g => format!("SPADs (superpixels of {g} × {g}, each pixel's averaged)"),
        },
        r.first
            .as_ref()
            .map(|f| format!(" First mismatch: {f}."))
            .unwrap_or_default()
    );
    let _ = writeln!(
        md,
        "The simulated readout: {} beats of {} bits per frame, {} cycles per frame ({} accumulating, {} reading); per-pixel digests in `vectors/digests.txt`.\n",
        ro.beats_per_frame(),
        ro.bits,
        ro.frame_cycles(),
        ro.accumulate_cycles(),
        ro.readout_cycles()
    );
    if let Some(words) = r.run.words.first() {
        let _ = writeln!(
            md,
            "| pixel | register 0 | register 1 | status |\n|---|---|---|---|"
        );
        for (q, w) in words.iter().enumerate().take(16) {
            let (row, col) = ro.order(q);
            let signed = |v: u64| tofprobe_pixel::fixed::sign_extend(v, ro.width);
            let _ = writeln!(
                md,
                "| ({row}, {col}) | {} | {} | {} |",
                signed(w[0]),
                w.get(1).map(|&v| signed(v)).unwrap_or(0),
                w[ro.registers]
            );
        }
        let _ = writeln!(md);
    }
    readout_section(design, &mut md)?;
    let size_line =
        "size: the array's area, pitch and timing are `tofprobe size CONFIG`".to_string();
    let seconds = t0.elapsed().as_secs_f64();
    let _ = writeln!(md, "Flow time: {seconds:.1} s.");
    let path = a.out.join("report.md");
    tofprobe_io::write_atomic(&path, md.as_bytes())
        .map_err(|e| FlowError::output(path.clone(), e.to_string()))?;
    crate::flowset::seal(&a.out)?;
    Ok(crate::flow::FlowOutcome {
        pass: r.pass,
        frame_pulses: ro.frame_pulses,
        cycles: r.cycles,
        mismatches: r.mismatches,
        seconds,
        headline: format!(
            "{} × {} array, {} bits per frame read in {} cycles",
            ro.rows,
            ro.cols,
            ro.stream_bits_per_frame(),
            ro.readout_cycles()
        ),
        size_line,
        report: path,
        signoff: Vec::new(),
    })
}
