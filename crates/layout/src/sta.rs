//! Post-route timing: OpenSTA on the placed netlist with the routed wires' parasitics
//! (SPEF from qrouter's RC trees, [`crate::spef`]), the clock propagated through the routed
//! clock net (its wire delays are the skew: the flow builds no clock tree), at the clock
//! the configuration needs. Setup (max) and hold (min) are both reported.

use crate::error::{LayoutError, Result};
use crate::tools::tail;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The worst path of one path group (OpenSTA's `Path Group:`: `clk`, the clock-gating
/// checks `**clock_gating_default**`, …) in one check.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GroupSlack {
    /// The path group.
    pub group: String,
    /// Its worst slack (ns).
    pub slack_ns: f64,
    /// The worst path's start and end.
    pub path: (String, String),
}

/// Post-route timing at one clock period. Each figure is the worst over every path group
/// (`report_checks` prints the worst path of each group; the worst of those is checked
/// against OpenSTA's own worst slack, `sta::worst_slack_cmd`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PostRoute {
    /// The clock period asked for (ns): C · f_laser.
    pub period_ns: f64,
    /// Worst setup slack over every path group (ns; negative = violated).
    pub setup_slack_ns: f64,
    /// Worst hold slack over every path group (ns).
    pub hold_slack_ns: f64,
    /// The clock the worst setup path allows (MHz): each group's worst path's minimum
    /// period from its launch and capture edges (`tofprobe_eda::sta::parse_report_at`;
    /// 1 / (period − slack) for a full-cycle path), the longest of them.
    pub f_max_mhz: f64,
    /// The worst setup path's start and end.
    pub setup_path: (String, String),
    /// The worst hold path's start and end.
    pub hold_path: (String, String),
    /// Worst hold slack between registers (ns): the paths inside the macro; the worst
    /// hold path above may start at an input port, which the constraints let change at
    /// the clock's edge at the port while the flops see the clock after its tree.
    pub hold_slack_registers_ns: f64,
    /// The worst register-to-register hold path's start and end (empty in reports
    /// written before it was kept).
    #[serde(default)]
    pub hold_registers_path: (String, String),
    /// Each path group's worst setup path (empty in reports written before they were
    /// kept).
    #[serde(default)]
    pub setup_groups: Vec<GroupSlack>,
    /// Each path group's worst hold path.
    #[serde(default)]
    pub hold_groups: Vec<GroupSlack>,
    /// Each path group's worst register-to-register hold path.
    #[serde(default)]
    pub hold_registers_groups: Vec<GroupSlack>,
    /// Nets annotated from the SPEF.
    pub spef_nets: usize,
}

impl PostRoute {
    /// Setup met on every path and hold met between registers (the paths inside the
    /// macro): what the layout's verdict asks of its timing.
    pub fn met(&self) -> bool {
        self.setup_slack_ns >= 0.0 && self.hold_slack_registers_ns >= 0.0
    }
}

/// The OpenSTA script: each check's `report_checks` (the worst path of every path group;
/// for setup also the worst into a flop and into an output, as the synthesis timing asks,
/// `tofprobe_eda::sta::sta_script`: a latch endpoint's slack can hide the longest
/// full-cycle path of its group) followed by OpenSTA's own worst slack of that check over
/// all groups, in ns to the report's 4 digits, which [`parse`] compares with the worst it
/// read.
pub fn script(liberty: &Path, netlist: &Path, spef: &Path, top: &str, period_ns: f64) -> String {
    let worst = |check: &str| {
        format!(
            "puts \"{WORST} {check} [format %.4f [expr {{[sta::worst_slack_cmd {check}] * 1e9}}]]\"\n"
        )
    };
    format!(
        "read_liberty {lib}\nread_verilog {net}\nlink_design {top}\nread_spef {spef}\n\
         create_clock -name clk -period {period_ns} [get_ports clk]\n\
         set_propagated_clock [all_clocks]\n\
         set_input_delay 0 -clock clk [delete_from_list [all_inputs] [get_ports clk]]\n\
         set_output_delay 0 -clock clk [all_outputs]\n\
         puts \"== setup\"\nreport_checks -path_delay max -digits 4\n\
         report_checks -path_delay max -digits 4 -to [all_registers -edge_triggered -data_pins]\n\
         report_checks -path_delay max -digits 4 -to [all_outputs]\n{max}\
         puts \"== hold\"\nreport_checks -path_delay min -digits 4\n{min}\
         puts \"== hold-registers\"\n\
         report_checks -path_delay min -digits 4 -from [all_registers -clock_pins] -to [all_registers -data_pins]\nexit\n",
        lib = liberty.display(),
        net = netlist.display(),
        spef = spef.display(),
        max = worst("max"),
        min = worst("min"),
    )
}

