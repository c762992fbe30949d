//! qrouter's RC trees as SPEF, so OpenSTA times the routed pixel with its wires.
//!
//! qrouter (`-d FILE`, as qflow's router step runs it) writes one line per net:
//! `NET 1 DRIVER NSINKS TREE`, where `DRIVER` and each sink are `INSTANCE/PIN` (or `PIN/PORT`
//! for a port) and `TREE` is a nested node `( R C ITEM , ITEM … )`: the wire from the
//! parent point to this point has resistance R (Ω), the point carries the wire's
//! capacitance C (pF), and each ITEM is a sink pin at this point or a child node. This
//! module parses that grammar and writes each net as a SPEF `*D_NET`: the driver, one
//! internal node per point (`NET:k`, or the sink pin itself when one sink sits there; a
//! second sink at one point is joined by a 1 mΩ resistor), its capacitance and the
//! resistors between parent and child points. Units: ns, pF, Ω.

use crate::error::{LayoutError, Result};
use std::fmt::Write as _;
use std::path::Path;

/// One point of a routed net.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Resistance of the wire from the parent point (Ω).
    pub r_ohm: f64,
    /// Capacitance at this point (pF).
    pub c_pf: f64,
    /// Sink pins at this point (`INST/PIN`, `PIN/PORT`).
    pub sinks: Vec<String>,
    /// Child points (indices into [`Net::points`]).
    pub children: Vec<usize>,
}

/// One routed net: its driver and the tree of points (root first).
#[derive(Debug, Clone, PartialEq)]
pub struct Net {
    /// Net name.
    pub name: String,
    /// Driver pin.
    pub driver: String,
    /// Sinks qrouter counted.
    pub sinks: usize,
    /// The points, the root at index 0 (empty for a net without wire).
    pub points: Vec<Point>,
}

impl Net {
    /// Total wire capacitance (pF).
    pub fn total_cap_pf(&self) -> f64 {
        self.points.iter().map(|p| p.c_pf).sum()
    }

    /// The sinks found in the tree.
    pub fn tree_sinks(&self) -> usize {
        self.points.iter().map(|p| p.sinks.len()).sum()
    }
}

/// Parses a qrouter RC file (`path` only names the file in errors).
pub fn parse_rc(text: &str, path: &Path) -> Result<Vec<Net>> {
    let mut nets = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let bad = |what: &str| LayoutError::Parse {
            tool: "qrouter",
            what: format!("{what} on line {} of the RC file", n + 1),
            path: path.to_path_buf(),
        };
        let toks: Vec<&str> = line.split_whitespace().collect();
        if toks.len() < 4 || toks[1] != "1" {
            return Err(bad("`NET 1 DRIVER NSINKS TREE`"));
        }
        let sinks: usize = toks[3].parse().map_err(|_| bad("a sink count"))?;
        let mut points = Vec::new();
        let mut pos = 4;
        if pos < toks.len() {
            parse_point(&toks, &mut pos, &mut points)
                .ok_or_else(|| bad("a well-formed RC tree"))?;
            if pos != toks.len() {
                return Err(bad("the end of the RC tree"));
            }
        }
        nets.push(Net {
            name: toks[0].to_string(),
            driver: toks[2].to_string(),
            sinks,
            points,
        });
    }
    Ok(nets)
}

/// Parses `( R C ITEM , … )` at `toks[*pos]`, appending the point and its subtree; returns
/// the point's index.
fn parse_point(toks: &[&str], pos: &mut usize, points: &mut Vec<Point>) -> Option<usize> {
    if toks.get(*pos) != Some(&"(") {
        return None;
    }
    let r: f64 = toks.get(*pos + 1)?.parse().ok()?;
    let c: f64 = toks.get(*pos + 2)?.parse().ok()?;
    if !(r.is_finite() && c.is_finite() && r >= 0.0 && c >= 0.0) {
        return None;
    }
    *pos += 3;
    let me = points.len();
    points.push(Point {
        r_ohm: r,
        c_pf: c,
        sinks: vec![],
        children: vec![],
    });
    loop {
        match *toks.get(*pos)? {
            ")" => {
                *pos += 1;
                return Some(me);
            }
            "," => *pos += 1,
            "(" => {
                let child = parse_point(toks, pos, points)?;
                points[me].children.push(child);
            }
            // qrouter writes ERROR where its walk of a route found no pin: a broken route
            // (an open net, which LVS reports); the wire up to there is kept, no pin named.
            "ERROR" => *pos += 1,
            name => {
                points[me].sinks.push(name.to_string());
                *pos += 1;
            }
        }
    }
}

