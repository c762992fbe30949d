//! The ECO re-route: the repair of a routed macro that magic's DRC or netgen's LVS finds
//! dirty after qrouter's stages 1 and 2 (stage 3, which re-routes every net, is skipped
//! on large pixels). The nets to repair are read from the checks' own output — the nets
//! whose wires come near a DRC error box (`drc listall why`), and the nets netgen's
//! `comp.out` lists as unmatched (a layout net named after a cell pin is mapped back to
//! the DEF net on that pin) — and only those are ripped up (`remove net`) and routed
//! again (`stage2 route NET`, which rips up and re-queues what blocks it, then `stage2`
//! for those) on the routed DEF, which qrouter reads with its routes. DRC and LVS then
//! run again, at most [`MAX_ROUNDS`] times.

use crate::error::{LayoutError, Result};
use crate::qflow::Checks;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// Rounds of re-route and re-check at most: each round re-routes only the nets the last
/// checks name, so a repair that has not converged in three rounds is not converging.
pub const MAX_ROUNDS: usize = 3;

/// How near (µm) a wire's centre line must come to a DRC error box for its net to be
/// re-routed: half a wire's width plus the minimum spacing (osu018 metal 1–5: 0.15 +
/// 0.3 µm), so the nets whose metal lies on the box or within a spacing of it. A box with
/// no net that near (a via pad, a wider wire) takes the nets within [`FAR_UM`].
pub const NEAR_UM: f64 = 0.45;

/// The fallback distance for a box with no net within [`NEAR_UM`].
pub const FAR_UM: f64 = 1.0;

/// A DRC error box (µm) and the rule it breaks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DrcBox {
    /// magic's text of the rule.
    pub rule: String,
    /// Lower left x (µm).
    pub x0: f64,
    /// Lower left y (µm).
    pub y0: f64,
    /// Upper right x (µm).
    pub x1: f64,
    /// Upper right y (µm).
    pub y1: f64,
}

/// The error boxes printed by the DRC script of [`crate::qflow::Project::drc_reasons`]:
/// `TOFPROBE-SCALE S` (µm per magic unit, `cif scale out`) and one
/// `TOFPROBE-BOX X0 Y0 X1 Y1 RULE` per box in magic units.
pub fn parse_drc_boxes(text: &str) -> Vec<DrcBox> {
    let scale = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("TOFPROBE-SCALE "))
        .and_then(|s| s.trim().parse::<f64>().ok());
    let Some(s) = scale else {
        return vec![];
    };
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("TOFPROBE-BOX "))
        .filter_map(|l| {
            let mut it = l.splitn(5, ' ');
            let mut c = [0.0; 4];
            for v in &mut c {
                *v = it.next()?.parse::<f64>().ok()? * s;
            }
            Some(DrcBox {
                rule: it.next()?.trim().to_string(),
                x0: c[0],
                y0: c[1],
                x1: c[2],
                y1: c[3],
            })
        })
        .collect()
}

/// One piece of a net's routing in the DEF: a wire between two points (its centre line's
/// bounding box, µm) on `layer`, or a via at a point (`layer` is then the via's name).
#[derive(Debug, Clone, PartialEq)]
pub struct Wire {
    /// The net.
    pub net: String,
    /// The routing layer (lower case as in the DEF) or the via's name.
    pub layer: String,
    /// Whether this is a via.
    pub via: bool,
    /// Bounding box (µm).
    pub x0: f64,
    /// Bounding box (µm).
    pub y0: f64,
    /// Bounding box (µm).
    pub x1: f64,
    /// Bounding box (µm).
    pub y1: f64,
}

/// The NETS section of a routed DEF: every net's wires and vias, and each cell pin's net.
#[derive(Debug, Clone, Default)]
pub struct DefNets {
    /// Every routed piece.
    pub wires: Vec<Wire>,
    /// `(instance, pin)` → net.
    pub pins: BTreeMap<(String, String), String>,
    /// Every net's name.
    pub names: BTreeSet<String>,
}