/// The tag of OpenSTA's own worst slack lines in the log.
const WORST: &str = "TOFPROBE-WORST";

/// Runs OpenSTA in `dir` (script and log kept there, named after `corner`).
#[allow(clippy::too_many_arguments)]
pub fn run(
    liberty: &Path,
    netlist: &Path,
    spef: &Path,
    top: &str,
    period_ns: f64,
    spef_nets: usize,
    dir: &Path,
    corner: &str,
) -> Result<PostRoute> {
    let path = dir.join(format!("post_route_sta-{corner}.tcl"));
    std::fs::write(&path, script(liberty, netlist, spef, top, period_ns))
        .map_err(|e| LayoutError::io("writing", &path, e))?;
    let (status, text) = tofprobe_eda::sta::run_script(&path)?;
    let log = dir.join(format!("post_route_sta-{corner}.log"));
    std::fs::write(&log, &text).map_err(|e| LayoutError::io("writing", &log, e))?;
    // A SPEF the reader stumbles on would leave wires unannotated: an error, not a warning.
    let spef_trouble = text
        .lines()
        .any(|l| l.contains(".spef") && (l.contains("syntax error") || l.contains("not found")));
    if !status.success() || text.contains("Error:") || spef_trouble {
        return Err(LayoutError::ToolFailed {
            step: "post-route timing",
            tool: "sta",
            status: status.code().map_or("killed".into(), |c| c.to_string()),
            log,
            tail: tail(&text, 12),
        });
    }
    parse(&text, period_ns, spef_nets, &log)
}

/// The worst path of each path group in one check's `report_checks` text (in the order
/// OpenSTA printed the groups).
pub fn group_paths(text: &str) -> Vec<GroupSlack> {
    let mut out: Vec<GroupSlack> = Vec::new();
    for block in text.split("Startpoint:").skip(1) {
        let field = |key: &str| {
            format!("Startpoint:{block}")
                .lines()
                .find_map(|l| l.trim().strip_prefix(key).map(str::to_string))
                .map(|v| v.split(" (").next().unwrap_or(&v).trim().to_string())
        };
        let slack = block
            .lines()
            .find(|l| l.contains("slack ("))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|v| v.parse::<f64>().ok());
        let (Some(slack), Some(start), Some(end)) =
            (slack, field("Startpoint:"), field("Endpoint:"))
        else {
            continue;
        };
        let group = field("Path Group:").unwrap_or_default();
        match out.iter_mut().find(|g| g.group == group) {
            Some(g) if slack < g.slack_ns => {
                g.slack_ns = slack;
                g.path = (start, end);
            }
            Some(_) => {}
            None => out.push(GroupSlack {
                group,
                slack_ns: slack,
                path: (start, end),
            }),
        }
    }
    out
}

/// The worst of `groups` (the first of equal slacks).
fn worst(groups: &[GroupSlack]) -> Option<&GroupSlack> {
    groups
        .iter()
        .reduce(|a, b| if b.slack_ns < a.slack_ns { b } else { a })
}

/// OpenSTA's own worst slack of `check` (`max` or `min`) in the log.
fn opensta_worst(text: &str, check: &str) -> Option<f64> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix(WORST)?.trim().strip_prefix(check))
        .and_then(|v| v.trim().parse::<f64>().ok())
}

