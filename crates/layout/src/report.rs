//! The layout report: what was routed where, the macro's figures, the checks' verdicts,
//! timing before and after routing, bins per pitch, and the time of each step; as JSON
//! and Markdown.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

pub use crate::Step;
use crate::def::DefFigures;
use crate::pitch_bins::BinsPerPitch;
use crate::sta::PostRoute;

pub mod verdict;

pub use crate::readers::{PostRouteTable, read_post_route, read_routed_factor};

/// JSON schema name of [`LayoutReport`].
pub const SCHEMA: &str = "tofprobe-layout-1";

/// One placement-and-routing attempt.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Attempt {
    /// Target density of the placement.
    pub density: f64,
    /// Nets qrouter left unrouted (0: routed).
    pub unrouted: usize,
    /// Their names (as qrouter reported them; at most 20).
    pub unrouted_nets: Vec<String>,
}

/// Synthesis figures of the routed netlist (the project's delay-driven yosys script,
/// ideal-clock OpenSTA).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SynthFigures {
    /// Cell area (µm²).
    pub area_um2: f64,
    /// Cells.
    pub cells: u64,
    /// f_max with an ideal clock and no wires (MHz).
    pub f_max_mhz: Option<f64>,
    /// Setup slack at the configuration's clock (ns).
    pub slack_ns: Option<f64>,
    /// The synthesis cache key.
    pub key: String,
}

/// Timing at one library corner: synthesis (ideal clock) beside post-route.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CornerRow {
    /// The liberty's library name.
    pub library: String,
    /// The corner (`typical` for osu018, `tt_025C_1v80`, `ss_n40C_1v40`, `ff_100C_1v95`).
    pub corner: String,
    /// Synthesis f_max (MHz), ideal clock, no wires.
    pub synthesis_f_max_mhz: f64,
    /// Synthesis setup slack at the configuration's clock (ns).
    pub synthesis_slack_ns: f64,
    /// Post-route timing at this corner (the same routed wires).
    pub post_route: PostRoute,
}

/// The report of `tofprobe layout`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct LayoutReport {
    /// [`SCHEMA`].
    pub schema: String,
    /// osu018 or sky130.
    pub tech: String,
    /// The configuration it came from.
    pub config: String,
    /// The module laid out.
    pub top: String,
    /// Bins B.
    pub bins: u64,
    /// Register width W.
    pub width: u32,
    /// Placement attempts, the routed one last.
    pub attempts: Vec<Attempt>,
    /// Whether qrouter ran its stage 3 (cleanup: every net re-routed shorter); reports
    /// written before the option existed all did.
    #[serde(default = "stage3_ran")]
    pub route_cleanup: bool,
    /// The routed macro.
    pub def: DefFigures,
    /// Synthesis.
    pub synthesis: SynthFigures,
    /// magic's DRC error count.
    pub drc_errors: u64,
    /// The rules the errors break (empty when clean).
    #[serde(default)]
    pub drc_rules: Vec<crate::qflow::DrcRule>,
    /// netgen's verdict: whether layout and synthesised netlist match.
    pub lvs_match: bool,
    /// netgen's result line.
    pub lvs_result: String,
    /// The nonzero counts of the LVS summary (empty when it matches).
    #[serde(default)]
    pub lvs_errors: Vec<String>,
    /// The ECO re-route of a route the checks found dirty (None: clean at once, or a
    /// report written before the repair existed).
    #[serde(default)]
    pub repair: Option<crate::repair::Repair>,
    /// Post-route timing.
    pub post_route: PostRoute,
    /// Bins per pitch (None when the B sweep's model could not be fitted).
    pub bins_per_pitch: Option<BinsPerPitch>,
    /// Steps and their wall times.
    pub steps: Vec<Step>,
    /// Buffers blifFanout added (the clock tree).
    pub clock_buffers: u64,
    /// Every corner of the technology's liberties (osu018: one; sky130: tt, ss, ff).
    pub corners: Vec<CornerRow>,
    /// The die grown by a track pitch around the edge tracks, pins extended to it (None:
    /// a report written before).
    #[serde(default)]
    pub die_growth: Option<crate::die::Growth>,
    /// Every shape of the routed DEF measured against the die.
    #[serde(default)]
    pub def_boundary: Option<crate::boundary::Outside>,
    /// Each DEF section's declared and listed entries.
    #[serde(default)]
    pub def_counts: Vec<crate::def::SectionCount>,
    /// The GDS as klayout reads it: its cells (empty ones: no cell GDS) and shapes.
    #[serde(default)]
    pub gds: Option<crate::gds::GdsFigures>,
    /// The laid-out netlist (the routed DEF's cells and nets) proven equivalent to the RTL.
    #[serde(default)]
    pub equivalence: Option<crate::netlist::LaidOutProof>,
    /// For each corner whose setup the routed pixel misses, the option that meets it.
    #[serde(default)]
    pub corner_options: Vec<tofprobe_eda::corner_option::CornerOption>,
    /// The checks the macro fails, each saying which and by how much (empty: exit 0).
    #[serde(default)]
    pub failures: Vec<String>,
    /// What the figures assume.
    pub notes: Vec<String>,
}

