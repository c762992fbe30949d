//! The flow as `tofprobe flow` runs it on any configuration: the options study first when
//! the design is to be recommended (a single pixel only), then the array's flow for an
//! `[array]` configuration or the pixel's. The CLI parses its options into these calls and
//! prints; which flow runs, and what is refused, is decided here (tested in
//! crates/flow/tests/it/command.rs).

use tofprobe_design::ResolvedDesign;
use tofprobe_experiments::options::OptionsReport;

use crate::error::FlowError;
use crate::flow::{FlowOptions, FlowOutcome, check_frames, recommended, run_flow};

/// `flow --recommended`: the options study's restriction and target.
#[derive(Debug, Clone, PartialEq)]
pub struct Recommend {
    /// Only these options of the catalogue (empty: all).
    pub only: Vec<String>,
    /// The tone error the recommendation must meet (µm).
    pub target_error_um: f64,
}

/// The design the flow runs: `design` itself, or with `recommend` the options study's
/// recommendation and the study (refused for an `[array]`, naming `recommended`). The
/// flow's `frames` is checked first, so a study is not run for a flow that would be
/// refused.
pub fn choose(
    design: ResolvedDesign,
    frames: u64,
    recommend: Option<&Recommend>,
) -> Result<(ResolvedDesign, Option<OptionsReport>), FlowError> {
    check_frames(frames)?;
    let Some(r) = recommend else {
        return Ok((design, None));
    };
    if design.array.is_some() {
        return Err(FlowError::option(
            "recommended",
            "given",
            "a single-pixel configuration",
        ));
    }
    let (chosen, report) = recommended(&design, r.only.clone(), r.target_error_um)?;
    Ok((chosen, Some(report)))
}

/// Runs the array's flow for an `[array]` design, the pixel's otherwise.
pub fn run_any(design: &ResolvedDesign, o: &FlowOptions) -> Result<FlowOutcome, FlowError> {
    if design.array.is_some() {
        crate::array::run_array_flow(design, o)
    } else {
        run_flow(design, o)
    }
}
