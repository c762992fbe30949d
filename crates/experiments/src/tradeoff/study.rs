//! The whole `tradeoff` study of a list of configurations: which measurement each design
//! gets (a Fourier `[array]`: its array levels against bit-true; a Haar pixel: the Haar
//! ladder; a Fourier pixel: the level ladder, then the knob sweep and the skipped stages
//! when asked), the imputation study once when asked, one report holding every result,
//! its Markdown tables and the files of its output set. The CLI parses the options into a
//! [`StudyRequest`], calls [`run`] and prints; the decisions are here, so they are tested
//! in this crate (crates/experiments/tests/it/study.rs).

use serde::Serialize;
use tofprobe_design::{ArrayLevel, ResolvedDesign};
use tofprobe_pixel::Mode;

use super::array::{self as array_levels, ArrayTradeoff, measure_array};
use super::haar::{self, HaarSceneResult, measure_haar};
use super::imputation::{self, ImputationReport};
use super::imputation_cost::CellAreas;
use super::knobs::{self, DEFAULT_SWEEP, KnobSweep};
use super::skips::{self, SkipReport, measure_skips};
use super::{SceneResult, markdown, measure, plot::pareto_svg_text};
use crate::error::ExperimentError;

/// What to measure besides each configuration's levels.
#[derive(Debug, Clone, Default)]
pub struct StudyRequest {
    /// Time the cycle-accurate RTL under Verilator too.
    pub verilator: bool,
    /// The bit-true knob sweep ([`DEFAULT_SWEEP`]).
    pub knobs: bool,
    /// Only these knobs of the sweep (empty: all); each must be a knob of the sweep.
    pub only_knobs: Vec<String>,
    /// The skipped-stage speedups.
    pub skips: bool,
    /// Largest frame of the knob sweep and the skips (pulses).
    pub sweep_pulses: u64,
    /// Runs per timing of the sweep and the skips (the median is kept).
    pub reps: usize,
    /// The imputation study: (pulses per record, seeds).
    pub imputation: Option<(u64, usize)>,
}

/// Every result of one study, as `tofprobe tradeoff --json` prints it.
#[derive(Debug, Serialize)]
pub struct Study {
    /// Fourier pixels' level ladders.
    pub scenes: Vec<SceneResult>,
    /// Haar pixels' ladders.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub haar_scenes: Vec<HaarSceneResult>,
    /// `[array]` configurations' levels against bit-true.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub array_scenes: Vec<ArrayTradeoff>,
    /// Knob sweeps (one per Fourier pixel, with `knobs`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub knobs: Vec<KnobSweep>,
    /// Skipped-stage speedups (one per Fourier pixel, with `skips`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skips: Vec<SkipReport>,
    /// The imputation study (with `imputation`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imputation: Option<ImputationReport>,
    /// The Markdown tables in the order they were measured.
    #[serde(skip)]
    pub tables: Vec<String>,
}

/// The knob names of [`DEFAULT_SWEEP`], each once, in the sweep's order.
pub fn knob_names() -> Vec<&'static str> {
    let mut names: Vec<&str> = DEFAULT_SWEEP.iter().map(|s| s.knob).collect();
    names.dedup();
    names
}

/// Runs the study on each design in turn. A knob asked for that the sweep does not have is
/// refused before anything runs, naming the option `knob` and the sweep's knobs.
pub fn run(designs: &[ResolvedDesign], req: &StudyRequest) -> Result<Study, ExperimentError> {
    if let Some(bad) = req
        .only_knobs
        .iter()
        .find(|k| !DEFAULT_SWEEP.iter().any(|s| s.knob == k.as_str()))
    {
        return Err(ExperimentError::option(
            "knob",
            bad,
            &knob_names().join(", "),
        ));
    }
    let mut study = Study {
        scenes: Vec::new(),
        haar_scenes: Vec::new(),
        array_scenes: Vec::new(),
        knobs: Vec::new(),
        skips: Vec::new(),
        imputation: None,
        tables: Vec::new(),
    };
    for design in designs {
        measure_design(design, req, &mut study)?;
    }
    if let Some((pulses, seeds)) = req.imputation {
        let cells = CellAreas::sky130()?;
        let r = imputation::measure(pulses, seeds, cells.as_ref())?;
        study.tables.push(imputation::markdown(&r));
        study.imputation = Some(r);
    }
    Ok(study)
}

/// One design's measurements, by its kind.
fn measure_design(
    design: &ResolvedDesign,
    req: &StudyRequest,
    study: &mut Study,
) -> Result<(), ExperimentError> {
    if design.array.is_some() && design.pixel.mode == Mode::Fourier {
        let r = measure_array(design, &ArrayLevel::ALL)?;
        study.tables.push(array_levels::markdown(&r));
        study.array_scenes.push(r);
        return Ok(());
    }
    design.single_pixel("tradeoff")?;
    if design.pixel.mode == Mode::Haar {
        let h = measure_haar(design, req.verilator)?;
        study.tables.push(haar::markdown(&h));
        if req.knobs || req.skips {
            study.tables.push(format!(
                "(--knobs / --skips measure the Fourier pixel's knobs and stages: skipped for the Haar pixel of {})\n",
                design.origin
            ));
        }
        study.haar_scenes.push(h);
        return Ok(());
    }
    let scene = measure(design, req.verilator)?;
    study.tables.push(markdown(&scene));
    study.scenes.push(scene);
    if req.knobs {
        let settings = knobs::select(DEFAULT_SWEEP, &req.only_knobs);
        let sw = knobs::sweep(design, &settings, req.sweep_pulses, req.reps);
        study.tables.push(knobs::markdown(&sw));
        study.knobs.push(sw);
    }
    if req.skips {
        let sk = measure_skips(design, req.sweep_pulses, req.reps)?;
        study.tables.push(skips::markdown(&sk));
        study.skips.push(sk);
    }
    Ok(())
}

impl Study {
    /// Every table, in the order measured.
    pub fn markdown(&self) -> String {
        self.tables.join("\n")
    }

    /// The output set's files (name, contents): the Pareto plot of the Fourier pixels' levels
    /// (when there are any) and `tradeoff.md`, last (the set's marker file). `dir` is where the
    /// set goes (named in a plot's error).
    pub fn files(
        &self,
        dir: &std::path::Path,
    ) -> Result<Vec<(&'static str, String)>, ExperimentError> {
        let mut files = Vec::new();
        if !self.scenes.is_empty() {
            files.push((
                "pareto.svg",
                pareto_svg_text(&dir.join("pareto.svg"), &self.scenes)?,
            ));
        }
        files.push(("tradeoff.md", self.markdown()));
        Ok(files)
    }
}