/// A name as SPEF writes it: every character other than a letter, a digit, `_` and the
/// bus delimiters `[` `]` escaped with a backslash (qflow's clock buffers drive `clk_hier0_bF$buf6`).
pub fn escape(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        if !(c.is_ascii_alphanumeric() || matches!(c, '_' | '[' | ']')) {
            s.push('\\');
        }
        s.push(c);
    }
    s
}

/// A pin of the RC file as SPEF names it: `PIN/PORT` → `PORT`, `INST/PIN` → `INST:PIN`.
fn spef_pin(pin: &str) -> (bool, String) {
    match pin.split_once('/') {
        Some(("PIN", port)) => (true, escape(port)),
        Some((inst, p)) => (false, format!("{}:{}", escape(inst), escape(p))),
        None => (true, escape(pin)),
    }
}

/// The vector ports of a netlist written by qflow's blif2Verilog (`input [6:0] tdc;`).
/// blif2Verilog keeps a routed net's name `base[i]` only when `base` is such a port;
/// every other name has its brackets and other specials turned into `_` (`y[3]_D` is
/// `y_3__D`, the clock buffers' `clk_bF$buf2` is `clk_bF_buf2` in the netlist), and
/// [`netlist_name`] does the same so that the SPEF's nets are found.
pub fn vector_ports(verilog: &str) -> std::collections::BTreeSet<String> {
    verilog
        .lines()
        .filter_map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            match t.as_slice() {
                ["input" | "output" | "inout", range, name, ..] if range.starts_with('[') => {
                    Some(name.trim_end_matches(';').to_string())
                }
                _ => None,
            }
        })
        .collect()
}