/// Reads the NETS section of a DEF (`- NET ( INST PIN ) … + ROUTED LAYER ( x y ) ( x * )
/// VIA NEW LAYER …`).
pub fn def_nets(def: &str) -> DefNets {
    let mut out = DefNets::default();
    let mut units = 100.0;
    let mut in_nets = false;
    let mut net = String::new();
    for line in def.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["UNITS", "DISTANCE", "MICRONS", u, ..] => {
                units = u.parse().unwrap_or(units);
                continue;
            }
            ["NETS", ..] => {
                in_nets = true;
                continue;
            }
            ["END", "NETS"] => {
                in_nets = false;
                continue;
            }
            _ => {}
        }
        if !in_nets {
            continue;
        }
        let mut i = 0;
        if t.first() == Some(&"-") {
            if let Some(n) = t.get(1) {
                net = n.to_string();
                out.names.insert(net.clone());
            }
            i = 2;
        }
        // Pins: ( INST PIN ) before the routing.
        let route_at = t.iter().position(|w| *w == "ROUTED" || *w == "NEW");
        let pins_end = route_at.unwrap_or(t.len());
        while i + 3 < pins_end + 1 && i < pins_end {
            if t[i] == "(" && i + 3 < t.len() && t[i + 3] == ")" && t[i + 1] != "*" {
                if t[i + 1].parse::<f64>().is_err() {
                    out.pins
                        .insert((t[i + 1].to_string(), t[i + 2].to_string()), net.clone());
                }
                i += 4;
            } else {
                i += 1;
            }
        }
        let Some(r) = route_at else { continue };
        let Some(layer) = t.get(r + 1) else { continue };
        let mut last: Option<(f64, f64)> = None;
        let mut j = r + 2;
        while j < t.len() {
            if t[j] == "(" && j + 3 < t.len() && t[j + 3] == ")" {
                let coord = |s: &str, prev: Option<f64>| {
                    if s == "*" {
                        prev
                    } else {
                        s.parse::<f64>().ok().map(|v| v / units)
                    }
                };
                let x = coord(t[j + 1], last.map(|p| p.0));
                let y = coord(t[j + 2], last.map(|p| p.1));
                if let (Some(x), Some(y)) = (x, y) {
                    let (px, py) = last.unwrap_or((x, y));
                    out.wires.push(Wire {
                        net: net.clone(),
                        layer: layer.to_lowercase(),
                        via: false,
                        x0: px.min(x),
                        y0: py.min(y),
                        x1: px.max(x),
                        y1: py.max(y),
                    });
                    last = Some((x, y));
                }
                j += 4;
            } else if let (Some((x, y)), w) = (last, t[j]) {
                // A via name after a point (a width or `;` is not a via).
                if w != ";" && w.parse::<f64>().is_err() && w != "+" {
                    out.wires.push(Wire {
                        net: net.clone(),
                        layer: w.to_string(),
                        via: true,
                        x0: x,
                        y0: y,
                        x1: x,
                        y1: y,
                    });
                }
                j += 1;
            } else {
                j += 1;
            }
        }
    }
    out
}

/// The routing layer a rule of magic's names, lower case (`Metal2 spacing < 3` → `metal2`),
/// when the DEF routes on it; `None` (every layer) otherwise.
fn rule_layer(rule: &str, nets: &DefNets) -> Option<String> {
    let first = rule.split_whitespace().next()?.to_lowercase();
    nets.wires
        .iter()
        .any(|w| !w.via && w.layer == first)
        .then_some(first)
}

/// The nets with a wire on the box's layer (or a via) within `near` µm of a DRC box, or
/// within [`FAR_UM`] for a box with none that near.
pub fn nets_at_boxes(nets: &DefNets, boxes: &[DrcBox], near: f64) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for b in boxes {
        let layer = rule_layer(&b.rule, nets);
        let at = |d: f64| -> BTreeSet<String> {
            nets.wires
                .iter()
                .filter(|w| {
                    (w.via || layer.as_ref().is_none_or(|l| *l == w.layer))
                        && w.x0 - d <= b.x1
                        && w.x1 + d >= b.x0
                        && w.y0 - d <= b.y1
                        && w.y1 + d >= b.y0
                })
                .map(|w| w.net.clone())
                .collect()
        };
        let mut found = at(near);
        if found.is_empty() {
            found = at(FAR_UM.max(near));
        }
        out.extend(found);
    }
    out
}

