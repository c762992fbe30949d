//! The layout report: what was routed where, the macro's figures, the checks' verdicts,
//! timing before and after routing, bins per pitch, and the time of each step; as JSON
//! and Markdown.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use tofprobe_io::markdown::{Align, Table};

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

    /// The macro's figures: die, core, cells, utilisation, routing, DRC, LVS.
    fn macro_table(&self) -> Table {
        let d = &self.def;
        let mut t = Table::numeric(["figure", "value"]);
        t.row([
            "die".to_string(),
            format!(
                "{:.2} × {:.2} µm = {:.0} µm²",
                d.die_width_um,
                d.die_height_um,
                d.die_area_um2()
            ),
        ])
        .row([
            "core (placed cells' extent)".to_string(),
            format!(
                "{:.2} × {:.2} µm = {:.0} µm²",
                d.core_width_um,
                d.core_height_um,
                d.core_area_um2()
            ),
        ])
        .row([
            "logic cells".to_string(),
            format!(
                "{} ({:.0} µm², {} of them clock buffers; {} fill cells)",
                d.cells, d.cell_area_um2, self.clock_buffers, d.fill_cells
            ),
        ])
        .row([
            "utilisation (cells / core)".to_string(),
            format!("{:.1} %", 100.0 * d.utilisation()),
        ])
        .row([
            "target density routed".to_string(),
            self.density().to_string(),
        ])
        .row([
            "routed wirelength".to_string(),
            format!(
                "{:.0} µm{}",
                d.wirelength_um,
                if self.route_cleanup {
                    ""
                } else {
                    " (qrouter stage 3 skipped)"
                }
            ),
        ])
        .row([
            "DRC errors (magic)".to_string(),
            self.drc_errors.to_string(),
        ])
        .row([
            "LVS (netgen, layout vs synthesised netlist)".to_string(),
            format!(
                "{} — {}",
                if self.lvs_match { "match" } else { "MISMATCH" },
                if self.lvs_errors.is_empty() {
                    self.lvs_result.clone()
                } else {
                    format!("{} ({})", self.lvs_result, self.lvs_errors.join(", "))
                }
            ),
        ]);
        t
    }

    /// Synthesis beside post-route at the configuration's clock.
    fn timing_table(&self) -> Table {
        let p = &self.post_route;
        let opt = |v: Option<f64>, d: usize| v.map_or("—".into(), |v| format!("{v:.d$}"));
        let mut t = Table::new([
            ("", Align::Left),
            ("synthesis (ideal clock, no wires)", Align::Right),
            ("post-route (SPEF, propagated clock)", Align::Right),
        ]);
        t.row([
            "f_max (MHz)".to_string(),
            opt(self.synthesis.f_max_mhz, 1),
            format!("{:.1}", p.f_max_mhz),
        ])
        .row([
            "setup slack (ns)".to_string(),
            opt(self.synthesis.slack_ns, 3),
            format!("{:.3}", p.setup_slack_ns),
        ])
        .row([
            "hold slack (ns), all paths".to_string(),
            "—".into(),
            format!("{:.3}", p.hold_slack_ns),
        ])
        .row([
            "hold slack (ns), register to register".to_string(),
            "—".into(),
            format!("{:.3}", p.hold_slack_registers_ns),
        ]);
        t
    }

    /// The Markdown report.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "# Layout of `{}` on {}\n\nConfiguration: `{}`; B = {}, W = {}.\n\n## Macro\n\n{}\n",
            self.top,
            self.tech,
            self.config,
            self.bins,
            self.width,
            self.macro_table(),
        );
        // The verdict first, after the title; the checks' details after the macro table.
        let at = s.find("## Macro").unwrap_or(s.len());
        s.insert_str(at, &verdict::verdict_markdown(self));
        s += &verdict::checks_markdown(self);
        if !self.drc_rules.is_empty() {
            let mut t = Table::numeric(["rule", "error boxes"]);
            for r in &self.drc_rules {
                t.row([r.rule.clone(), r.boxes.to_string()]);
            }
            let _ = writeln!(s, "DRC errors by rule (magic's `drc listall why`):\n\n{t}");
        }
        if let Some(r) = &self.repair {
            let _ = writeln!(
                s,
                "ECO re-route of the dirty stage-2 route (the nets at the DRC error boxes and \
                 netgen's unmatched nets ripped up and routed again, at most {} rounds): DRC {} → {}, \
                 LVS errors {} → {}; {}.\n",
                crate::repair::MAX_ROUNDS,
                r.drc_before,
                self.drc_errors,
                r.lvs_before,
                r.rounds.last().map_or(r.lvs_before, |x| x.lvs_errors),
                r.stopped,
            );
            let mut t = Table::numeric([
                "round",
                "nets re-routed",
                "unrouted",
                "DRC after",
                "LVS errors after",
                "re-route (s)",
                "checks (s)",
            ]);
            for (i, x) in r.rounds.iter().enumerate() {
                t.row([
                    (i + 1).to_string(),
                    x.nets
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", "),
                    x.unrouted.to_string(),
                    x.drc_errors.to_string(),
                    x.lvs_errors.to_string(),
                    format!("{:.1}", x.route_seconds),
                    format!("{:.1}", x.check_seconds),
                ]);
            }
            let _ = writeln!(s, "{t}");
        }
        if self.attempts.len() > 1 {
            let mut t = Table::new([("density", Align::Right), ("unrouted nets", Align::Left)]);
            for a in &self.attempts {
                t.row([
                    a.density.to_string(),
                    format!(
                        "{}{}",
                        a.unrouted,
                        if a.unrouted_nets.is_empty() {
                            String::new()
                        } else {
                            format!(" ({})", a.unrouted_nets.join(", "))
                        }
                    ),
                ]);
            }
            let _ = writeln!(s, "Placement attempts:\n\n{t}");
        }
        let p = &self.post_route;
        let _ = write!(
            s,
            "## Timing at the configuration's clock ({:.3} ns, {:.1} MHz)\n\n{}\n\
             Worst setup path: `{}` → `{}`; worst hold path: `{}` → `{}`; {} nets annotated from the SPEF.\n\n",
            p.period_ns,
            1e3 / p.period_ns,
            self.timing_table(),
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
                 The routed macro of this pixel (B = {}) needs a {:.1} × {:.1} µm pitch at {} nm.\n\n",
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
            let mut t = Table::numeric(["pitch", "from layout", "from synthesis", "paper"]);
            for p in &b.pitches {
                t.row([
                    format!("{0} × {0} µm", p.side_um),
                    p.layout_bins.to_string(),
                    p.synthesis_bins.to_string(),
                    p.paper_bins.map_or("—".into(), |n| n.to_string()),
                ]);
            }
            let _ = writeln!(s, "{t}");
        }
        let mut steps = Table::numeric(["step", "seconds"]);
        for st in &self.steps {
            steps.row([st.step.to_string(), format!("{:.1}", st.seconds)]);
        }
        let total: f64 = self.steps.iter().map(|s| s.seconds).sum();
        steps.row(["total".to_string(), format!("{total:.1}")]);
        let _ = writeln!(s, "## Steps\n\n{steps}\n## Notes\n");
        for n in &self.notes {
            let _ = writeln!(s, "- {n}");
        }
        s
    }
}

