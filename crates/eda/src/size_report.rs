//! The sizing report: what is asked ([`SizeRequest`]), what comes back ([`SizeReport`],
//! the stable JSON schema documented in docs/size-report-schema.md), and the build that
//! runs synthesis, timing, the sky130 mapping and the sweeps.

pub use crate::analysis::Design;
mod steps;

use crate::analysis::{PointResult, RtlProvider};
use crate::corner_option::CornerOption;
use crate::corners::CornerTiming;
use crate::error::Result;
use crate::memory::{Memory, MemoryInput};
use crate::paper_memory::{PaperFigure, section8};
use crate::scaling::{AreaModel, BinFit};
use crate::sky130::Sky130Source;
use crate::split::AreaSplit;
use crate::sta::Timing;
use crate::throughput::Throughput;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The JSON schema identifier; bumped on any incompatible change.
pub const SCHEMA: &str = "tofprobe-size-report/1";

/// What to build a report from.
pub struct SizeRequest<'a> {
    /// The pixel's RTL for any (B, W).
    pub provider: &'a dyn RtlProvider,
    /// The configured pixel.
    pub design: Design,
    /// Memory-section inputs.
    pub memory: MemoryInput,
    /// Liberty with timing (default: osu018).
    pub liberty: PathBuf,
    /// Area-only sky130 liberty (from scripts/sky130-liberty.sh), or None to skip.
    pub sky130_liberty: Option<PathBuf>,
    /// Bins to sweep (at the configured W).
    pub sweep_bins: Vec<u64>,
    /// Widths to sweep (at the configured B).
    pub sweep_widths: Vec<u32>,
    /// The clock port of the pixel.
    pub clock_port: String,
    /// Cache directory for synthesis results (outside the repository or under target/).
    pub cache: PathBuf,
    /// Node for the "bins per pixel" question (nm).
    pub target_node_nm: f64,
    /// Pixel sides (µm) to answer for, with the paper's estimate where it gave one.
    pub pixel_sides_um: Vec<(f64, Option<u64>)>,
    /// Candidates synthesised at most for each corner the configured pixel misses
    /// (`crate::corner_option`); 0 reports the misses without looking for an option.
    pub corner_trials: usize,
}

impl std::fmt::Debug for SizeRequest<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SizeRequest")
            .field("design", &self.design)
            .field("liberty", &self.liberty)
            .field("sky130_liberty", &self.sky130_liberty)
            .finish_non_exhaustive()
    }
}

/// Area of the configured pixel on one liberty.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct AreaSection {
    /// Liberty file.
    pub liberty: PathBuf,
    /// `library (NAME)`.
    pub library: String,
    /// Liberty carries timing.
    pub has_timing: bool,
    /// Total cell area (µm²), from yosys `stat -liberty`, with `area_from_lef`'s cells at
    /// their LEF outline.
    pub total_area_um2: f64,
    /// Cells the liberty gives no area, counted at their LEF outline (µm² each): osu018's
    /// `LATCH` (a latch register file, or a clock gate's latch). Reported "from LEF".
    #[serde(default)]
    pub area_from_lef: std::collections::BTreeMap<String, f64>,
    /// Cell instances.
    pub cell_count: u64,
    /// Instances per cell type.
    pub cells_by_type: std::collections::BTreeMap<String, u64>,
    /// Register file / adders / hold+prefilter / control.
    pub split: AreaSplit,
    /// total / B.
    pub area_per_bin_um2: f64,
    /// Marginal area of one more bin (slope of the B sweep), when the sweep has ≥ 2 B.
    pub model: Option<AreaModel>,
    /// Smallest flop of the library and its area (µm²).
    pub smallest_flop: Option<(String, f64)>,
    /// Cache key of the synthesis (hash of RTL, parameters, liberty, yosys version).
    pub rtl_hash: String,
}

/// Timing and what it means for the shared adder.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TimingSection {
    /// OpenSTA's critical path.
    pub sta: Timing,
    /// Registers per adder at the laser rate, and the fit verdict.
    pub throughput: Throughput,
}

/// The sky130 mapping (timed tt liberty, or the area-only fallback) and its node scaling.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Sky130Section {
    /// The configured pixel mapped onto sky130 hd.
    pub area: AreaSection,
    /// True when mapped on the timed PDK (tt, delay-driven ABC; corners in
    /// `SizeReport::timing_corners`); false on the area-only liberty (LEF outlines and
    /// functional models).
    pub has_timing: bool,
    /// Target node (nm).
    pub target_node_nm: f64,
    /// (node / 130)².
    pub area_factor: f64,
    /// Configured pixel's area scaled to the node (µm²).
    pub scaled_area_um2: f64,
    /// Bins that fit each pixel size at the node.
    pub fits: Vec<BinFit>,
    /// The sky130 area model the paper's estimates imply (when it gave two), for
    /// comparison with the synthesised one.
    pub paper_implied: Option<AreaModel>,
}

