//! What the checks and the routed DEF say about the nets: the nets at magic's DRC error
//! boxes ([`crate::qflow::DrcBox`]), the DEF's wires, vias and pins, the nets at each box and netgen's unmatched nets.

use crate::def::{RouteItem, route_items};
use crate::qflow::DrcBox;
use std::collections::{BTreeMap, BTreeSet};

/// How near (µm) a wire's centre line must come to a DRC error box for its net to be
/// re-routed: half a wire's width plus the minimum spacing (osu018 metal 1–5: 0.15 +
/// 0.3 µm), so the nets whose metal lies on the box or within a spacing of it. A box with
/// no net that near (a via pad, a wider wire) takes the nets within [`FAR_UM`].
pub const NEAR_UM: f64 = 0.45;

/// The fallback distance for a box with no net within [`NEAR_UM`].
pub const FAR_UM: f64 = 1.0;

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
        for item in route_items(&t[r + 2..]) {
            match item {
                RouteItem::Point(x, y) => {
                    let (x, y) = (x / units, y / units);
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
                // A via name after a point (a width or `;` is not a via).
                RouteItem::Word(w) => {
                    if let Some((x, y)) = last
                        && w != ";"
                        && w.parse::<f64>().is_err()
                        && w != "+"
                    {
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
                }
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