fn stage3_ran() -> bool {
    true
}

impl LayoutReport {
    /// Whether the macro is clean: DRC 0 and LVS match.
    pub fn clean(&self) -> bool {
        self.drc_errors == 0 && self.lvs_match
    }

    /// Whether every check passed (`tofprobe layout` exits 0): clean, the laid-out netlist
    /// proven, timing met, every shape inside the die, the DEF's counts right.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// The density that routed.
    pub fn density(&self) -> f64 {
        self.attempts.last().map_or(0.0, |a| a.density)
    }

    /// One line for the terminal.
    pub fn summary(&self) -> String {
        format!(
            "layout {}: {:.1} × {:.1} µm die ({:.0} µm²), utilisation {:.1} %, wirelength {:.0} µm, DRC {}, LVS {}, post-route f_max {:.1} MHz (setup slack {:.3} ns, hold {:.3} ns, register to register {:.3} ns at {:.3} ns)",
            self.tech,
            self.def.die_width_um,
            self.def.die_height_um,
            self.def.die_area_um2(),
            100.0 * self.def.utilisation(),
            self.def.wirelength_um,
            self.drc_errors,
            if self.lvs_match { "match" } else { "MISMATCH" },
            self.post_route.f_max_mhz,
            self.post_route.setup_slack_ns,
            self.post_route.hold_slack_ns,
            self.post_route.hold_slack_registers_ns,
            self.post_route.period_ns,
        )
    }