/// One row of the sweep table.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SweepRow {
    /// B.
    pub bins: u64,
    /// W.
    pub width: u32,
    /// Area on the timing liberty (µm²).
    pub area_um2: f64,
    /// Cells on the timing liberty.
    pub cells: u64,
    /// f_max (MHz) on the timing liberty.
    pub f_max_mhz: Option<f64>,
    /// Critical path (ns).
    pub critical_path_ns: Option<f64>,
    /// Area on sky130 (µm²), for rows of the B sweep.
    pub sky130_area_um2: Option<f64>,
    /// Cache key of this row's synthesis.
    pub rtl_hash: String,
}

/// The whole report (JSON schema [`SCHEMA`]).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SizeReport {
    /// Schema identifier.
    pub schema: String,
    /// The configured pixel.
    pub design: Design,
    /// Widths, bytes, compression.
    pub memory: Memory,
    /// The paper's Section 8 memory example computed, its printed figures beside
    /// ([`crate::paper_memory`]); empty in reports written before it existed.
    #[serde(default)]
    pub paper_section8: Vec<PaperFigure>,
    /// Area on the timing liberty.
    pub area: AreaSection,
    /// Timing, when the liberty carries it.
    pub timing: Option<TimingSection>,
    /// sky130 area and node scaling, when asked.
    pub sky130: Option<Sky130Section>,
    /// Sweeps over B (at W) and W (at B).
    pub sweep: Vec<SweepRow>,
    /// f_max, slack at C·f_laser and registers per adder for every liberty and corner
    /// timed: the timing liberty first, then sky130 tt/ss/ff when the PDK is installed.
    #[serde(default)]
    pub timing_corners: Vec<CornerTiming>,
    /// For each corner below the margin, the number of adders that meets it, measured
    /// (`crate::corner_option`); absent in reports written before it existed.
    #[serde(default)]
    pub corner_options: Vec<CornerOption>,
    /// The assumptions behind the figures, in words.
    pub assumptions: Vec<String>,
    /// Wall time of the build (s).
    pub seconds: f64,
}

/// Builds the report. When `req.sky130_liberty` is set, a timed sky130 PDK found by
/// [`crate::pdk::Sky130Pdk::discover`] (`$TOFPROBE_SKY130_PDK`, then the search path)
/// takes its place; the area-only liberty is the fallback. See [`build_with`].
pub fn build(req: &SizeRequest<'_>) -> Result<SizeReport> {
    let sky = match &req.sky130_liberty {
        None => None,
        Some(area_only) => Some(match crate::pdk::Sky130Pdk::discover(None)? {
            Some(pdk) => Sky130Source::Timed(pdk),
            None => Sky130Source::AreaOnly(area_only.clone()),
        }),
    };
    build_with(req, sky.as_ref())
}

/// Builds the report with an explicit sky130 source (`req.sky130_liberty` is ignored);
/// None skips sky130.
pub fn build_with(req: &SizeRequest<'_>, sky_source: Option<&Sky130Source>) -> Result<SizeReport> {
    let start = std::time::Instant::now();
    let d = &req.design;
    let (mem, lib) = steps::check(req)?;
    // Map for the clock the configuration needs, C·f_laser (ABC buffers and sizes for it).
    let target_ps = 1e12 / (d.cycles_per_pulse as f64 * d.laser_rate_hz);
    let results = steps::timing_liberty_points(req, &lib, target_ps)?;
    let main = steps::configured_point(d, &results)?;
    let b_sweep: Vec<&PointResult> = results.iter().filter(|r| r.width == d.width).collect();
    let area = steps::area_section(&lib, main, steps::model_from(&b_sweep));
    let timing = steps::timing_section(d, main)?;
    let clock_mhz = d.cycles_per_pulse as f64 * d.laser_rate_hz / 1e6;
    let mut timing_corners = steps::typical_corner(&lib, main, clock_mhz, d.laser_rate_hz);
    let sky = match sky_source {
        None => None,
        Some(source) => Some(steps::sky130(
            req,
            source,
            &b_sweep,
            target_ps,
            clock_mhz,
            &mut timing_corners,
        )?),
    };
    let corner_options = steps::corner_options(req, &lib, main, &timing_corners, sky.as_ref())?;
    let sweep = steps::sweep_rows(&results, sky.as_ref().map_or(&[][..], |s| &s.rows[..]));
    Ok(SizeReport {
        schema: SCHEMA.to_string(),
        design: d.clone(),
        memory: mem,
        paper_section8: section8()?,
        area,
        timing,
        sky130: sky.map(|s| s.section),
        sweep,
        timing_corners,
        corner_options,
        assumptions: steps::assumptions(req, sky_source),
        seconds: start.elapsed().as_secs_f64(),
    })
}
