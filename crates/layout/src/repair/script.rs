//! One ECO round's qrouter script (the other nets' wires fenced off, the nets re-routed
//! one by one with stage 1) and the splice of its routes into the routed DEF and RC files.

use super::nets::DefNets;
use std::collections::{BTreeMap, BTreeSet};

/// How far (µm) around a re-routed net's old wires the other nets' wires are fenced off
/// ([`fence`]): the re-route of a net stays near its pins (qrouter's search mask), and a
/// detour beyond this distance meets no fenced wire but the routes qrouter holds itself.
pub const FENCE_UM: f64 = 40.0;

/// Half the width (µm) of a routed wire and of a via's pad on osu018's LEF (metal 1–5:
/// width 0.3 µm; metal 6: 0.5 µm; via pads 0.4 µm square).
fn half_width(layer: &str, via: bool) -> f64 {
    match (via, layer) {
        (true, _) => 0.2,
        (false, "metal6") => 0.25,
        _ => 0.15,
    }
}

/// The routing layers a via's name joins (`M2_M1` → metal2, metal1), as the DEF names
/// its layers (those of the routed wires whose names end in the via's digits).
fn via_layers(via: &str, layers: &BTreeSet<&str>) -> Vec<String> {
    via.split('_')
        .filter_map(|p| {
            let d: String = p.chars().filter(char::is_ascii_digit).collect();
            (!d.is_empty()).then_some(d)
        })
        .filter_map(|d| {
            layers
                .iter()
                .find(|l| l.trim_start_matches(|c: char| !c.is_ascii_digit()) == d)
                .map(|l| l.to_string())
        })
        .collect()
}

/// qrouter `obstruction` commands for the wires and vias of every net but `targets`
/// within [`FENCE_UM`] of the targets' wires. qrouter 1.4 reads the routes of a routed
/// DEF but does not keep the re-route off them (the first ECO rounds on the default
/// pixel cleared its DRC errors and shorted the re-routed nets to their neighbours: LVS
/// 2 → 19 → 47 errors), so the ECO declares them as obstructions, each wire as its metal
/// (centre line ± half the width).
pub fn fence(nets: &DefNets, targets: &BTreeSet<String>) -> Vec<String> {
    let mut win: Vec<(f64, f64, f64, f64)> = Vec::new();
    for t in targets {
        let mut b = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for w in nets.wires.iter().filter(|w| &w.net == t) {
            b = (b.0.min(w.x0), b.1.min(w.y0), b.2.max(w.x1), b.3.max(w.y1));
        }
        if b.0 <= b.2 {
            win.push((
                b.0 - FENCE_UM,
                b.1 - FENCE_UM,
                b.2 + FENCE_UM,
                b.3 + FENCE_UM,
            ));
        }
    }
    let layers: BTreeSet<&str> = nets
        .wires
        .iter()
        .filter(|w| !w.via)
        .map(|w| w.layer.as_str())
        .collect();
    let mut out = BTreeSet::new();
    for w in &nets.wires {
        if targets.contains(&w.net)
            || !win
                .iter()
                .any(|b| w.x0 <= b.2 && w.x1 >= b.0 && w.y0 <= b.3 && w.y1 >= b.1)
        {
            continue;
        }
        let h = half_width(&w.layer, w.via);
        let on = if w.via {
            via_layers(&w.layer, &layers)
        } else {
            vec![w.layer.clone()]
        };
        for l in on {
            out.insert(format!(
                "obstruction {:.3} {:.3} {:.3} {:.3} {l}",
                w.x0 - h,
                w.y0 - h,
                w.x1 + h,
                w.y1 + h
            ));
        }
    }
    out.into_iter().collect()
}