    /// The Markdown report.
    pub fn markdown(&self) -> String {
        let d = &self.def;
        let mut s = format!(
            "# Layout of `{}` on {}\n\nConfiguration: `{}`; B = {}, W = {}.\n\n## Macro\n\n\
             | figure | value |\n|---|---:|\n\
             | die | {:.2} × {:.2} µm = {:.0} µm² |\n| core (placed cells' extent) | {:.2} × {:.2} µm = {:.0} µm² |\n\
             | logic cells | {} ({:.0} µm², {} of them clock buffers; {} fill cells) |\n| utilisation (cells / core) | {:.1} % |\n\
             | target density routed | {} |\n| routed wirelength | {:.0} µm{} |\n| DRC errors (magic) | {} |\n\
             | LVS (netgen, layout vs synthesised netlist) | {} — {} |\n\n",
            self.top,
            self.tech,
            self.config,
            self.bins,
            self.width,
            d.die_width_um,
            d.die_height_um,
            d.die_area_um2(),
            d.core_width_um,
            d.core_height_um,
            d.core_area_um2(),
            d.cells,
            d.cell_area_um2,
            self.clock_buffers,
            d.fill_cells,
            100.0 * d.utilisation(),
            self.density(),
            d.wirelength_um,
            if self.route_cleanup {
                ""
            } else {
                " (qrouter stage 3 skipped)"
            },
            self.drc_errors,
            if self.lvs_match { "match" } else { "MISMATCH" },
            if self.lvs_errors.is_empty() {
                self.lvs_result.clone()
            } else {
                format!("{} ({})", self.lvs_result, self.lvs_errors.join(", "))
            },
        );
        // The verdict first, after the title; the checks' details after the macro table.
        let at = s.find("## Macro").unwrap_or(s.len());
        s.insert_str(at, &verdict::verdict_markdown(self));
        s += &verdict::checks_markdown(self);
        if !self.drc_rules.is_empty() {
            s += "DRC errors by rule (magic's `drc listall why`):\n\n| rule | error boxes |\n|---|---:|\n";
            for r in &self.drc_rules {
                let _ = writeln!(s, "| {} | {} |", r.rule, r.boxes);
            }
            s += "\n";
        }
        if let Some(r) = &self.repair {
            let _ = writeln!(
                s,
                "ECO re-route of the dirty stage-2 route (the nets at the DRC error boxes and \
                 netgen's unmatched nets ripped up and routed again, at most {} rounds): DRC {} → {}, \
                 LVS errors {} → {}; {}.\n\n| round | nets re-routed | unrouted | DRC after | LVS errors after | re-route (s) | checks (s) |\n|---:|---|---:|---:|---:|---:|---:|",
                crate::repair::MAX_ROUNDS,
                r.drc_before,
                self.drc_errors,
                r.lvs_before,
                r.rounds.last().map_or(r.lvs_before, |x| x.lvs_errors),
                r.stopped,
            );
            for (i, x) in r.rounds.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {:.1} | {:.1} |",
                    i + 1,
                    x.nets
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", "),
                    x.unrouted,
                    x.drc_errors,
                    x.lvs_errors,
                    x.route_seconds,
                    x.check_seconds
                );
            }
            s += "\n";
        }
        if self.attempts.len() > 1 {
            s += "Placement attempts:\n\n| density | unrouted nets |\n|---:|---|\n";
            for a in &self.attempts {
                let _ = writeln!(
                    s,
                    "| {} | {}{} |",
                    a.density,
                    a.unrouted,
                    if a.unrouted_nets.is_empty() {
                        String::new()
                    } else {
                        format!(" ({})", a.unrouted_nets.join(", "))
                    }
                );
            }
            s += "\n";
        }
        let p = &self.post_route;
        let opt = |v: Option<f64>, d: usize| v.map_or("—".into(), |v| format!("{v:.d$}"));
        let _ = write!(
            s,
            "## Timing at the configuration's clock ({:.3} ns, {:.1} MHz)\n\n\
             | | synthesis (ideal clock, no wires) | post-route (SPEF, propagated clock) |\n|---|---:|---:|\n\
             | f_max (MHz) | {} | {:.1} |\n| setup slack (ns) | {} | {:.3} |\n| hold slack (ns), all paths | — | {:.3} |\n| hold slack (ns), register to register | — | {:.3} |\n\n\
             Worst setup path: `{}` → `{}`; worst hold path: `{}` → `{}`; {} nets annotated from the SPEF.\n\n",
            p.period_ns,
            1e3 / p.period_ns,
            opt(self.synthesis.f_max_mhz, 1),
            p.f_max_mhz,
            opt(self.synthesis.slack_ns, 3),
            p.setup_slack_ns,
            p.hold_slack_ns,
            p.hold_slack_registers_ns,
            p.setup_path.0,
            p.setup_path.1,
            p.hold_path.0,
            p.hold_path.1,
            p.spef_nets,
        );
        s += &verdict::timing_note(p);
        s += "## Corners\n\n";
        s += &corners_markdown(&self.corners);
        s += "\n";
        if let Some(b) = &self.bins_per_pitch {
            let _ = write!(
                s,
                "## Bins per pitch at {} nm\n\nSynthesis model A(B) = {:.0} + {:.0}·B µm² ({} nm), routed factor k = die / cell area = {:.3}, scaled by ({}/{})² = {:.4}.\n\n\
                 The routed macro of this pixel (B = {}) needs a {:.1} × {:.1} µm pitch at {} nm.\n\n\
                 | pitch | from layout | from synthesis | paper |\n|---|---:|---:|---:|\n",
                b.target_node_nm,
                b.synthesis_model.fixed_um2,
                b.synthesis_model.per_bin_um2,
                b.tech_node_nm,
                b.routed_factor,
                b.target_node_nm,
                b.tech_node_nm,
                b.area_factor,
                self.bins,
                b.routed_side_um,
                b.routed_side_um,
                b.target_node_nm,
            );
            for p in &b.pitches {
                let _ = writeln!(
                    s,
                    "| {0} × {0} µm | {1} | {2} | {3} |",
                    p.side_um,
                    p.layout_bins,
                    p.synthesis_bins,
                    p.paper_bins.map_or("—".into(), |n| n.to_string())
                );
            }
            s += "\n";
        }
        s += "## Steps\n\n| step | seconds |\n|---|---:|\n";
        for st in &self.steps {
            let _ = writeln!(s, "| {} | {:.1} |", st.step, st.seconds);
        }
        let total: f64 = self.steps.iter().map(|s| s.seconds).sum();
        let _ = writeln!(s, "| total | {total:.1} |\n\n## Notes\n");
        for n in &self.notes {
            let _ = writeln!(s, "- {n}");
        }
        s
    }
}

/// The corner table: synthesis beside post-route, setup and hold, per library and corner
/// (the layout report's and `tofprobe size --layout-report`'s).
pub fn corners_markdown(corners: &[CornerRow]) -> String {
    let mut s = String::from(
        "| library | corner | synthesis f_max (MHz) | synthesis slack (ns) | post-route f_max (MHz) | post-route setup slack (ns) | hold slack (ns), all / register to register | meets the clock |\n|---|---|---:|---:|---:|---:|---:|---|\n",
    );
    for c in corners {
        let p = &c.post_route;
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.3} | {:.1} | {:.3} | {:.3} / {:.3} | {} |",
            c.library,
            c.corner,
            c.synthesis_f_max_mhz,
            c.synthesis_slack_ns,
            p.f_max_mhz,
            p.setup_slack_ns,
            p.hold_slack_ns,
            p.hold_slack_registers_ns,
            if p.setup_slack_ns >= 0.0 && p.hold_slack_registers_ns >= 0.0 {
                "yes"
            } else {
                "**no**"
            }
        );
    }
    s
}
