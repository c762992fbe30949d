//! Area against accuracy (issue 16): every architecture option of [`catalogue`] applied to
//! the scene, its accuracy measured by the bit-true model against the float DFT over
//! several seeds ([`accuracy`]), its area, timing and bins per pitch synthesised on each
//! library ([`area`]); the Pareto front of area per bin against tone error, and the
//! recommendation: the smallest pixel that meets its clock on every library and the
//! accuracy target ([`front`]). `tofprobe size --options` prints it; `tofprobe flow
//! --recommended` builds the recommended pixel.

pub mod accuracy;
pub mod area;
pub mod catalogue;
pub mod front;
pub mod markdown;
pub mod plot;

use std::path::PathBuf;

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::scaling::RoutedFactor;

pub use catalogue::ArchOption;
pub use front::Recommendation;

use crate::error::ExperimentError;
use accuracy::Spread;
use area::LibraryArea;

/// The seeds the accuracy is averaged over by default.
pub const DEFAULT_SEEDS: [u64; 5] = [1, 2, 3, 4, 5];
/// The default accuracy target: tone error ≤ 1 µm against the float DFT.
pub const DEFAULT_TARGET_ERROR_UM: f64 = 1.0;

/// What to measure.
#[derive(Debug, Clone)]
pub struct OptionsRequest {
    /// Option names to measure (all of the catalogue when empty; the baseline is always kept).
    pub only: Vec<String>,
    /// Photon-source seeds of the accuracy measurement.
    pub seeds: Vec<u64>,
    /// Largest tone error (µm, worst seed) the recommendation accepts.
    pub target_error_um: f64,
    /// The libraries: the timing liberty first (osu018 by default), then sky130 tt when
    /// the timed PDK is found.
    pub liberties: Vec<PathBuf>,
    /// Synthesis cache.
    pub cache: PathBuf,
    /// Node of the bins-per-pitch answer (nm).
    pub node_nm: f64,
    /// The B points of each option's area model, besides the configured B (the size
    /// report's B sweep; ⌈B/4⌉ is added when that leaves one point).
    pub sweep_bins: Vec<u64>,
    /// Pitches (µm) with the paper's estimate.
    pub pixel_sides_um: Vec<(f64, Option<u64>)>,
    /// A routed macro's factor k (`size --options --layout-report`): each option's bins per
    /// pitch from layout, on the liberties of its technology, beside the synthesis answer.
    pub routed: Option<RoutedFactor>,
}

/// One option's row.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct OptionRow {
    /// The option.
    pub option: ArchOption,
    /// Register width W it resolves to (bits).
    pub width_bits: u32,
    /// G, fraction bits into the registers.
    pub register_frac_bits: u32,
    /// `floor` or `nearest`.
    pub prefilter_rounding: String,
    /// `flops`, `clock_gated` or `latch`.
    pub register_file: String,
    /// Tone error against the float DFT over the seeds (µm).
    pub tone_error_um: Spread,
    /// Area and timing per library, in request order.
    pub libraries: Vec<LibraryArea>,
    /// Meets C·f_laser with the margin on every library that carries timing.
    pub meets_clock: bool,
    /// On the Pareto front of (area per bin on the front's library, mean tone error).
    pub on_front: bool,
}

/// The options study (JSON: `options` in `size --json`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct OptionsReport {
    /// Bins B of the configuration.
    pub bins: u64,
    /// The clock every option must meet, C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Pulses of the accuracy measurement (the scene's frame).
    pub pulses: u64,
    /// Seeds of the accuracy measurement.
    pub seeds: Vec<u64>,
    /// The library whose area per bin is the front's axis (sky130 when measured).
    pub front_library: String,
    /// Tone-error target (µm).
    pub target_error_um: f64,
    /// One row per option, catalogue order.
    pub rows: Vec<OptionRow>,
    /// The recommended option (JSON `null` never: a target no option meets is an error).
    pub recommendation: Recommendation,
    /// The routed factor the layout answers use (`--layout-report`), or absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layout: Option<RoutedFactor>,
    /// The assumptions, in words.
    pub assumptions: Vec<String>,
}

