//! `tofprobe bench cosim-array`: the whole array co-simulated under Verilator, its harness
//! built cold once per layout (`tofprobe_cosim::array::Layout`: every pixel inlined, or the
//! pixel one hierarchical block compiled once), side by side in one run — the build's
//! wall and CPU seconds (the tools are child processes: their CPU time is this process's
//! children's), the run's, and the verdict of each against the same golden vectors.

use std::path::PathBuf;

use serde::Serialize;
use tofprobe_cosim::array::Layout;
use tofprobe_design::{ResolvedDesign, resolve};
use tofprobe_io::cpu::children_cpu_seconds;

use crate::array::{ArrayCosimOptions, cosim_array};
use crate::error::FlowError;

/// One layout's figures.
#[derive(Debug, Clone, Serialize)]
pub struct LayoutTiming {
    /// `flat` or `hierarchical`.
    pub layout: &'static str,
    /// Verilate and C++ compile, cold (an empty build cache), wall seconds.
    pub build_seconds: f64,
    /// CPU seconds of the tools, user + system of the waited-for children: Verilator, the
    /// C++ compile and the harness's run (the run is a small part); the model's and the
    /// vectors' time (this process's own) is not in it.
    pub tools_cpu_seconds: Option<f64>,
    /// The harness's run over the whole frame and its readout, wall seconds.
    pub run_seconds: f64,
    pub cycles: u64,
    pub mismatches: u64,
    pub pass: bool,
}

/// The benchmark's report.
#[derive(Debug, Clone, Serialize)]
pub struct CosimBenchReport {
    pub configuration: String,
    pub rows: usize,
    pub cols: usize,
    pub frame_pulses: u64,
    pub layouts: Vec<LayoutTiming>,
    /// Flat over hierarchical tools' CPU seconds (both measured): above 1, the hierarchical
    /// build is the cheaper.
    pub flat_over_hierarchical_build_cpu: Option<f64>,
}

/// `base` (which must have an `[array]` table) at `rows` × `cols` pixels.
fn sized(base: &ResolvedDesign, rows: u32, cols: u32) -> Result<ResolvedDesign, FlowError> {
    let mut doc = base.document.clone();
    let a = doc.array.as_mut().ok_or_else(|| {
        FlowError::option(
            "config",
            &base.origin,
            "a configuration with an [array] table (e.g. scenes/sensor-64x64.toml)",
        )
    })?;
    (a.rows, a.cols) = (rows, cols);
    Ok(resolve(doc, &base.origin)?)
}

/// A work directory under the system's temporary one, removed when dropped and by an
/// interrupt (`tofprobe_io::live`).
struct Work {
    dir: PathBuf,
    _live: tofprobe_io::live::Live,
}

impl Work {
    fn new() -> Result<Work, FlowError> {
        let dir = std::env::temp_dir().join(format!("tofprobe-bench-cosim-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let ((), live) = tofprobe_io::live::create(
            tofprobe_io::live::Kind::Temporary,
            || std::fs::create_dir_all(&dir),
            |_| dir.clone(),
        )
        .map_err(|e| FlowError::output(dir.clone(), e.to_string()))?;
        Ok(Work { dir, _live: live })
    }
}

impl Drop for Work {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// What to co-simulate: the shape, the frame and the ROM (`None`: the design's).
#[derive(Debug, Clone, Copy)]
pub struct CosimBenchSpec {
    pub rows: u32,
    pub cols: u32,
    pub frame_pulses: Option<u64>,
    /// A sign-probe ROM of this depth (as `tofprobe rtl --rom-depth`).
    pub rom_depth: Option<usize>,
}

/// Co-simulates `base`'s array at the spec's shape for one frame and its readout, once per
/// layout, each built cold (an empty build cache) in a temporary directory.
pub fn measure(
    base: &ResolvedDesign,
    spec: CosimBenchSpec,
    layouts: &[Layout],
) -> Result<CosimBenchReport, FlowError> {
    let CosimBenchSpec {
        rows,
        cols,
        frame_pulses,
        rom_depth,
    } = spec;
    let design = sized(base, rows, cols)?;
    let work = Work::new()?;
    let work = work.dir.as_path();
    let mut timings = Vec::new();
    let mut frame = 0;
    for &layout in layouts {
        let dir = work.join(layout.name());
        let _ = std::fs::remove_dir_all(&dir);
        let mut o = ArrayCosimOptions::new(&dir);
        o.frame_pulses = frame_pulses;
        o.rom_depth = rom_depth;
        o.layout = Some(layout);
        o.cache = Some(dir.join("cache"));
        o.x_seeds = vec![1];
        o.command = "tofprobe bench cosim-array".into();
        let cpu0 = children_cpu_seconds();
        let r = cosim_array(&design, &o)?;
        let cpu = children_cpu_seconds().zip(cpu0).map(|(b, a)| b - a);
        frame = r.readout.frame_pulses;
        timings.push(LayoutTiming {
            layout: layout.name(),
            build_seconds: r.build_seconds,
            tools_cpu_seconds: cpu,
            run_seconds: r.sim_seconds,
            cycles: r.cycles,
            mismatches: r.mismatches,
            pass: r.pass,
        });
        let _ = std::fs::remove_dir_all(&dir);
    }
    let cpu_of = |name: &str| {
        timings
            .iter()
            .find(|t| t.layout == name)
            .and_then(|t| t.tools_cpu_seconds)
    };
    let ratio = cpu_of("flat")
        .zip(cpu_of("hierarchical"))
        .filter(|(_, h)| *h > 0.0)
        .map(|(f, h)| f / h);
    Ok(CosimBenchReport {
        configuration: base.origin.clone(),
        rows: rows as usize,
        cols: cols as usize,
        frame_pulses: frame,
        layouts: timings,
        flat_over_hierarchical_build_cpu: ratio,
    })
}