/// The corner table: synthesis beside post-route, setup and hold, per library and corner
/// (the layout report's and `tofprobe size --layout-report`'s).
pub fn corners_markdown(corners: &[CornerRow]) -> String {
    let right = |h: &'static str| (h, Align::Right);
    let mut t = Table::new([
        ("library", Align::Left),
        ("corner", Align::Left),
        right("synthesis f_max (MHz)"),
        right("synthesis slack (ns)"),
        right("post-route f_max (MHz)"),
        right("post-route setup slack (ns)"),
        right("hold slack (ns), all / register to register"),
        ("meets the clock", Align::Left),
    ]);
    for c in corners {
        let p = &c.post_route;
        t.row([
            c.library.clone(),
            c.corner.clone(),
            format!("{:.1}", c.synthesis_f_max_mhz),
            format!("{:.3}", c.synthesis_slack_ns),
            format!("{:.1}", p.f_max_mhz),
            format!("{:.3}", p.setup_slack_ns),
            format!("{:.3} / {:.3}", p.hold_slack_ns, p.hold_slack_registers_ns),
            if p.setup_slack_ns >= 0.0 && p.hold_slack_registers_ns >= 0.0 {
                "yes"
            } else {
                "**no**"
            }
            .to_string(),
        ]);
    }
    t.render()
}