/// The options `req` asks for, after checking the request: what `run` measures. Cheap, so
/// a command checks it before anything slow.
pub fn check(
    design: &ResolvedDesign,
    req: &OptionsRequest,
) -> Result<Vec<ArchOption>, ExperimentError> {
    require_fourier(design)?;
    if !(req.target_error_um.is_finite() && req.target_error_um > 0.0) {
        return Err(ExperimentError::option(
            "target-error-um",
            req.target_error_um,
            "a finite tone error > 0 µm (default 1)",
        ));
    }
    if req.liberties.is_empty() {
        return Err(ExperimentError::option(
            "liberty",
            "none",
            "at least one liberty",
        ));
    }
    if let Some(k) = &req.routed
        && !req
            .liberties
            .iter()
            .any(|l| k.applies_to(&l.to_string_lossy()))
    {
        return Err(ExperimentError::option(
            "layout-report",
            format!("a {} layout (k = {:.3})", k.technology, k.factor),
            &format!(
                "a layout of a technology among the liberties ({}): osu018 (the default) or sky130 (with the shared PDK)",
                req.liberties
                    .iter()
                    .map(|l| l.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    if req.seeds.is_empty() {
        return Err(ExperimentError::option(
            "seeds",
            "none",
            "at least one seed",
        ));
    }
    let mut only = req.only.clone();
    if !only.is_empty() && !only.iter().any(|o| o == "baseline") {
        only.insert(0, "baseline".into());
    }
    catalogue::select(
        catalogue::catalogue(design.pixel.frac_bits, design.pixel.ops_per_pulse()),
        &only,
    )
    .map_err(|e| ExperimentError::option("option", only.join(","), &e))
}

/// The study measures each option's tone error against the float DFT: a Fourier pixel's.
/// A Haar design is refused before anything runs, naming `pixel.mode` (it used to run for
/// minutes and then blame an `--option` the user never gave).
pub fn require_fourier(design: &ResolvedDesign) -> Result<(), ExperimentError> {
    if design.pixel.mode == tofprobe_pixel::Mode::Fourier {
        return Ok(());
    }
    Err(tofprobe_design::DesignError::pixel(
        &design.origin,
        tofprobe_pixel::PixelError::invalid(
            "mode",
            "\"haar\"",
            "the architecture options study (size --options, flow --recommended) compares \
             the tone errors of Fourier pixels; a Haar pixel has no tones to compare",
            "pixel.mode = \"fourier\", or size / flow without --options / --recommended",
        ),
    )
    .into())
}

/// Runs the study on `design`.
pub fn run(
    design: &ResolvedDesign,
    req: &OptionsRequest,
) -> Result<OptionsReport, ExperimentError> {
    let options = check(design, req)?;
    let libs = req
        .liberties
        .iter()
        .map(|p| Liberty::load(p))
        .collect::<Result<Vec<_>, _>>()?;
    let laser = design.sensor().laser_rate_hz;
    let base = design.document_with_decided_adders();
    let accuracies = accuracy::measure(&base, &design.origin, &options, &req.seeds);
    let mut rows = Vec::new();
    for (option, acc) in options.into_iter().zip(accuracies) {
        let acc = acc?;
        let p = acc.design.pixel.clone();
        let mut libraries = Vec::new();
        for lib in &libs {
            let a = area::measure(
                &p,
                &area::AreaRequest {
                    lib,
                    cache: &req.cache,
                    laser_rate_hz: laser,
                    node_nm: req.node_nm,
                    pixel_sides_um: &req.pixel_sides_um,
                    sweep_bins: &req.sweep_bins,
                    routed: req.routed.as_ref(),
                },
            )
            .map_err(|e| {
                ExperimentError::option(
                    "option",
                    &option.name,
                    &format!("synthesisable on {}: {e}", lib.name),
                )
            })?;
            libraries.push(a);
        }
        let meets_clock = libraries
            .iter()
            .all(|l| l.timing.as_ref().is_none_or(|t| t.meets_margin));
        rows.push(OptionRow {
            width_bits: p.width,
            register_frac_bits: p.register_frac_bits(),
            prefilter_rounding: p.prefilter_rounding.to_string(),
            register_file: p.register_file.to_string(),
            tone_error_um: acc.tone_error_um,
            libraries,
            meets_clock,
            on_front: false,
            option,
        });
    }
    let front_lib = libs.len() - 1;
    front::mark(&mut rows, front_lib);
    let recommendation = front::recommend(&rows, front_lib, req.target_error_um)?;
    let clock_mhz = design.pixel.cycles_per_pulse as f64 * laser / 1e6;
    let assumptions = vec![
        format!(
            "Tone error: |bit-true − float full DFT| tone amplitude at the scene's tone bin, on the scene's frame of {} pulses, over seeds {:?} of the photon source (the table shows the mean and the range; the recommendation holds the worst seed against the target).",
            design.pixel.frame_pulses, req.seeds
        ),
        format!(
            "Area: yosys and ABC's delay-driven mapping for C·f_laser (as `tofprobe size`), cell area only; the model A(B) = fixed + per_bin·B is the least-squares line through B = {:?} (the size report's B sweep) at the option's W, so the baseline's bins per pitch are the size report's.",
            area::model_bins(design.pixel.bins as u64, &req.sweep_bins)
        ),
        format!(
            "Bins per pitch: area scaled from the library's node by (node / library node)² to {} nm (osu018 180 nm, sky130 130 nm; first-order, an upper bound), the whole pitch given to the digital logic as the paper's estimate did.",
            req.node_nm
        ),
        format!(
            "Timing: OpenSTA on the synthesised netlist at C·f_laser = {clock_mhz:.1} MHz; an option meets its clock when it keeps {} % slack on every timed library.",
            tofprobe_eda::corners::MARGIN_PERCENT
        ),
        "The Pareto front: no other option has both less area per bin (front library) and a lower mean tone error.".into(),
    ];
    let mut assumptions = assumptions;
    let mut from_lef = std::collections::BTreeMap::new();
    for l in rows.iter().flat_map(|r| &r.libraries) {
        for (cell, a) in &l.area_from_lef {
            from_lef.insert((l.library.clone(), cell.clone()), *a);
        }
    }
    for ((library, cell), a) in from_lef {
        assumptions.push(format!(
            "{library}'s `{cell}` counts {a:.2} µm² from LEF: its liberty gives it area 0, so its outline in the LEF beside the liberty is used (the options that use it: a latch register file, or a clock gate built of a latch)."
        ));
    }
    if let Some(k) = &req.routed {
        assumptions.push(format!(
            "Bins per pitch from layout: each option's area model times the routed factor k = {:.3} (die area / cell area) of the {} macro of {} routed at density {:.2} (`tofprobe layout`), on the {} liberties only; k is taken to hold for every option and B (first order: it follows the density and the technology more than the logic).",
            k.factor, k.technology, k.config, k.density, k.technology
        ));
    }
    Ok(OptionsReport {
        bins: design.pixel.bins as u64,
        clock_mhz,
        pulses: design.pixel.frame_pulses,
        seeds: req.seeds.clone(),
        front_library: libs[front_lib].name.clone(),
        target_error_um: req.target_error_um,
        rows,
        recommendation,
        layout: req.routed.clone(),
        assumptions,
    })
}

/// `design` with the recommendation's `[pixel]` keys set: the pixel `flow --recommended`
/// builds. The same overrides and resolution as the study's own measurement.
pub fn recommended_design(
    design: &ResolvedDesign,
    report: &OptionsReport,
) -> Result<ResolvedDesign, ExperimentError> {
    let ov: Vec<(&str, &str)> = report
        .recommendation
        .overrides
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let origin = format!(
        "{} with option {}",
        design.origin, report.recommendation.option
    );
    crate::tradeoff::overrides::with_overrides(
        &design.document_with_decided_adders(),
        &origin,
        &ov,
        &mut tofprobe_design::ProbeCache::default(),
    )
}