/// A routed net's (or port's) name as blif2Verilog wrote it in the netlist.
pub fn netlist_name(name: &str, vectors: &std::collections::BTreeSet<String>) -> String {
    if let Some((base, rest)) = name.split_once('[')
        && vectors.contains(base)
        && rest.ends_with(']')
        && !rest[..rest.len() - 1].contains(['[', ']'])
    {
        return name.to_string();
    }
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Renames every net and port pin of `nets` as the netlist names them ([`netlist_name`]).
pub fn rename_to_netlist(nets: &mut [Net], verilog: &str) {
    let v = vector_ports(verilog);
    let pin = |p: &str| match p.split_once('/') {
        Some(("PIN", port)) => format!("PIN/{}", netlist_name(port, &v)),
        _ => p.to_string(),
    };
    for n in nets {
        n.name = netlist_name(&n.name, &v);
        n.driver = pin(&n.driver);
        for point in &mut n.points {
            for s in &mut point.sinks {
                *s = pin(s);
            }
        }
    }
}

/// Writes `nets` as SPEF for `design` (deterministic: no date).
pub fn write_spef(design: &str, nets: &[Net]) -> String {
    let mut s = format!(
        "*SPEF \"IEEE 1481-1998\"\n*DESIGN \"{design}\"\n*DATE \"\"\n*VENDOR \"tofprobe\"\n\
         *PROGRAM \"tofprobe layout (from qrouter's RC trees)\"\n*VERSION \"{}\"\n\
         *DESIGN_FLOW \"PIN_CAP NONE\"\n*DIVIDER /\n*DELIMITER :\n*BUS_DELIMITER [ ]\n\
         *T_UNIT 1 NS\n*C_UNIT 1 PF\n*R_UNIT 1 OHM\n*L_UNIT 1 HENRY\n\n",
        env!("CARGO_PKG_VERSION")
    );
    for net in nets.iter().filter(|n| !n.points.is_empty()) {
        let name = escape(&net.name);
        let _ = writeln!(s, "*D_NET {name} {:.6e}", net.total_cap_pf());
        s += "*CONN\n";
        let (drv_port, drv) = spef_pin(&net.driver);
        // A port driving the net is an input of the design; an instance pin an output.
        let _ = writeln!(
            s,
            "{} {drv} {}",
            if drv_port { "*P" } else { "*I" },
            if drv_port { "I" } else { "O" }
        );
        for p in &net.points {
            for sink in &p.sinks {
                let (port, name) = spef_pin(sink);
                let _ = writeln!(
                    s,
                    "{} {name} {}",
                    if port { "*P" } else { "*I" },
                    if port { "O" } else { "I" }
                );
            }
        }
        // Node names: the single sink at a point, else NET:k.
        let node: Vec<String> = net
            .points
            .iter()
            .enumerate()
            .map(|(k, p)| match p.sinks.as_slice() {
                [one] => spef_pin(one).1,
                _ => format!("{name}:{}", k + 1),
            })
            .collect();
        s += "*CAP\n";
        for (k, p) in net.points.iter().enumerate() {
            let _ = writeln!(s, "{} {} {:.6e}", k + 1, node[k], p.c_pf);
        }
        s += "*RES\n";
        let mut id = 0;
        let mut res = |s: &mut String, a: &str, b: &str, r: f64| {
            id += 1;
            let _ = writeln!(s, "{id} {a} {b} {r:.6e}");
        };
        res(&mut s, &drv, &node[0], net.points[0].r_ohm);
        for (k, p) in net.points.iter().enumerate() {
            for &c in &p.children {
                res(&mut s, &node[k], &node[c], net.points[c].r_ohm);
            }
            if p.sinks.len() > 1 {
                for sink in &p.sinks {
                    res(&mut s, &node[k], &spef_pin(sink).1, 1e-3);
                }
            }
        }
        s += "*END\n\n";
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    // A net of qrouter's own output (the 2-bin pixel on osu018): 5 sinks.
    const LINE: &str = "rd_ptr[2] 1 DFFPOSX1_74/Q 5 ( 2.18667 0.00072378 ( 3.09333 0.00080324 NOR2X1_4/A ) , ( 1.33333 0.0003285 INVX1_18/A ) , ( 2.18667 0.00051378 ( 0.426667 0.00010512 OAI21X1_76/C ) , ( 4.42667 0.00104694 ( 0.533333 0.0001314 NAND2X1_118/A ) , ( 2.02667 0.00053604 AND2X2_18/A ) ) ) )\n";

    #[test]
    fn parses_the_tree_and_keeps_every_sink_and_capacitance() {
        let nets = parse_rc(LINE, Path::new("x.rc")).unwrap();
        assert_eq!(nets.len(), 1);
        let n = &nets[0];
        assert_eq!(
            (n.name.as_str(), n.driver.as_str()),
            ("rd_ptr[2]", "DFFPOSX1_74/Q")
        );
        assert_eq!(n.sinks, 5);
        assert_eq!(n.tree_sinks(), 5);
        assert_eq!(n.points.len(), 8);
        // The sum of the nine capacitances of the line, added by hand.
        let total = 0.00072378
            + 0.00080324
            + 0.0003285
            + 0.00051378
            + 0.00010512
            + 0.00104694
            + 0.0001314
            + 0.00053604;
        assert!(
            (n.total_cap_pf() - total).abs() < 1e-15,
            "{}",
            n.total_cap_pf()
        );
        assert_eq!(n.points[0].children.len(), 3);
    }

    #[test]
    fn a_broken_route_keeps_its_wire_and_names_no_error_pin() {
        // The shape of the default pixel's open net (2026-11-28): qrouter's walk ends in
        // ERROR where no pin is reached. The wire is kept, the sink not counted, and the
        // SPEF names no pin `ERROR` (OpenSTA would not find it).
        let line = "n 1 A/Y 2 ( 1.0 0.001 ( 2.0 0.002 B/A ) , ( 0.5 0.0005 ERROR ) )\n";
        let nets = parse_rc(line, Path::new("x.rc")).unwrap();
        assert_eq!(nets[0].tree_sinks(), 1);
        assert_eq!(nets[0].points.len(), 3);
        assert!((nets[0].total_cap_pf() - 0.0035).abs() < 1e-15);
        assert!(!write_spef("top", &nets).contains("ERROR"));
    }

    #[test]
    fn spef_has_a_resistor_per_wire_and_the_pins_as_nodes() {
        let nets = parse_rc(
            "clk 1 PIN/clk 3 ( 4 0.001 A/CLK , ( 2 0.002 B/CLK , PIN/q ) )\n",
            Path::new("x.rc"),
        )
        .unwrap();
        let s = write_spef("top", &nets);
        assert!(s.contains("*D_NET clk 3.000000e-3"), "{s}");
        assert!(
            s.contains("*P clk I\n*I A:CLK I\n*I B:CLK I\n*P q O\n"),
            "{s}"
        );
        assert!(
            s.contains("1 A:CLK 1.000000e-3\n2 clk:2 2.000000e-3\n"),
            "{s}"
        );
        assert!(
            s.contains("1 clk A:CLK 4.000000e0\n2 A:CLK clk:2 2.000000e0\n"),
            "{s}"
        );
        // Two sinks at one point: each joined by 1 mΩ.
        assert!(
            s.contains("3 clk:2 B:CLK 1.000000e-3\n4 clk:2 q 1.000000e-3\n"),
            "{s}"
        );
    }

    #[test]
    fn names_follow_blif2verilog() {
        let v = vector_ports(
            "module m (a, b);\ninput [6:0] tdc;\noutput [38:0] rd_data;\noutput ready;\n",
        );
        assert_eq!(v.len(), 2);
        assert_eq!(netlist_name("tdc[2]", &v), "tdc[2]");
        assert_eq!(
            netlist_name("y[3]_DFFPOSX1_Q_9_D", &v),
            "y_3__DFFPOSX1_Q_9_D"
        );
        assert_eq!(netlist_name("y[3][29]", &v), "y_3__29_");
        assert_eq!(netlist_name("rd_ptr[2]", &v), "rd_ptr_2_");
        assert_eq!(netlist_name("ready", &v), "ready");
        assert_eq!(netlist_name("clk_bF$buf2", &v), "clk_bF_buf2");
        let mut nets = parse_rc("y[1] 1 PIN/tdc[2] 1 ( 1 0.5 A/B )\n", Path::new("x")).unwrap();
        rename_to_netlist(&mut nets, "input [6:0] tdc;\n");
        assert_eq!(
            (nets[0].name.as_str(), nets[0].driver.as_str()),
            ("y_1_", "PIN/tdc[2]")
        );
    }

    #[test]
    fn special_characters_are_escaped() {
        assert_eq!(escape("clk_hier0_bF$buf6"), "clk_hier0_bF\\$buf6");
        assert_eq!(escape("rd_ptr[2]"), "rd_ptr[2]");
        let nets = parse_rc("a$b 1 X$1/Y 1 ( 1 0.5 Z/A )\n", Path::new("x.rc")).unwrap();
        let s = write_spef("top", &nets);
        assert!(
            s.contains("*D_NET a\\$b 5.000000e-1\n*CONN\n*I X\\$1:Y O\n"),
            "{s}"
        );
    }

    #[test]
    fn a_broken_tree_is_refused_naming_the_line() {
        for bad in [
            "n 1 A/Y 1 ( 1 0.1 B/A\n",
            "n 1 A/Y 1 ( x 0.1 B/A )\n",
            "n 1 A/Y 1 ( 1 -0.1 B/A )\n",
            "n 1 A/Y 1 ( 1 0.1 B/A ) )\n",
            "n 2 A/Y\n",
        ] {
            let e = parse_rc(&format!("\n{bad}"), Path::new("x.rc")).unwrap_err();
            assert!(e.to_string().contains("line 2"), "{bad}: {e}");
        }
    }
}
