//! The layout's verdict: each check the macro fails, saying which and by how much (DRC,
//! LVS, the laid-out netlist's equivalence, setup and hold after routing at the nominal
//! corner, shapes past the die, the DEF's counts), and the report's sections on them.
//! `tofprobe layout` exits 1 when any fails, with the report and picture written.

use std::fmt::Write as _;

use tofprobe_io::markdown::Table;

use crate::report::LayoutReport;

/// Each failed check, in words (empty: every check passed).
pub fn failures(r: &LayoutReport) -> Vec<String> {
    let mut f = Vec::new();
    if r.drc_errors > 0 {
        let rules: Vec<String> = r
            .drc_rules
            .iter()
            .map(|x| format!("{} × {}", x.boxes, x.rule))
            .collect();
        f.push(format!(
            "DRC: {} errors (magic{})",
            r.drc_errors,
            if rules.is_empty() {
                String::new()
            } else {
                format!(": {}", rules.join("; "))
            }
        ));
    }
    if !r.lvs_match {
        f.push(format!(
            "LVS: {} ({})",
            r.lvs_result,
            r.lvs_errors.join(", ")
        ));
    }
    if let Some(e) = &r.equivalence
        && !e.proven()
    {
        f.push(format!(
            "equivalence: the laid-out netlist is not proven equivalent to the RTL ({} of {} pairs unproven; first {})",
            e.points - e.proven,
            e.points,
            e.first_unproven
        ));
    }
    let p = &r.post_route;
    let corner = r
        .corners
        .iter()
        .find(|c| c.post_route == *p)
        .map_or_else(|| r.tech.clone(), |c| format!("{} {}", c.library, c.corner));
    if p.setup_slack_ns < 0.0 {
        f.push(format!(
            "setup: worst slack {:.3} ns at {:.3} ns ({corner}; `{}` → `{}`): post-route f_max {:.1} MHz, the clock needs {:.1} MHz",
            p.setup_slack_ns,
            p.period_ns,
            p.setup_path.0,
            p.setup_path.1,
            p.f_max_mhz,
            1e3 / p.period_ns
        ));
    }
    if p.hold_slack_registers_ns < 0.0 {
        f.push(format!(
            "hold: worst register-to-register slack {:.3} ns ({corner}; `{}` → `{}`)",
            p.hold_slack_registers_ns, p.hold_registers_path.0, p.hold_registers_path.1
        ));
    }
    let outside =
        r.def_boundary.as_ref().map_or(0, |o| o.outside) + r.gds.as_ref().map_or(0, |g| g.outside);
    if outside > 0 {
        let worst = r
            .def_boundary
            .as_ref()
            .map_or(0.0, |o| o.worst_um)
            .max(r.gds.as_ref().map_or(0.0, |g| g.worst_um));
        f.push(format!(
            "boundary: {} DEF and {} GDS shapes reach past the die, up to {worst:.3} µm",
            r.def_boundary.as_ref().map_or(0, |o| o.outside),
            r.gds.as_ref().map_or(0, |g| g.outside),
        ));
    }
    for c in r.def_counts.iter().filter(|c| c.declared != c.listed) {
        f.push(format!(
            "DEF: {} declares {} entries and lists {}",
            c.section, c.declared, c.listed
        ));
    }
    f
}

/// The "Verdict" section.
pub fn verdict_markdown(r: &LayoutReport) -> String {
    let mut s = String::from("## Verdict\n\n");
    if r.failures.is_empty() {
        s += "**PASS**: DRC 0, LVS match, the laid-out netlist proven equivalent to the RTL, setup and register-to-register hold met after routing at the nominal corner, every shape inside the die, the DEF's counts consistent.\n\n";
    } else {
        s += "**FAIL** (`tofprobe layout` exits 1):\n\n";
        for x in &r.failures {
            let _ = writeln!(s, "- {x}");
        }
        s += "\n";
    }
    s
}

/// The sections on the checks beyond DRC and LVS: the boundary, the stream, the laid-out
/// netlist's proof, the options for corners missed after routing.
pub fn checks_markdown(r: &LayoutReport) -> String {
    let mut t = Table::left(["check", "result"]);
    if let Some(g) = &r.die_growth {
        t.row([
            "die margin".to_string(),
            format!(
                "{:.2} µm left and right, {:.2} µm top and bottom (a track pitch past the edge tracks, which the router is kept to); {} pins extended to the edge",
                g.margin_x_um, g.margin_y_um, g.pins_extended
            ),
        ]);
    }
    if let Some(o) = &r.def_boundary {
        t.row([
            "DEF shapes past the die".to_string(),
            format!(
                "{} of {}{}",
                o.outside,
                o.shapes,
                if o.outside > 0 {
                    format!(", up to {:.3} µm ({})", o.worst_um, o.examples.join("; "))
                } else {
                    String::new()
                }
            ),
        ]);
    }
    if let Some(g) = &r.gds {
        t.row([
            "GDS shapes past the die (klayout)".to_string(),
            format!(
                "{} of {}{}",
                g.outside,
                g.shapes,
                if g.outside > 0 {
                    format!(", up to {:.3} µm", g.worst_um)
                } else {
                    String::new()
                }
            ),
        ]);
        t.row(["GDS holds".to_string(), g.holds().to_string()]);
    }
    if !r.def_counts.is_empty() {
        let counts: Vec<String> = r
            .def_counts
            .iter()
            .map(|c| {
                if c.declared == c.listed {
                    format!("{} {}", c.section, c.listed)
                } else {
                    format!("{} {} declared, {} listed", c.section, c.declared, c.listed)
                }
            })
            .collect();
        t.row([
            "DEF sections (declared = listed)".to_string(),
            counts.join(", "),
        ]);
    }
    if let Some(e) = &r.equivalence {
        let physical: Vec<String> = e
            .physical_only
            .iter()
            .map(|(c, n)| format!("{n} {c}"))
            .collect();
        t.row([
            "laid-out netlist ≡ RTL (yosys)".to_string(),
            format!(
            "{} — {} of {} pairs proven; {} cells from the routed DEF (`{}`), physical-only cells left out: {}; {:.1} s{}",
            if e.proven() {
                "proven"
            } else {
                "**NOT proven**"
            },
            e.proven,
            e.points,
            e.cells,
            e.netlist,
            if physical.is_empty() {
                "none".to_string()
            } else {
                physical.join(", ")
            },
            e.seconds,
            if e.cached { " (cached)" } else { "" }
            ),
        ]);
    }
    let mut s = format!("## Boundary, stream and netlist\n\n{t}\n");
    if !r.corner_options.is_empty() {
        s += "## Options for the corners missed after routing\n\n";
        for o in &r.corner_options {
            let _ = writeln!(s, "- {} {}: {}", o.library, o.corner, o.note);
        }
        s += "\n";
    }
    s
}

