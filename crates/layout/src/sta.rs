//! Post-route timing: OpenSTA on the placed netlist with the routed wires' parasitics
//! (SPEF from qrouter's RC trees, [`crate::spef`]), the clock propagated through the routed
//! clock net (its wire delays are the skew: the flow builds no clock tree), at the clock
//! the configuration needs. Setup (max) and hold (min) are both reported.

use crate::error::{LayoutError, Result};
use crate::tools::{Tool, tail};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::process::Command;

/// Post-route timing at one clock period.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PostRoute {
    /// The clock period asked for (ns): C · f_laser.
    pub period_ns: f64,
    /// Worst setup slack (ns; negative = violated).
    pub setup_slack_ns: f64,
    /// Worst hold slack (ns).
    pub hold_slack_ns: f64,
    /// 1 / (period − setup slack) (MHz): the clock the worst setup path allows.
    pub f_max_mhz: f64,
    /// The worst setup path's start and end.
    pub setup_path: (String, String),
    /// The worst hold path's start and end.
    pub hold_path: (String, String),
    /// Worst hold slack between registers (ns): the paths inside the macro; the worst
    /// hold path above may start at an input port, which the constraints let change at
    /// the clock's edge at the port while the flops see the clock after its tree.
    pub hold_slack_registers_ns: f64,
    /// Nets annotated from the SPEF.
    pub spef_nets: usize,
}

/// The OpenSTA script.
pub fn script(liberty: &Path, netlist: &Path, spef: &Path, top: &str, period_ns: f64) -> String {
    format!(
        "read_liberty {lib}\nread_verilog {net}\nlink_design {top}\nread_spef {spef}\n\
         create_clock -name clk -period {period_ns} [get_ports clk]\n\
         set_propagated_clock [all_clocks]\n\
         set_input_delay 0 -clock clk [delete_from_list [all_inputs] [get_ports clk]]\n\
         set_output_delay 0 -clock clk [all_outputs]\n\
         puts \"== setup\"\nreport_checks -path_delay max -digits 4\n\
         puts \"== hold\"\nreport_checks -path_delay min -digits 4\n\
         puts \"== hold-registers\"\n\
         report_checks -path_delay min -digits 4 -from [all_registers -clock_pins] -to [all_registers -data_pins]\nexit\n",
        lib = liberty.display(),
        net = netlist.display(),
        spef = spef.display(),
    )
}

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
    let sta = Tool::Sta.locate()?;
    let path = dir.join(format!("post_route_sta-{corner}.tcl"));
    std::fs::write(&path, script(liberty, netlist, spef, top, period_ns))
        .map_err(|e| LayoutError::io("writing", &path, e))?;
    let out = Command::new(&sta)
        .arg("-no_init")
        .arg("-exit")
        .arg(&path)
        .output()
        .map_err(|e| LayoutError::io("running", &sta, e))?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let log = dir.join(format!("post_route_sta-{corner}.log"));
    std::fs::write(&log, &text).map_err(|e| LayoutError::io("writing", &log, e))?;
    // A SPEF the reader stumbles on would leave wires unannotated: an error, not a warning.
    let spef_trouble = text
        .lines()
        .any(|l| l.contains(".spef") && (l.contains("syntax error") || l.contains("not found")));
    if !out.status.success() || text.contains("Error:") || spef_trouble {
        return Err(LayoutError::ToolFailed {
            step: "post-route timing",
            tool: "sta",
            status: out.status.code().map_or("killed".into(), |c| c.to_string()),
            log,
            tail: tail(&text, 12),
        });
    }
    parse(&text, period_ns, spef_nets, &log)
}

/// Parses the setup and hold reports.
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
    let path = |s: &str, what: &str| -> Result<(f64, (String, String))> {
        let field = |key: &str| {
            s.lines()
                .find_map(|l| l.trim().strip_prefix(key))
                .map(|v| v.split(" (").next().unwrap_or(v).trim().to_string())
        };
        let slack = s
            .lines()
            .find(|l| l.contains("slack ("))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| bad(&format!("the {what} slack")))?;
        let start = field("Startpoint:").ok_or_else(|| bad(&format!("the {what} startpoint")))?;
        let end = field("Endpoint:").ok_or_else(|| bad(&format!("the {what} endpoint")))?;
        Ok((slack, (start, end)))
    };
    let (setup_slack, setup_path) = path(setup, "setup")?;
    let (hold_slack, hold_path) = path(hold, "hold")?;
    let (hold_regs_slack, _) = path(hold_regs, "register-to-register hold")?;
    let need = period_ns - setup_slack;
    if !(need.is_finite() && need > 0.0) {
        return Err(bad("a positive period − setup slack"));
    }
    Ok(PostRoute {
        period_ns,
        setup_slack_ns: setup_slack,
        hold_slack_ns: hold_slack,
        f_max_mhz: 1e3 / need,
        setup_path,
        hold_path,
        hold_slack_registers_ns: hold_regs_slack,
        spef_nets,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setup_and_hold_slacks_give_f_max() {
        let text = "== setup\nStartpoint: a (rising edge-triggered flip-flop clocked by clk)\n\
                    Endpoint: b (rising edge-triggered flip-flop clocked by clk)\n\
                    \x20  2.2500   slack (MET)\n== hold\nStartpoint: c (rising)\nEndpoint: d (rising)\n\
                    \x20 -0.0300   slack (VIOLATED)\n== hold-registers\nStartpoint: e (rising)\nEndpoint: f (rising)\n\
                    \x20  0.1200   slack (MET)\n";
        let t = parse(text, 6.25, 3, Path::new("l")).unwrap();
        assert_eq!(t.setup_slack_ns, 2.25);
        assert_eq!(t.hold_slack_ns, -0.03);
        // 1 / (6.25 − 2.25) ns = 250 MHz.
        assert!((t.f_max_mhz - 250.0).abs() < 1e-9);
        assert_eq!(t.setup_path, ("a".into(), "b".into()));
        assert_eq!(t.hold_path, ("c".into(), "d".into()));
        assert_eq!(t.hold_slack_registers_ns, 0.12);
        assert!(parse("== setup\n== hold\n", 6.25, 0, Path::new("l")).is_err());
    }
}