/// The qrouter script of one ECO round: the flow's router configuration `cfg` (LEF,
/// layers, obstructions) without its `read_def` and routing commands, the `fence`
/// obstructions, then the routed DEF read with its routes, the `nets` removed and routed
/// again one by one by stage 1 (a net that fails is tried again without the search mask),
/// the count of nets left unrouted printed (`ECO failing: N`), the DEF and RC files written as
/// `TOP_eco.def` and `TOP_eco.rc`.
pub fn eco_script(cfg: &str, top: &str, nets: &BTreeSet<String>, fence: &[String]) -> String {
    let mut s: String = cfg
        .lines()
        .filter(|l| {
            let w = l.split_whitespace().next().unwrap_or("");
            !matches!(w, "read_def" | "quit") && !w.starts_with("qrouter::")
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let list = nets
        .iter()
        .map(|n| format!("{{{n}}}"))
        .collect::<Vec<_>>()
        .join(" ");
    for f in fence {
        s += f;
        s.push('\n');
    }
    s += &format!(
        "read_def {top}.def\nset eco_nets [list {list}]\n\
         set left 0\nforeach n $eco_nets {{\n  remove net $n\n  set r [stage1 route $n]\n  if {{$r > 0}} {{ set r [stage1 mask none route $n] }}\n  \
         puts stdout \"ECO route $n: $r\"\n  incr left $r\n}}\n\
         puts stdout \"ECO failing: $left\"\n\
         cleanup net {{*}}$eco_nets\nwrite_def {top}_eco.def\nwrite_delays {top}_eco.rc\nquit\n"
    );
    s
}

/// The number of nets left unrouted by an ECO round (`ECO failing: N` of its log).
pub fn eco_failing(log: &str) -> Option<u64> {
    log.lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix("ECO failing: "))
        .and_then(|n| n.trim().parse().ok())
}

/// The nets an ECO round changed: the nets it was given and the blockers qrouter ripped
/// up to route them (`Ripping up blocking net NAME` in its log), which it routed again.
pub fn eco_changed(log: &str, nets: &BTreeSet<String>) -> BTreeSet<String> {
    let mut out = nets.clone();
    out.extend(
        log.lines()
            .filter_map(|l| l.trim().strip_prefix("Ripping up blocking net "))
            .map(|n| n.trim().to_string()),
    );
    out
}

/// A DEF section entry: its name, first and last line.
type Entry = (String, usize, usize);

/// The entries (`- NAME … ;`, as line ranges) of a DEF section from `header` (`NETS`,
/// `SPECIALNETS`) to its `END`: (name, first line, last line), and the header's line.
fn section_entries(lines: &[&str], header: &str) -> Option<(usize, usize, Vec<Entry>)> {
    let start = lines
        .iter()
        .position(|l| l.split_whitespace().next() == Some(header))?;
    let end = start
        + lines[start..]
            .iter()
            .position(|l| l.trim() == format!("END {header}"))?;
    let mut entries = Vec::new();
    let mut i = start + 1;
    while i < end {
        let t = lines[i].trim();
        if let Some(name) = t.strip_prefix("- ") {
            let name = name.split_whitespace().next().unwrap_or("").to_string();
            let mut j = i;
            while j < end && !lines[j].trim_end().ends_with(';') {
                j += 1;
            }
            entries.push((name, i, j.min(end - 1)));
            i = j + 1;
        } else {
            i += 1;
        }
    }
    Some((start, end, entries))
}

/// The routed DEF `base` with the routing of `nets` taken from `eco` (qrouter's DEF of an
/// ECO round): their NETS entries replaced, their SPECIALNETS entries (qrouter's stubs to
/// off-grid pins) replaced by the ECO's. Every other net stays as `base` has it, line for
/// line: qrouter writes the routes it read back in pieces (the whole ECO DEF of the default
/// pixel had 645 DRC errors and 9 merged nets), so only the nets it routed are taken.
pub fn splice_def(base: &str, eco: &str, nets: &BTreeSet<String>) -> Option<String> {
    let b: Vec<&str> = base.lines().collect();
    let e: Vec<&str> = eco.lines().collect();
    let (_, _, b_nets) = section_entries(&b, "NETS")?;
    let (_, _, e_nets) = section_entries(&e, "NETS")?;
    let e_route: BTreeMap<&str, (usize, usize)> = e_nets
        .iter()
        .filter(|(n, _, _)| nets.contains(n))
        .map(|(n, i, j)| (n.as_str(), (*i, *j)))
        .collect();
    // Line index → replacement (None: drop the line).
    let mut replace: BTreeMap<usize, Option<String>> = BTreeMap::new();
    for (n, i, j) in &b_nets {
        if let Some(&(ei, ej)) = e_route.get(n.as_str()) {
            replace.insert(*i, Some(e[ei..=ej].join("\n")));
            for k in i + 1..=*j {
                replace.insert(k, None);
            }
        }
    }
    let spec = |lines: &[&str]| section_entries(lines, "SPECIALNETS");
    if let (Some((bs, be, b_spec)), Some((_, _, e_spec))) = (spec(&b), spec(&e)) {
        let mut count = b_spec.len();
        for (n, i, j) in b_spec.iter().filter(|(n, _, _)| nets.contains(n)) {
            let _ = n;
            for k in *i..=*j {
                replace.insert(k, None);
            }
            count -= 1;
        }
        let added: Vec<String> = e_spec
            .iter()
            .filter(|(n, _, _)| nets.contains(n))
            .map(|(_, i, j)| e[*i..=*j].join("\n"))
            .collect();
        count += added.len();
        replace.insert(bs, Some(format!("SPECIALNETS {count} ;")));
        let mut end = added;
        end.push(b[be].to_string());
        replace.insert(be, Some(end.join("\n")));
    }
    let mut out = String::with_capacity(base.len());
    for (k, l) in b.iter().enumerate() {
        match replace.get(&k) {
            Some(Some(r)) => {
                out += r;
                out.push('\n');
            }
            Some(None) => {}
            None => {
                out += l;
                out.push('\n');
            }
        }
    }
    Some(out)
}

/// qrouter's RC file `base` (one line per net, the net's name first) with the lines of
/// `nets` taken from `eco`.
pub fn splice_rc(base: &str, eco: &str, nets: &BTreeSet<String>) -> String {
    let first = |l: &str| l.split_whitespace().next().unwrap_or("").to_string();
    let new: BTreeMap<String, &str> = eco
        .lines()
        .filter(|l| nets.contains(&first(l)))
        .map(|l| (first(l), l))
        .collect();
    base.lines()
        .map(|l| new.get(&first(l)).copied().unwrap_or(l))
        .fold(String::with_capacity(base.len()), |mut s, l| {
            s += l;
            s.push('\n');
            s
        })
}
