//! The OpenSTA driver: the critical path of the mapped netlist and the maximum clock.
//!
//! Constraints, stated in the report: one clock on `clk` with an ideal network (no skew,
//! no clock tree), inputs arriving at the clock edge and outputs required at the next
//! one, no wire load model and no output load (the liberty's defaults). This is the
//! register-to-register logic delay of the pixel in isolation: an optimistic f_max. With a
//! clock-gated register file the clock propagates through the gates (ideal: no insertion
//! delay), the integrated gate's enable is checked like a flop's D, and a latch-and-AND
//! gate adds OpenSTA's clock-gating checks on the AND, launched half a cycle later — or,
//! for a gate on the inverted clock (a latch register file's), captured half a cycle
//! earlier (see [`parse_report`]).

use crate::error::{EdaError, Result};
use crate::fsutil::write_atomic;
use crate::tools::{Tool, tail};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::process::Command;

/// The clock period OpenSTA is asked to meet (ns). Large, so the slack is always positive
/// and the critical delay is `period − slack`; the value does not change the path.
const PROBE_PERIOD_NS: f64 = 1000.0;

/// OpenSTA's view of the critical path.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Timing {
    /// Minimum clock period = data arrival + setup (ns).
    pub critical_path_ns: f64,
    /// 1 / critical_path (MHz).
    pub f_max_mhz: f64,
    /// Start point (an instance named after the signal it drives).
    pub startpoint: String,
    /// End point.
    pub endpoint: String,
    /// Cells on the path (logic depth).
    pub path_cells: u32,
}

/// The OpenSTA script timing `netlist` (module `top`) against `liberty`: the worst path of
/// each path group, then the worst into a flop and into an output (a latch endpoint's slack
/// is counted from its opening edge half a cycle earlier, so it can hide the worst
/// full-cycle path of its group); [`parse_report`] keeps the one needing the longest period.
pub fn sta_script(liberty: &Path, netlist: &Path, top: &str, clock: &str) -> String {
    format!(
        "read_liberty {lib}\n\
         read_verilog {net}\n\
         link_design {top}\n\
         create_clock -name clk -period {PROBE_PERIOD_NS} [get_ports {clock}]\n\
         set_input_delay 0 -clock clk [delete_from_list [all_inputs] [get_ports {clock}]]\n\
         set_output_delay 0 -clock clk [all_outputs]\n\
         report_checks -path_delay max -digits 4\n\
         report_checks -path_delay max -digits 4 -to [all_registers -edge_triggered -data_pins]\n\
         report_checks -path_delay max -digits 4 -to [all_outputs]\n\
         exit\n",
        lib = liberty.display(),
        net = netlist.display(),
    )
}

/// Runs OpenSTA on a mapped netlist. The liberty must carry timing.
pub fn time_netlist(
    liberty: &Path,
    netlist: &Path,
    top: &str,
    clock: &str,
    work: &Path,
) -> Result<Timing> {
    // One script per liberty: the corners of one netlist are timed in the same directory.
    let stem = liberty
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let script = work.join(format!("sta-{stem}.tcl"));
    write_atomic(&script, sta_script(liberty, netlist, top, clock).as_bytes())?;
    let (status, text) = run_script(&script)?;
    if !status.success() {
        return Err(EdaError::ToolFailed {
            tool: "sta",
            status: status
                .code()
                .map_or("killed by a signal".into(), |c| c.to_string()),
            log_tail: tail(&text, 15),
        });
    }
    parse_report(&text)
}

/// OpenSTA (the one located, `$TOFPROBE_STA` or PATH) on the Tcl file `script`
/// (`sta -no_init -exit`): its exit status and its log, standard output then error.
pub fn run_script(script: &Path) -> Result<(std::process::ExitStatus, String)> {
    let sta = Tool::Sta.locate()?;
    let out = Command::new(&sta)
        .arg("-no_init")
        .arg("-exit")
        .arg(script)
        .output()
        .map_err(|e| EdaError::io("running", &sta, e))?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    Ok((out.status, text))
}