/// The width of a name in netgen's `comp.out` columns: a longer name is cut to it.
const COMP_NAME_CHARS: usize = 37;

/// The most nets a cut name may stand for and still be re-routed (all of them).
const MAX_PREFIXED: usize = 8;

/// The nets netgen's `comp.out` lists among its net mismatches ("NET mismatches: Class
/// fragments follow"): both columns' `Net: NAME` lines. A layout net without a label is
/// named after a cell pin (`DFFPOSX1_198/Q`), mapped to the DEF net on that pin; a name
/// neither a DEF net nor a known pin is left out.
pub fn lvs_nets(comp_out: &str, nets: &DefNets) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let Some(at) = comp_out.find("NET mismatches") else {
        return out;
    };
    for line in comp_out[at..].lines() {
        for col in line.split('|') {
            let Some(name) = col.trim().strip_prefix("Net: ") else {
                continue;
            };
            let name = name.trim();
            if nets.names.contains(name) {
                out.insert(name.to_string());
            } else if let Some(n) = name
                .rsplit_once('/')
                .and_then(|(inst, pin)| nets.pins.get(&(inst.to_string(), pin.to_string())))
            {
                out.insert(n.clone());
            } else if name.len() >= COMP_NAME_CHARS {
                // netgen cuts a long name to its column: the nets it may be.
                let prefixed: Vec<&String> = nets
                    .names
                    .range(name.to_string()..)
                    .take_while(|n| n.starts_with(name))
                    .collect();
                if prefixed.len() <= MAX_PREFIXED {
                    out.extend(prefixed.into_iter().cloned());
                }
            }
        }
    }
    out
}

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
/// again one by one, the ripped-up blockers routed, the DEF and RC files written as
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