/// Parses the setup and hold reports: the worst path of every group of each check, the
/// worst of all checked against OpenSTA's own worst slack (a reader that kept one group
/// only — the first, say the clock-gating checks — would disagree with it).
pub fn parse(text: &str, period_ns: f64, spef_nets: usize, log: &Path) -> Result<PostRoute> {
    let bad = |what: &str| LayoutError::Parse {
        tool: "sta",
        what: what.into(),
        path: log.to_path_buf(),
    };
    let (_, rest) = text
        .split_once("== setup")
        .ok_or_else(|| bad("`== setup`"))?;
    let (setup, rest) = rest.split_once("== hold").ok_or_else(|| bad("`== hold`"))?;
    let (hold, hold_regs) = rest
        .split_once("== hold-registers")
        .ok_or_else(|| bad("`== hold-registers`"))?;
    let checked = |section: &str, what: &str, check: Option<&str>| -> Result<Vec<GroupSlack>> {
        let groups = group_paths(section);
        let w = worst(&groups).ok_or_else(|| bad(&format!("a {what} path (`Startpoint:`)")))?;
        if let Some(check) = check {
            let sta = opensta_worst(section, check)
                .ok_or_else(|| bad(&format!("OpenSTA's worst {what} slack (`{WORST} {check}`)")))?;
            // Both are OpenSTA's numbers printed to 4 digits: equal up to that rounding.
            if (sta - w.slack_ns).abs() > 1.5e-4 {
                return Err(bad(&format!(
                    "the worst {what} slack of the path groups ({:.4} ns, group `{}`) equal to OpenSTA's own worst ({sta:.4} ns)",
                    w.slack_ns, w.group
                )));
            }
        }
        Ok(groups)
    };
    let setup_groups = checked(setup, "setup", Some("max"))?;
    let hold_groups = checked(hold, "hold", Some("min"))?;
    let hold_registers_groups = checked(hold_regs, "register-to-register hold", None)?;
    let (s, h, r) = (
        worst(&setup_groups).cloned(),
        worst(&hold_groups).cloned(),
        worst(&hold_registers_groups).cloned(),
    );
    let (Some(s), Some(h), Some(r)) = (s, h, r) else {
        return Err(bad("a path of every check"));
    };
    // f_max: the longest minimum period of the groups' worst setup paths (a half-cycle
    // clock-gating check scales with its window), by the synthesis timing's own reader.
    let critical = tofprobe_eda::sta::parse_report_at(setup, period_ns)
        .map_err(|_| bad("a setup path's arrival and required times"))?;
    if !(critical.critical_path_ns.is_finite() && critical.critical_path_ns > 0.0) {
        return Err(bad("a positive minimum period"));
    }
    Ok(PostRoute {
        period_ns,
        setup_slack_ns: s.slack_ns,
        hold_slack_ns: h.slack_ns,
        f_max_mhz: 1e3 / critical.critical_path_ns,
        setup_path: s.path,
        hold_path: h.path,
        hold_slack_registers_ns: r.slack_ns,
        hold_registers_path: r.path,
        setup_groups,
        hold_groups,
        hold_registers_groups,
        spef_nets,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// OpenSTA 2.0.17's output of [`script`] (less `read_spef`) on the 4-bin latch pixel
    /// synthesised for osu018 at 6.25 ns: each check prints the worst path of each path
    /// group, the clock-gating checks first. Its hold: the gating group +6.5100 ns, the
    /// `clk` group −1.6524 ns (a flop into a latch whose gated clock arrives 1.72 ns late).
    const LATCH4: &str = include_str!("../testdata/sta-latch4-osu018.log");

    #[test]
    fn every_path_group_counts_and_the_worst_is_opensta_s_own() {
        let t = parse(LATCH4, 6.25, 0, Path::new("l")).unwrap();
        // The first group's hold was +6.51 ns: the reader must not stop there.
        assert_eq!(t.hold_groups[0].group, "**clock_gating_default**");
        assert_eq!(t.hold_groups[0].slack_ns, 6.51);
        assert_eq!(t.hold_slack_ns, -1.6524, "{t:?}");
        assert_eq!(
            t.hold_path,
            ("wd_0_DFFPOSX1_Q".into(), "y[0]_LATCH_Q".into())
        );
        assert_eq!(t.hold_slack_registers_ns, -1.6524);
        assert_eq!(t.hold_registers_path.1, "y[0]_LATCH_Q");
        assert!(!t.met(), "a hold violation between registers is a miss");
        // Setup: gating +2.8464, clk (three reports of it) worst +0.2510 — OpenSTA's own.
        assert_eq!(t.setup_groups.len(), 2, "{:?}", t.setup_groups);
        assert_eq!(t.setup_slack_ns, 0.251);
        // f_max: the longest minimum period of the paths. The latch → flop path is
        // launched at the falling edge (3.125 ns) and captured at 6.25 ns: its 3.125 ns
        // window with 0.6037 ns slack needs 2 × (3.125 − 0.6037) = 5.0426 ns (the gating
        // check's half cycle needs 2 × (3.125 − 2.8464) = 0.557 ns, the output 0.5521 ns).
        assert!((t.f_max_mhz - 1e3 / 5.0426).abs() < 1e-6, "{}", t.f_max_mhz);
    }

    #[test]
    fn a_reader_disagreeing_with_opensta_s_worst_is_an_error() {
        // Drop the violating `clk` group from the hold report (a reader that saw the first
        // group only): OpenSTA's own worst (−1.6524) no longer matches, and that is refused.
        let (head, rest) = LATCH4.split_once("== hold\n").unwrap();
        let (hold, regs) = rest.split_once("== hold-registers").unwrap();
        let first_group = &hold[..hold.find("Startpoint: wd_0").unwrap()];
        let worst_line = &hold[hold.find("TOFPROBE-WORST").unwrap()..];
        let cut = format!("{head}== hold\n{first_group}{worst_line}== hold-registers{regs}");
        let e = parse(&cut, 6.25, 0, Path::new("l"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("6.5100") && e.contains("-1.6524") && e.contains("clock_gating"),
            "{e}"
        );
        // No paths at all: named.
        let e = parse(
            "== setup\n== hold\n== hold-registers\n",
            6.25,
            0,
            Path::new("l"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("a setup path"), "{e}");
    }

    #[test]
    fn one_group_reads_as_before() {
        let text = "== setup\nStartpoint: a (rising edge-triggered flip-flop clocked by clk)\n\
                    Endpoint: b (rising edge-triggered flip-flop clocked by clk)\nPath Group: clk\n\
                    \x20  0.0000    0.0000   clock clk (rise edge)\n\
                    \x20            1.9000   data arrival time\n\
                    \x20  6.2500    6.2500   clock clk (rise edge)\n\
                    \x20  2.2500   slack (MET)\nTOFPROBE-WORST max 2.2500\n== hold\nStartpoint: c (rising)\nEndpoint: d (rising)\n\
                    \x20 -0.0300   slack (VIOLATED)\nTOFPROBE-WORST min -0.0300\n== hold-registers\nStartpoint: e (rising)\nEndpoint: f (rising)\n\
                    \x20  0.1200   slack (MET)\n";
        let t = parse(text, 6.25, 3, Path::new("l")).unwrap();
        assert_eq!(t.setup_slack_ns, 2.25);
        assert_eq!(t.hold_slack_ns, -0.03);
        // 1 / (6.25 − 2.25) ns = 250 MHz.
        assert!((t.f_max_mhz - 250.0).abs() < 1e-9, "{}", t.f_max_mhz);
        assert_eq!(t.setup_path, ("a".into(), "b".into()));
        assert_eq!(t.hold_path, ("c".into(), "d".into()));
        assert_eq!(t.hold_slack_registers_ns, 0.12);
        assert!(t.met(), "all-paths hold is the input's, registers meet");
    }
}
