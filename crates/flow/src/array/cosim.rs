//! The array co-simulated at its ports: the vectors of [`crate::array::vectors`] replayed
//! under Verilator (once per power-up seed) or Icarus against the RTL rendered, or an
//! existing set (its header and ports checked), the first mismatch explained by the model.

use std::path::{Path, PathBuf};

use tofprobe_array::rtl_driver::ArrayRun;
use tofprobe_cosim::RunOutcome;
use tofprobe_design::readout::Readout;
use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{ResolvedDesign, RomPurpose};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::array::ArrayTile;

use crate::array::render::render_array_to;
use crate::array::vectors::{ArrayStimulus, write_vectors};
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
    /// Thin the scene's detections (`tofprobe_rtlgen::array_vectors::exercise`) so every
    /// count of valid SPADs, the hold and the priming are reached (default on; given
    /// `detections` are replayed as they are).
    pub exercise: bool,
    /// How Verilator builds the pixel (`None`: by the pixel count,
    /// `tofprobe_cosim::array::Layout::for_pixels`).
    pub layout: Option<tofprobe_cosim::array::Layout>,
    /// Another build cache root (`None`: the user's; an empty directory: a cold build).
    pub cache: Option<PathBuf>,
    /// A test option: one cycle of `rst` in the middle of the first frame, while the
    /// pixels accumulate a pulse (`tofprobe_array::rtl_driver::mid_frame_reset`); model and RTL
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