/// The entries (`- NAME … ;`, as line ranges) of a DEF section from `header` (`NETS`,
/// `SPECIALNETS`) to its `END`: (name, first line, last line), and the header's line.
fn section_entries(
    lines: &[&str],
    header: &str,
) -> Option<(usize, usize, Vec<(String, usize, usize)>)> {
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

/// netgen's total error count in qflow's LVS log (`Total errors = N`).
pub fn lvs_total(log: &str) -> Option<u64> {
    log.lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix("Total errors = "))
        .and_then(|n| n.trim().parse().ok())
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
    let fenced = if std::env::var_os("TOFPROBE_ECO_NO_FENCE").is_some() {
        vec![]
    } else {
        fence(&def_nets(&read(&def)?), targets)
    };
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
    steps: &mut Vec<crate::report::Step>,
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
        steps.push(crate::report::Step {
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
        steps.push(crate::report::Step {
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
            steps.push(crate::report::Step {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The default pixel's routed DEF around its two DRC spots and its open net
    /// (2026-11-28, density 0.5, stage 3 skipped), cut to three nets; `far` is a net
    /// elsewhere, `up` a metal3 wire over the first spot.
    const DEF: &str = "UNITS DISTANCE MICRONS 100 ;\nNETS 4 ;\n- y[0][5]\n  ( AOI22X1_862 A ) \n  ( NAND2X1_370 A ) \n  ( DFFPOSX1_198 Q ) \n  ( AOI22X1_435 D ) \n\
+ ROUTED metal1 ( 35840 35400 ) M2_M1 \n  NEW metal2 ( 35840 35400 ) ( * 35100 ) ( 35920 * ) ( * 34300 ) ( 35840 * ) ( * 33400 ) M2_M1 \n\
  NEW metal1 ( 35840 33400 ) ( 35920 * ) \n  NEW metal1 ( 35520 35500 ) ( 35840 * ) ( * 35400 ) \n  NEW metal1 ( 37600 34755 ) ( 37440 * ) M2_M1 \n\
  NEW metal2 ( 37440 34800 ) ( 37360 * ) M3_M2 \n  NEW metal3 ( 37360 34800 ) ( 35920 * ) M3_M2 ;\n\
- y[9][37]\n  ( AOI22X1_1053 A ) \n  ( DFFPOSX1_1381 Q ) \n+ ROUTED metal1 ( 25600 51500 ) M2_M1 \n  NEW metal2 ( 25600 51500 ) ( * 51400 ) M3_M2 \n\
  NEW metal2 ( 25600 51300 ) M3_M2 \n  NEW metal3 ( 25600 51300 ) M4_M3 ;\n\
- far\n  ( INVX1_1 Y ) ( INVX1_2 A ) \n+ ROUTED metal2 ( 10000 10000 ) ( * 12000 ) ;\n\
- up\n  ( INVX1_3 Y ) \n+ ROUTED metal3 ( 37000 34790 ) ( 37800 * ) ;\nEND NETS\n\
SPECIALNETS 2 ;\n- vdd\n+ ROUTED metal1 240 ( 0 0 ) ( 90000 * ) ;\n- y[0][5]\n+ ROUTED metal1 40 ( 37600 34740 ) ;\nEND SPECIALNETS\nEND DESIGN\n";

    /// What the DRC script printed for that macro (magic 8.3, `cif scale out` = 0.1 µm).
    const DRC: &str = "Loading\nTOFPROBE-SCALE 0.10000000149011612\n\
TOFPROBE-DRC 1 Metal2 spacing < 3 (Mosis #9.2)\nTOFPROBE-BOX 3739 3478 3745 3480 Metal2 spacing < 3 (Mosis #9.2)\n\
TOFPROBE-DRC 2 Metal2 area < 20 (Mosis #+++)\nTOFPROBE-BOX 2558 5128 2562 5132 Metal2 area < 20 (Mosis #+++)\n\
TOFPROBE-BOX 3742 3473 3746 3477 Metal2 area < 20 (Mosis #+++)\n";

    /// netgen's comp.out for the open net (its NET mismatches block).
    const COMP: &str = "Number of nets: 9437 **Mismatch**          |Number of nets: 9436 **Mismatch**          \n\
---------------------------------------------------------------------------------------\n\
NET mismatches: Class fragments follow (with fanout counts):\n\
Circuit 1: tofprobe_pixel                  |Circuit 2: tofprobe_pixel                  \n\n\
---------------------------------------------------------------------------------------\n\
Net: NAND2X1_370/A                         |Net: y[0][5]                               \n\
  NAND2X1/A = 1                            |  AOI22X1/D = 1                            \n\
                                           |                                           \n\
Net: DFFPOSX1_198/Q                        |(no matching net)                          \n\
  DFFPOSX1/Q = 1                           |                                           \n\
Netlists do not match.\n";

    fn set(v: &[&str]) -> BTreeSet<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn drc_boxes_are_read_in_micrometres() {
        let b = parse_drc_boxes(DRC);
        assert_eq!(b.len(), 3);
        assert_eq!(b[0].rule, "Metal2 spacing < 3 (Mosis #9.2)");
        // 3739 magic units × 0.1 µm (the f32 scale: 1e-6 relative).
        assert!((b[0].x0 - 373.9).abs() < 1e-3 && (b[0].y1 - 348.0).abs() < 1e-3);
        // Without the scale line the units are unknown: no box.
        assert!(parse_drc_boxes(&DRC.replace("TOFPROBE-SCALE", "x")).is_empty());
    }

    #[test]
    fn the_def_gives_wires_vias_and_pins() {
        let n = def_nets(DEF);
        assert_eq!(n.names, set(&["far", "up", "y[0][5]", "y[9][37]"]));
        assert_eq!(n.pins[&("DFFPOSX1_198".into(), "Q".into())], "y[0][5]");
        assert_eq!(n.pins[&("INVX1_2".into(), "A".into())], "far");
        // The `( * 35100 )` point continues the last x; `far` is one 20 µm wire.
        let far: Vec<&Wire> = n.wires.iter().filter(|w| w.net == "far").collect();
        assert_eq!(far.len(), 2); // the start point and the wire
        assert_eq!((far[1].x0, far[1].y0, far[1].y1), (100.0, 100.0, 120.0));
        assert!(
            n.wires
                .iter()
                .any(|w| w.via && w.layer == "M2_M1" && w.x0 == 374.4 && w.y0 == 347.55)
        );
        // Power stripes (SPECIALNETS) are not nets to re-route.
        assert!(!n.names.contains("vdd"));
    }

    #[test]
    fn each_drc_box_names_the_nets_at_it() {
        let n = def_nets(DEF);
        let boxes = parse_drc_boxes(DRC);
        // The spacing/area boxes at (374, 347.5) µm lie on y[0][5]'s metal2; the area box
        // at (256, 513) µm on y[9][37]'s stacked via. `up`'s metal3 passes over the
        // first spot: not a metal2 rule's net; `far` is 250 µm away.
        assert_eq!(
            nets_at_boxes(&n, &boxes, NEAR_UM),
            set(&["y[0][5]", "y[9][37]"])
        );
        // A Metal3 rule at the same box takes `up` (and y[0][5]'s metal3 and its vias).
        let m3 = DrcBox {
            rule: "Metal3 spacing < 3".into(),
            ..boxes[0].clone()
        };
        assert_eq!(nets_at_boxes(&n, &[m3], NEAR_UM), set(&["up", "y[0][5]"]));
        // A box far from every wire names none.
        let nowhere = DrcBox {
            x0: 600.0,
            x1: 601.0,
            ..boxes[0].clone()
        };
        assert!(nets_at_boxes(&n, &[nowhere], NEAR_UM).is_empty());
    }

    #[test]
    fn the_open_net_of_comp_out_is_the_def_net_on_its_pins() {
        let n = def_nets(DEF);
        // Both columns: the netlist's `y[0][5]`, and the layout's pin-named fragments
        // (DFFPOSX1_198/Q, NAND2X1_370/A) are on y[0][5] in the DEF.
        assert_eq!(lvs_nets(COMP, &n), set(&["y[0][5]"]));
        let only_pin = COMP.replace("|Net: y[0][5]", "|Net: zz");
        assert_eq!(lvs_nets(&only_pin, &n), set(&["y[0][5]"]));
        // A pin on no DEF net maps to nothing; a matching comp.out names nothing.
        let unknown = "NET mismatches\nNet: NOPE_1/A  |(no matching net)\n";
        assert!(lvs_nets(unknown, &n).is_empty());
        assert!(lvs_nets("Circuits match uniquely.\n", &n).is_empty());
        // netgen cuts long names to its column (the first ECO round's comp.out: `Net:
        // rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NO`): the DEF nets that begin so.
        let mut long = n.clone();
        for x in [
            "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_A",
            "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_B",
            "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_C",
        ] {
            long.names.insert(x.to_string());
        }
        let cut =
            "NET mismatches\n(no matching net)     |Net: rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NO \n";
        assert_eq!(
            lvs_nets(cut, &long),
            set(&[
                "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_A",
                "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_B"
            ])
        );
    }

    #[test]
    fn the_fence_holds_the_other_nets_wires_near_the_re_routed_ones() {
        let n = def_nets(DEF);
        let f = fence(&n, &set(&["y[0][5]"]));
        // `up`'s metal3 wire over y[0][5], as its metal (centre line ± 0.15 µm); `far`
        // (250 µm away) and y[9][37] (165 µm away) are beyond the 40 µm fence; the
        // re-routed net's own wires are not obstructions. (A route's first point is a
        // piece of its own, for routes that are one point and a via.)
        assert_eq!(
            f,
            vec![
                "obstruction 369.850 347.750 370.150 348.050 metal3",
                "obstruction 369.850 347.750 378.150 348.050 metal3"
            ]
        );
        // Re-routing `up` fences y[0][5]: its wires and, on both layers, its vias.
        let g = fence(&n, &set(&["up"]));
        assert!(
            g.contains(&"obstruction 374.200 347.350 374.600 347.750 metal1".to_string()),
            "{g:?}"
        );
        assert!(
            g.contains(&"obstruction 374.200 347.350 374.600 347.750 metal2".to_string()),
            "{g:?}"
        );
        assert!(
            g.iter()
                .all(|l| !l.ends_with("metal3") || !l.contains("369.850"))
        );
    }

    #[test]
    fn the_eco_script_routes_only_the_named_nets() {
        let cfg = "verbose 1\nread_lef /x.lef\ncatch {layers 6}\nobstruction 0 0 1 1 metal1\n\
                   read_def top.def\nqrouter::standard_route top_route.def false true\nquit\n";
        let fenced = vec!["obstruction 1.000 2.000 3.000 4.000 metal2".to_string()];
        let s = eco_script(
            &cfg.replace("top", "tofprobe_pixel"),
            "tofprobe_pixel",
            &set(&["y[0][5]", "a"]),
            &fenced,
        );
        assert!(
            s.contains(
                "metal1\nobstruction 1.000 2.000 3.000 4.000 metal2\nread_def tofprobe_pixel.def\n"
            ),
            "{s}"
        );
        assert!(s.starts_with("verbose 1\nread_lef /x.lef\ncatch {layers 6}\nobstruction"));
        assert!(!s.contains("standard_route"), "{s}");
        // Braces keep Tcl from substituting the bus brackets.
        assert!(s.contains("set eco_nets [list {a} {y[0][5]}]"), "{s}");
        assert_eq!(s.matches("read_def").count(), 1);
        // Stage 1 only: other nets are blockages (stage 2 may route across a net it
        // then cannot rip up, a read-in route: a short).
        // One net at a time: removed, then routed, the others' routes in place.
        assert!(
            s.contains("remove net $n\n  set r [stage1 route $n]"),
            "{s}"
        );
        assert!(!s.contains("stage2"), "{s}");
        assert!(s.ends_with(
            "write_def tofprobe_pixel_eco.def\nwrite_delays tofprobe_pixel_eco.rc\nquit\n"
        ));
        assert_eq!(eco_failing("ECO route a: 0\nECO failing: 2\n"), Some(2));
        assert_eq!(eco_failing("Final: No failed routes!\n"), None);
        let changed = eco_changed("Ripping up blocking net b\n", &set(&["a"]));
        assert_eq!(changed, set(&["a", "b"]));
    }

    #[test]
    fn the_splice_takes_only_the_repaired_nets_from_the_eco_def() {
        // qrouter's ECO DEF: y[0][5] re-routed (no stub now), `far` written back in pieces.
        let eco = "UNITS DISTANCE MICRONS 100 ;\nNETS 2 ;\n- far\n  ( INVX1_1 Y ) ( INVX1_2 A ) \n\
+ ROUTED metal2 ( 10000 10000 ) ( * 11000 ) \n  NEW metal2 ( 10000 11000 ) ( * 12000 ) ;\n\
- y[0][5]\n  ( DFFPOSX1_198 Q ) \n+ ROUTED metal1 ( 37760 34400 ) ( 37920 * ) M2_M1 ;\nEND NETS\n\
SPECIALNETS 1 ;\n- vdd\n+ ROUTED metal1 240 ( 0 0 ) ( 90000 * ) ;\nEND SPECIALNETS\n";
        let out = splice_def(DEF, eco, &set(&["y[0][5]"])).unwrap();
        assert!(out.contains("- y[0][5]\n  ( DFFPOSX1_198 Q ) \n+ ROUTED metal1 ( 37760 34400 ) ( 37920 * ) M2_M1 ;\n- y[9][37]"));
        assert!(!out.contains("( 37600 34755 )"), "the old route is gone");
        // `far` stays as it was, in one piece; the old stub of y[0][5] is dropped.
        assert!(out.contains("+ ROUTED metal2 ( 10000 10000 ) ( * 12000 ) ;"));
        assert!(out.contains("SPECIALNETS 1 ;\n- vdd\n") && !out.contains("37600 34740"));
        assert!(out.ends_with("END SPECIALNETS\nEND DESIGN\n"));
        // Nothing repaired: the DEF comes back line for line.
        assert_eq!(splice_def(DEF, eco, &set(&[])).unwrap(), DEF);
        // An ECO file without a NETS section is not spliced.
        assert!(splice_def(DEF, "garbage", &set(&["far"])).is_none());

        let rc = splice_rc(
            "a 1 X/Y 1 ( 2 3 P/A )\nb 1 Q/Y 0\n",
            "a 1 X/Y 1 ( 9 9 P/A )\nb 9\n",
            &set(&["a"]),
        );
        assert_eq!(rc, "a 1 X/Y 1 ( 9 9 P/A )\nb 1 Q/Y 0\n");
        assert_eq!(
            lvs_total("Total errors = 2\nDesign fails LVS with 2 errors.\n"),
            Some(2)
        );
    }
}
