//! The ECO re-route: the repair of a routed macro that magic's DRC or netgen's LVS finds
//! dirty after qrouter's stages 1 and 2 (stage 3, which re-routes every net, is skipped
//! on large pixels). The nets to repair are read from the checks' own output — the nets
//! whose wires come near a DRC error box (`drc listall why`), and the nets netgen's
//! `comp.out` lists as unmatched (a layout net named after a cell pin is mapped back to
//! the DEF net on that pin) — and only those are re-routed: qrouter reads the routed DEF
//! and, one net at a time, removes it (`remove net`) and routes it with stage 1, the other
//! nets' wires nearby also declared as obstructions (stage 2 would route across read-in
//! routes it cannot rip up: shorts). Only the re-routed nets are spliced into the DEF and
//! RC files; DRC and LVS then run again, at most [`MAX_ROUNDS`] times.

use crate::error::{LayoutError, Result};
use crate::qflow::Checks;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

mod nets;
mod script;
#[cfg(test)]
mod tests;

pub use nets::*;
pub use script::*;

/// Rounds of re-route and re-check at most: each round re-routes only the nets the last
/// checks name, so a repair that has not converged in three rounds is not converging.
pub const MAX_ROUNDS: usize = 3;

/// One round of the repair.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RepairRound {
    /// The nets ripped up and re-routed.
    pub nets: Vec<String>,
    /// Nets qrouter left unrouted in this round (the round is dropped when > 0).
    pub unrouted: u64,
    /// DRC errors after the round.
    pub drc_errors: u64,
    /// LVS total errors after the round (0: match).
    pub lvs_errors: u64,
    /// Wall time of the re-route (s).
    pub route_seconds: f64,
    /// Wall time of the checks after it (s).
    pub check_seconds: f64,
}

/// The repair of a dirty route: the checks before, each round, the verdict.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Repair {
    /// DRC errors before the repair.
    pub drc_before: u64,
    /// LVS total errors before the repair.
    pub lvs_before: u64,
    /// The rounds run.
    pub rounds: Vec<RepairRound>,
    /// Whether the macro is clean after the last round.
    pub clean: bool,
    /// Why it stopped (clean, no net to re-route, unrouted nets, rounds exhausted).
    pub stopped: String,
}

impl Repair {
    /// Every net re-routed, over the rounds.
    pub fn nets(&self) -> BTreeSet<&str> {
        self.rounds
            .iter()
            .flat_map(|r| r.nets.iter().map(String::as_str))
            .collect()
    }
}

/// An error for an ECO round's output that qrouter did not write.
pub fn missing(path: &std::path::Path) -> LayoutError {
    LayoutError::Parse {
        tool: "qrouter (ECO re-route)",
        what: "the re-routed DEF and RC files".into(),
        path: path.to_path_buf(),
    }
}

/// What one ECO round did to the routed DEF.
#[derive(Debug, Clone, PartialEq)]
pub struct EcoRound {
    /// The nets re-routed (those asked for and the blockers qrouter ripped up).
    pub changed: BTreeSet<String>,
    /// Nets qrouter left unrouted (then the DEF was not changed).
    pub unrouted: u64,
    /// Wall time (s).
    pub seconds: f64,
}

/// One ECO round: qrouter reads the routed `layout/TOP.def`, re-routes `targets`
/// ([`eco_script`], log `log/eco_route_N.log`), and the nets it changed are spliced into
/// `TOP.def` and `TOP.rc` ([`splice_def`], [`splice_rc`]) — unless it left a net
/// unrouted, when both files stay as they were.
pub fn eco_round(
    project: &crate::qflow::Project,
    targets: &BTreeSet<String>,
    round: usize,
) -> Result<EcoRound> {
    let qrouter = crate::tools::Tool::Qrouter.locate()?;
    let layout = project.dir.join("layout");
    let top = &project.top;
    let t = std::time::Instant::now();
    let (def, rc) = (project.layout_file("def"), project.layout_file("rc"));
    let script = layout.join(format!("{top}_eco.cfg"));
    let cfg = read(&project.layout_file("cfg"))?;
    let fenced = fence(&def_nets(&read(&def)?), targets);
    std::fs::write(&script, eco_script(&cfg, top, targets, &fenced))
        .map_err(|e| LayoutError::io("writing", &script, e))?;
    let out = std::process::Command::new(&qrouter)
        .args(["-nog", "-s"])
        .arg(&script)
        .current_dir(&layout)
        .output()
        .map_err(|e| LayoutError::io("running", &qrouter, e))?;
    let log = String::from_utf8_lossy(&out.stdout).to_string();
    let log_path = project
        .dir
        .join("log")
        .join(format!("eco_route_{round}.log"));
    std::fs::write(&log_path, &log).map_err(|e| LayoutError::io("writing", &log_path, e))?;
    let unrouted = eco_failing(&log).ok_or_else(|| missing(&log_path))?;
    let changed = eco_changed(&log, targets);
    if unrouted == 0 {
        let (eco_def, eco_rc) = (
            layout.join(format!("{top}_eco.def")),
            layout.join(format!("{top}_eco.rc")),
        );
        let spliced = splice_def(&read(&def)?, &read(&eco_def)?, &changed)
            .ok_or_else(|| missing(&eco_def))?;
        let rc_text = splice_rc(&read(&rc)?, &read(&eco_rc)?, &changed);
        std::fs::write(&def, spliced).map_err(|e| LayoutError::io("writing", &def, e))?;
        std::fs::write(&rc, rc_text).map_err(|e| LayoutError::io("writing", &rc, e))?;
    }
    Ok(EcoRound {
        changed,
        unrouted,
        seconds: t.elapsed().as_secs_f64(),
    })
}