/// Parses `report_checks` output: the path of each path group (`clk`, and the clock gating
/// checks of a latch-and-AND clock gate), the one that needs the longest clock period.
pub fn parse_report(text: &str) -> Result<Timing> {
    parse_report_at(text, PROBE_PERIOD_NS)
}

/// [`parse_report`] of a report at the clock period `period_ns` (the post-route timing's
/// setup paths at the configuration's clock, `tofprobe_layout::sta`): each path's minimum
/// period scaled from its launch and capture edges within `period_ns`.
pub fn parse_report_at(text: &str, period_ns: f64) -> Result<Timing> {
    let err = |what| EdaError::Parse {
        tool: "sta",
        what,
        tail: tail(text, 20),
    };
    let mut best: Option<Timing> = None;
    for block in text.split("Startpoint:").skip(1) {
        let t = parse_path(&format!("Startpoint:{block}"), period_ns)?;
        if best
            .as_ref()
            .is_none_or(|b| t.critical_path_ns > b.critical_path_ns)
        {
            best = Some(t);
        }
    }
    best.ok_or_else(|| err("`Startpoint:` (no constrained path: is the clock port right?)"))
}

/// One path of `report_checks`. Its minimum clock period scales with where in the cycle it
/// is launched and captured: a path launched at time L of the probe period P (a clock
/// gate's latch opens on the falling edge, L = P/2) and captured at C (P, or P/2 for the
/// gating check of a gate on the inverted clock) with slack s needs (C − L − s)·P/(C − L);
/// for a flop-to-flop path (L = 0, C = P) that is P − s = arrival + setup.
fn parse_path(text: &str, period_ns: f64) -> Result<Timing> {
    let err = |what| EdaError::Parse {
        tool: "sta",
        what,
        tail: tail(text, 20),
    };
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.trim().strip_prefix(key))
            .map(|v| v.split(" (").next().unwrap_or(v).trim().to_string())
    };
    let startpoint = field("Startpoint:")
        .ok_or_else(|| err("`Startpoint:` (no constrained path: is the clock port right?)"))?;
    let endpoint = field("Endpoint:").ok_or_else(|| err("`Endpoint:`"))?;
    let slack = text
        .lines()
        .find(|l| l.contains("slack ("))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|v| v.parse::<f64>().ok())
        .ok_or_else(|| err("the slack line"))?;
    let arrival_idx = text
        .find("data arrival time")
        .ok_or_else(|| err("`data arrival time`"))?;
    // The launching edge: the first `clock NAME (rise|fall edge)` line, its time column.
    let launch = text[..arrival_idx]
        .lines()
        .find(|l| l.contains(" clock ") && l.trim_end().ends_with("edge)"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|l| (0.0..period_ns).contains(l))
        .unwrap_or(0.0);
    // Cells on the path: lines "delay time ^/v inst/PIN (CELL)" with an output pin,
    // between the clock's launch and the arrival, excluding the launching flop's CLK.
    let path_cells = text[..arrival_idx]
        .lines()
        .filter(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            t.len() == 5 && (t[2] == "^" || t[2] == "v") && t[4].starts_with('(')
        })
        .count()
        .saturating_sub(2) as u32;
    // The capturing edge: the first clock edge line after the arrival. A check is usually
    // required at the period's end (P), but a latch-and-AND gate on the inverted clock
    // (a latch register file's gates) has its gating check launched at the rising edge,
    // when its enable latch opens, and required at the falling edge (P/2), when the AND's
    // clock input rises: that path has half a period, not P.
    let capture = text[arrival_idx..]
        .lines()
        .find(|l| l.contains(" clock ") && l.trim_end().ends_with("edge)"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|c| *c > launch && *c <= period_ns)
        .unwrap_or(period_ns);
    let open = period_ns - launch;
    // A latch endpoint (a latch-and-AND clock gate's enable latch, open while clk is low):
    // OpenSTA requires the data at the opening edge and lets it borrow up to the closing
    // edge, the next rising edge of clk. So its constraint is a full cycle: the arrival
    // (without the latch's setup and D→Q, a few tenths of a ns: stated in the docs).
    let latch_endpoint = text.contains("time borrowed from endpoint");
    let arrival = text[..arrival_idx]
        .lines()
        .last()
        .and_then(|l| l.split_whitespace().next())
        .and_then(|v| v.parse::<f64>().ok());
    let window = capture - launch;
    let critical = match (latch_endpoint, arrival) {
        (true, Some(a)) => (a - launch) * period_ns / open,
        _ => (window - slack) * period_ns / window,
    };
    // The report prints 4 digits; round away the binary noise of 1000 − slack.
    let critical = (critical * 1e4).round() / 1e4;
    if !(critical.is_finite() && critical > 0.0) {
        return Err(err("a positive critical path (period − slack)"));
    }
    Ok(Timing {
        critical_path_ns: critical,
        f_max_mhz: 1e3 / critical,
        startpoint,
        endpoint,
        path_cells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPORT: &str =
        "Startpoint: slot_DFFPOSX1_Q_1 (rising edge-triggered flip-flop clocked by clk)
Endpoint: Y[7]_DFFPOSX1_Q (rising edge-triggered flip-flop clocked by clk)
Path Group: clk
    Delay      Time   Description
   0.0000    0.0000   clock clk (rise edge)
   0.0000    0.0000 ^ slot_DFFPOSX1_Q_1/CLK (DFFPOSX1)
   0.1958    0.1958 ^ slot_DFFPOSX1_Q_1/Q (DFFPOSX1)
   0.6116    0.8074 ^ a/Y (AND2X1)
   0.1598    0.9672 v b/Y (AOI22X1)
   0.0000    0.9672 v Y[7]_DFFPOSX1_Q/D (DFFPOSX1)
             0.9672   data arrival time
  -0.1683  999.8317   library setup time
          998.8645   slack (MET)
";

    #[test]
    fn critical_path_is_period_minus_slack() {
        let t = parse_report(REPORT).unwrap();
        // period − slack must equal arrival + setup = 0.9672 + 0.1683 (4-digit rounding).
        assert!(
            (t.critical_path_ns - 1.1355).abs() < 1e-9,
            "{}",
            t.critical_path_ns
        );
        assert!((t.f_max_mhz - 1e3 / 1.1355).abs() < 1e-6);
        assert_eq!(t.startpoint, "slot_DFFPOSX1_Q_1");
        assert_eq!(t.endpoint, "Y[7]_DFFPOSX1_Q");
        assert_eq!(t.path_cells, 3, "Q of the launching flop, AND2, AOI22");
    }

    /// A latch-and-AND clock gate's gating check (osu018, OpenSTA 2.0.17): launched when the
    /// latch opens on the falling edge, required at the next rising edge.
    const GATING: &str =
        "Startpoint: cg_0.enable_latch (positive level-sensitive latch clocked by clk')
Endpoint: cg_0.clk_and (rising clock gating-check end-point clocked by clk)
Path Group: **clock_gating_default**
    Delay      Time   Description
 500.0000  500.0000   clock clk' (rise edge)
   0.0000  500.0000   clock network delay (ideal)
   0.0000  500.0000 ^ cg_0.enable_latch/CLK (LATCH)
   0.1705  500.1705 v cg_0.enable_latch/Q (LATCH)
   0.0000  500.1705 v cg_0.clk_and/B (AND2X1)
           500.1705   data arrival time
1000.0000 1000.0000   clock clk (rise edge)
   0.0000 1000.0000   clock gating setup time
           499.8295   slack (MET)
";

    #[test]
    fn half_cycle_gating_check_scales_with_its_launch_edge() {
        // Alone: 0.1705 ns in half a period needs a 0.341 ns period, not 1000 − 499.8295.
        let t = parse_report(GATING).unwrap();
        assert!(
            (t.critical_path_ns - 0.341).abs() < 1e-9,
            "{}",
            t.critical_path_ns
        );
        assert_eq!(t.endpoint, "cg_0.clk_and");
        // With the flop-to-flop path of another group, the longer period wins, in any order.
        for text in [format!("{GATING}\n{REPORT}"), format!("{REPORT}\n{GATING}")] {
            let t = parse_report(&text).unwrap();
            assert!(
                (t.critical_path_ns - 1.1355).abs() < 1e-9,
                "{}",
                t.critical_path_ns
            );
            assert_eq!(t.endpoint, "Y[7]_DFFPOSX1_Q");
        }
        // A gating check with 0.9 ns in its half period (slack 499.1) needs 1.8 ns: it wins.
        let slow = GATING.replace("499.8295   slack", "499.1000   slack");
        let t = parse_report(&format!("{REPORT}\n{slow}")).unwrap();
        assert!(
            (t.critical_path_ns - 1.8).abs() < 1e-9,
            "{}",
            t.critical_path_ns
        );
    }

    /// The gating check of a latch register file's gate on osu018 (OpenSTA 2.0.17): the gate
    /// is on the inverted clock, so its enable latch opens at the rising edge and the AND's
    /// clock input rises at the falling edge: required at P/2 (it read as a 500 ns path).
    #[test]
    fn inverted_clock_gating_check_is_captured_half_a_period_later() {
        let inverted =
            "Startpoint: cg_0.enable_latch (positive level-sensitive latch clocked by clk)
Endpoint: cg_0.clk_and (rising clock gating-check end-point clocked by clk')
Path Group: **clock_gating_default**
    Delay      Time   Description
   0.0000    0.0000   clock clk (rise edge)
   0.0000    0.0000   clock network delay (ideal)
   0.1590    0.1590   time given to startpoint
   0.0000    0.1590 v cg_0.enable_latch/D (LATCH)
   0.1712    0.3302 v cg_0.enable_latch/Q (LATCH)
   0.0000    0.3302 v cg_0.clk_and/B (AND2X1)
             0.3302   data arrival time
 500.0000  500.0000   clock clk' (rise edge)
   0.0000  500.0000   clock gating setup time
           500.0000   data required time
           499.6698   slack (MET)
";
        // 0.3302 ns in half a period needs 0.6604 ns (= 2 × (500 − 499.6698)), not 500.33.
        let t = parse_report(inverted).unwrap();
        assert!(
            (t.critical_path_ns - 0.6604).abs() < 1e-9,
            "{}",
            t.critical_path_ns
        );
        assert_eq!(t.endpoint, "cg_0.clk_and");
    }

    #[test]
    fn latch_endpoint_is_timed_to_the_closing_edge() {
        // Required at the latch's opening edge (half a period), borrowing allowed up to the
        // next rising edge: the constraint is the arrival in a full cycle, not 1000 − slack.
        let latch =
            "Startpoint: rd_ptr_DFFPOSX1_Q_4 (rising edge-triggered flip-flop clocked by clk)
Endpoint: cg_10.enable_latch (positive level-sensitive latch clocked by clk')
Path Group: clk
    Delay      Time   Description
   0.0000    0.0000   clock clk (rise edge)
   0.0000    0.0000 ^ rd_ptr_DFFPOSX1_Q_4/CLK (DFFPOSX1)
   0.1598    0.1598 v rd_ptr_DFFPOSX1_Q_4/Q (DFFPOSX1)
   1.0809    1.2407 v cg_10.en_NAND2X1_Y/Y (NAND2X1)
   0.0000    1.2407 v cg_10.enable_latch/D (LATCH)
             1.2407   data arrival time
 500.0000  500.0000   clock clk' (rise edge)
   0.0000  500.0000   time borrowed from endpoint
           500.0000   data required time
           498.7593   slack (MET)
";
        let t = parse_report(latch).unwrap();
        assert!(
            (t.critical_path_ns - 1.2407).abs() < 1e-9,
            "{}",
            t.critical_path_ns
        );
        assert_eq!(t.endpoint, "cg_10.enable_latch");
    }

    #[test]
    fn empty_report_is_a_clear_error() {
        let msg = parse_report("No paths found.").unwrap_err().to_string();
        assert!(
            msg.contains("Startpoint") && msg.contains("No paths found"),
            "{msg}"
        );
    }
}