/// Below the timing table: each path group's worst setup and hold, and what the hold over
/// all paths means when it is worse than between registers (not judged: an input's).
pub fn timing_note(p: &crate::sta::PostRoute) -> String {
    let mut s = String::new();
    let groups = |g: &[crate::sta::GroupSlack]| -> String {
        g.iter()
            .map(|x| {
                format!(
                    "`{}` {:.3} ns (`{}` → `{}`)",
                    x.group, x.slack_ns, x.path.0, x.path.1
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !p.setup_groups.is_empty() {
        let _ = writeln!(
            s,
            "Worst path of each path group (OpenSTA; the worst of them is OpenSTA's own worst slack): setup {}; hold {}; hold between registers {}.\n",
            groups(&p.setup_groups),
            groups(&p.hold_groups),
            groups(&p.hold_registers_groups)
        );
    }
    if p.hold_slack_ns < 0.0 && p.hold_slack_ns < p.hold_slack_registers_ns {
        let _ = writeln!(
            s,
            "Hold over all paths ({:.3} ns, `{}` → `{}`) starts at an input, which the constraints let change at the clock's edge at the port while the flops see the clock after its buffer tree: the macro needs its inputs held {:.3} ns after that edge, a requirement on whatever drives them. The verdict judges hold between registers, the paths inside the macro.\n",
            p.hold_slack_ns, p.hold_path.0, p.hold_path.1, -p.hold_slack_ns
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The report of the 2-bin pixel on osu018 (`tofprobe layout two.toml --route-cleanup
    /// off`): every check passed.
    const CLEAN: &str = include_str!("../../testdata/layout-report-2bin-osu018.json");

    fn clean() -> LayoutReport {
        serde_json::from_str(CLEAN).unwrap()
    }

    #[test]
    fn a_clean_macro_passes_and_its_input_hold_is_explained() {
        let r = clean();
        assert!(failures(&r).is_empty() && r.passed(), "{:?}", failures(&r));
        let md = r.markdown();
        assert!(md.contains("## Verdict\n\n**PASS**"), "{md}");
        // Hold over all paths is negative (an input at the clock edge), between registers
        // positive: not a failure, but said.
        assert!(r.post_route.hold_slack_ns < 0.0 && r.post_route.hold_slack_registers_ns > 0.0);
        assert!(
            md.contains("the macro needs its inputs held 0.501 ns after that edge"),
            "{md}"
        );
    }

    #[test]
    fn each_failed_check_is_named_with_its_figure() {
        // The 4-bin latch pixel's timing (the recorded OpenSTA log of crate::sta's tests):
        // hold between registers −1.6524 ns.
        let log = include_str!("../../testdata/sta-latch4-osu018.log");
        let mut r = clean();
        r.post_route = crate::sta::parse(log, 6.25, 0, Path::new("l")).unwrap();
        let f = failures(&r);
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(
            f[0].starts_with("hold: worst register-to-register slack -1.652 ns")
                && f[0].contains("`wd_0_DFFPOSX1_Q` → `y[0]_LATCH_Q`"),
            "{f:?}"
        );
        // Setup missed by 0.1 ns at the 6.25 ns clock.
        let mut r = clean();
        r.post_route.setup_slack_ns = -0.1;
        let f = failures(&r);
        assert!(
            f[0].starts_with("setup: worst slack -0.100 ns at 6.250 ns"),
            "{f:?}"
        );
        // qrouter's SPECIALNETS count as it was, shapes past the die, an unproven pair.
        let mut r = clean();
        r.def_counts[4].declared = 359;
        r.def_counts[4].listed = 357;
        if let Some(o) = r.def_boundary.as_mut() {
            o.outside = 101;
            o.worst_um = 1.15;
        }
        if let Some(e) = r.equivalence.as_mut() {
            e.proven = e.points - 1;
            e.first_unproven = "\\y[0]_gold [5] \\y[0]_gate [5]".into();
        }
        let f = failures(&r);
        assert!(
            f.iter()
                .any(|x| x == "DEF: SPECIALNETS declares 359 entries and lists 357"),
            "{f:?}"
        );
        assert!(
            f.iter()
                .any(|x| x.starts_with("boundary: 101 DEF and 0 GDS shapes")
                    && x.ends_with("up to 1.150 µm")),
            "{f:?}"
        );
        assert!(
            f.iter()
                .any(|x| x.starts_with("equivalence:") && x.contains("1 of 432 pairs unproven")),
            "{f:?}"
        );
        r.failures = f;
        assert!(!r.passed());
        let md = r.markdown();
        assert!(
            md.contains("**FAIL** (`tofprobe layout` exits 1):\n\n- equivalence:"),
            "{md}"
        );
    }
}