fn read(p: &std::path::Path) -> Result<String> {
    std::fs::read_to_string(p).map_err(|e| LayoutError::io("reading", p, e))
}

fn copy(a: &std::path::Path, b: &std::path::Path) -> Result<()> {
    std::fs::copy(a, b)
        .map(|_| ())
        .map_err(|e| LayoutError::io("copying", a, e))
}

/// The errors a set of checks counts: DRC boxes plus netgen's total.
fn errors(c: &Checks) -> u64 {
    c.drc_errors + c.lvs_total
}

/// Repairs a routed macro whose `first` checks are dirty: at most [`MAX_ROUNDS`] rounds of
/// re-routing the nets the last checks name ([`eco_round`]) and checking again. The
/// stage-2 DEF and RC files are kept as `TOP_stage2.def`/`.rc`. A round that leaves a net
/// unrouted changes nothing; a round whose checks count more errors than the best so far
/// is undone (the best route is put back and checked again) and ends the repair, so the
/// macro is never left worse than the route it started from. Each round's re-route and
/// checks are timed in `steps`. Returns the repair's record and the last checks.
pub fn repair(
    project: &crate::qflow::Project,
    first: Checks,
    steps: &mut Vec<crate::Step>,
    progress: &mut dyn FnMut(&str),
) -> Result<(Repair, Checks)> {
    let layout = project.dir.join("layout");
    let top = &project.top;
    let (def, rc) = (project.layout_file("def"), project.layout_file("rc"));
    let (best_def, best_rc) = (
        layout.join(format!("{top}_best.def")),
        layout.join(format!("{top}_best.rc")),
    );
    copy(&def, &layout.join(format!("{top}_stage2.def")))?;
    copy(&rc, &layout.join(format!("{top}_stage2.rc")))?;
    copy(&def, &best_def)?;
    copy(&rc, &best_rc)?;
    let mut rep = Repair {
        drc_before: first.drc_errors,
        lvs_before: first.lvs_total,
        rounds: vec![],
        clean: false,
        stopped: format!("{MAX_ROUNDS} rounds run, still dirty"),
    };
    let mut best = errors(&first);
    let mut checks = first;
    for round in 1..=MAX_ROUNDS {
        let nets = def_nets(&read(&def)?);
        let mut targets = nets_at_boxes(&nets, &checks.drc_boxes, NEAR_UM);
        if !checks.lvs_match {
            let comp = layout.join("comp.out");
            targets.extend(lvs_nets(&read(&comp).unwrap_or_default(), &nets));
        }
        if targets.is_empty() {
            rep.stopped = format!("round {round}: no net found at the errors");
            break;
        }
        progress(&format!(
            "ECO re-route, round {round}: {} nets",
            targets.len()
        ));
        let eco = eco_round(project, &targets, round)?;
        steps.push(crate::Step {
            step: format!(
                "ECO re-route round {round} (qrouter, {} nets)",
                eco.changed.len()
            ),
            seconds: eco.seconds,
        });
        let mut record = RepairRound {
            nets: eco.changed.iter().cloned().collect(),
            unrouted: eco.unrouted,
            drc_errors: checks.drc_errors,
            lvs_errors: checks.lvs_total,
            route_seconds: eco.seconds,
            check_seconds: 0.0,
        };
        if eco.unrouted > 0 {
            rep.rounds.push(record);
            rep.stopped = format!(
                "round {round}: {} nets left unrouted, round not taken",
                eco.unrouted
            );
            break;
        }
        progress(&format!("DRC and LVS after round {round}"));
        checks = project.checks()?;
        let seconds = checks.drc_seconds + checks.lvs_seconds;
        steps.push(crate::Step {
            step: format!("DRC, extraction, LVS after round {round} (magic, netgen)"),
            seconds,
        });
        record.drc_errors = checks.drc_errors;
        record.lvs_errors = checks.lvs_total;
        record.check_seconds = seconds;
        rep.rounds.push(record);
        if checks.clean() {
            rep.stopped = format!("clean after round {round}");
            break;
        }
        if errors(&checks) < best {
            best = errors(&checks);
            copy(&def, &best_def)?;
            copy(&rc, &best_rc)?;
        } else {
            progress("the round made it worse: the best route back, checked again");
            copy(&best_def, &def)?;
            copy(&best_rc, &rc)?;
            checks = project.checks()?;
            steps.push(crate::Step {
                step: "DRC, extraction, LVS of the best route again (magic, netgen)".into(),
                seconds: checks.drc_seconds + checks.lvs_seconds,
            });
            rep.stopped = format!(
                "round {round} counted {} errors against {best}: undone, the best route kept",
                rep.rounds.last().map_or(0, |r| r.drc_errors + r.lvs_errors)
            );
            break;
        }
    }
    rep.clean = checks.clean();
    Ok((rep, checks))
}
