//! Every shape of a routed DEF measured against its die (`crate::die` keeps them in):
//! placed cells, pins, regular wires, vias and special wires, with the routing layers'
//! widths and the vias' shapes read from the technology LEF and the DEF's own VIAS.

use crate::def::{RouteItem, route_items};
use crate::die::{Rect, frame, orient_rect};
use crate::error::Result;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Routing layer widths and via shapes (µm) of the technology LEF (and the DEF's own VIAS).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Geometry {
    /// `LAYER l … WIDTH w` of each routing layer.
    pub widths: BTreeMap<String, f64>,
    /// Each via's rectangles (relative to its point).
    pub vias: BTreeMap<String, Vec<Rect>>,
}

impl Geometry {
    /// Reads `LAYER … TYPE ROUTING … WIDTH` and `VIA name … RECT` of LEF texts.
    pub fn from_lef(texts: &[&str]) -> Geometry {
        let mut g = Geometry::default();
        for text in texts {
            let (mut layer, mut via): (Option<String>, Option<String>) = (None, None);
            for line in text.lines() {
                let t: Vec<&str> = line.split_whitespace().collect();
                match t.as_slice() {
                    ["LAYER", name] | ["LAYER", name, ..] if via.is_none() => {
                        layer = Some(name.trim_end_matches(';').to_string());
                    }
                    ["VIA", name, ..] => via = Some(name.to_string()),
                    ["WIDTH", w, ..] if via.is_none() => {
                        if let (Some(l), Ok(w)) = (&layer, w.trim_end_matches(';').parse()) {
                            g.widths.entry(l.clone()).or_insert(w);
                        }
                    }
                    ["RECT", a, b, c, d, ..] => {
                        let v: Vec<f64> = [a, b, c, d]
                            .iter()
                            .filter_map(|s| s.trim_end_matches(';').parse().ok())
                            .collect();
                        if let (Some(name), 4) = (&via, v.len()) {
                            g.vias
                                .entry(name.clone())
                                .or_default()
                                .push((v[0], v[1], v[2], v[3]));
                        }
                    }
                    ["END", name] => {
                        if via.as_deref() == Some(*name) {
                            via = None;
                        } else if layer.as_deref() == Some(*name) {
                            layer = None;
                        }
                    }
                    _ => {}
                }
            }
        }
        g
    }
}

/// The shapes of a DEF that lie (partly) outside its die.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Outside {
    /// Shapes checked.
    pub shapes: u64,
    /// Shapes reaching past the die.
    pub outside: u64,
    /// The furthest any reaches past it (µm; 0 when none does).
    pub worst_um: f64,
    /// The first few, named (`net rd_data[14] metal2 …`).
    pub examples: Vec<String>,
}

/// Every shape of the DEF measured against its die: placed cells (outlines from `sizes`),
/// pins, regular wires (± half the layer's width, ends extended by it, as DEF draws them),
/// vias (their LEF or DEF rectangles), and special wires (± half their stated width, ends
/// not extended).
pub fn outside_die(
    def: &str,
    g: &Geometry,
    sizes: &BTreeMap<String, (f64, f64)>,
    path: &Path,
) -> Result<Outside> {
    let f = frame(def, path)?;
    let u = f.units;
    let die = (f.die.0 / u, f.die.1 / u, f.die.2 / u, f.die.3 / u);
    let mut vias = g.vias.clone();
    vias.extend(def_vias(def, u));
    let mut o = Outside::default();
    let mut check = |what: &dyn Fn() -> String, r: Rect| {
        o.shapes += 1;
        // 1e-6 µm: DEF coordinates are integers of 1/units µm.
        let over = (die.0 - r.0)
            .max(die.1 - r.1)
            .max(r.2 - die.2)
            .max(r.3 - die.3);
        if over > 1e-6 {
            o.outside += 1;
            o.worst_um = o.worst_um.max(over);
            if o.examples.len() < 5 {
                o.examples.push(format!(
                    "{} ({:.3}, {:.3})–({:.3}, {:.3}) µm, {over:.3} µm out",
                    what(),
                    r.0,
                    r.1,
                    r.2,
                    r.3
                ));
            }
        }
    };
    let mut section = "";
    let mut name = String::new();
    let mut entry: Vec<String> = Vec::new();
    for line in def.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            [s @ ("COMPONENTS" | "PINS" | "NETS" | "SPECIALNETS"), _, ..] => {
                section = s;
                continue;
            }
            ["END", _] => {
                section = "";
                continue;
            }
            _ => {}
        }
        if t.first() == Some(&"-")
            && let Some(n) = t.get(1)
        {
            name = n.to_string();
        }
        match section {
            "COMPONENTS" | "PINS" => {
                entry.extend(t.iter().map(|s| s.to_string()));
                if t.last() == Some(&";") {
                    for (what, r) in placed_shapes(&entry, section, sizes, u) {
                        check(&|| format!("{what} {name}"), scale(r, 1.0 / u));
                    }
                    entry.clear();
                }
            }
            "NETS" | "SPECIALNETS" => {
                let special = section == "SPECIALNETS";
                let Some(r) = t
                    .iter()
                    .position(|w| matches!(*w, "ROUTED" | "NEW" | "FIXED"))
                else {
                    continue;
                };
                let Some(layer) = t.get(r + 1) else { continue };
                let mut rest = &t[r + 2..];
                let half = if special {
                    let w = rest
                        .first()
                        .and_then(|w| w.parse::<f64>().ok())
                        .unwrap_or(0.0);
                    rest = &rest[1..];
                    w / u / 2.0
                } else {
                    g.widths.get(*layer).copied().unwrap_or(0.0) / 2.0
                };
                let mut last: Option<(f64, f64)> = None;
                for item in route_items(rest) {
                    match item {
                        RouteItem::Point(x, y) => {
                            let (x, y) = (x / u, y / u);
                            if let Some((px, py)) = last {
                                let (a, b, c, d) = (px.min(x), py.min(y), px.max(x), py.max(y));
                                // Special wires: no end extension, half the width across.
                                let r = if !special {
                                    (a - half, b - half, c + half, d + half)
                                } else if a == c {
                                    (a - half, b, c + half, d)
                                } else {
                                    (a, b - half, c, d + half)
                                };
                                check(&|| format!("{section} {name} {layer}"), r);
                            }
                            last = Some((x, y));
                        }
                        RouteItem::Word(v) => {
                            if let (Some((x, y)), Some(rects)) = (last, vias.get(v)) {
                                for r in rects {
                                    check(
                                        &|| format!("{section} {name} via {v}"),
                                        (x + r.0, y + r.1, x + r.2, y + r.3),
                                    );
                                }
                            }
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(o)
}

/// A rectangle scaled by `k`.
fn scale(r: Rect, k: f64) -> Rect {
    (r.0 * k, r.1 * k, r.2 * k, r.3 * k)
}

/// The absolute shapes (DEF units) of a COMPONENTS or PINS entry: a cell's outline (its
/// LEF size in µm times `units`), or each of a pin's LAYER rectangles.
fn placed_shapes(
    words: &[String],
    section: &str,
    sizes: &BTreeMap<String, (f64, f64)>,
    units: f64,
) -> Vec<(String, Rect)> {
    let num = |i: usize| words.get(i).and_then(|w| w.parse::<f64>().ok());
    let Some((px, py, orient)) = words
        .iter()
        .position(|w| w == "PLACED" || w == "FIXED")
        .and_then(|i| Some((num(i + 2)?, num(i + 3)?, words.get(i + 5)?.as_str())))
    else {
        return vec![];
    };
    if section == "COMPONENTS" {
        let Some(&(w, h)) = words.get(2).and_then(|c| sizes.get(c)) else {
            return vec![];
        };
        let (w, h) = if matches!(orient, "E" | "W" | "FE" | "FW") {
            (h, w)
        } else {
            (w, h)
        };
        return vec![(
            format!("cell {}", words[2]),
            (px, py, px + w * units, py + h * units),
        )];
    }
    let mut out = Vec::new();
    for (i, w) in words.iter().enumerate() {
        if w != "LAYER" {
            continue;
        }
        if let (Some(a), Some(b), Some(c), Some(d)) =
            (num(i + 3), num(i + 4), num(i + 7), num(i + 8))
        {
            let r = orient_rect((a, b, c, d), orient);
            out.push((
                format!("pin on {}", words[i + 1]),
                (px + r.0, py + r.1, px + r.2, py + r.3),
            ));
        }
    }
    out
}

/// The DEF's own VIAS (`- name + RECT layer ( a b ) ( c d ) …`), in µm.
fn def_vias(def: &str, units: f64) -> BTreeMap<String, Vec<Rect>> {
    let mut out: BTreeMap<String, Vec<Rect>> = BTreeMap::new();
    let (Some(a), Some(b)) = (def.find("\nVIAS "), def.find("\nEND VIAS")) else {
        return out;
    };
    if b < a {
        return out;
    }
    let mut name = String::new();
    for line in def[a..b].lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.first() == Some(&"-")
            && let Some(n) = t.get(1)
        {
            name = n.to_string();
        }
        if let Some(i) = t.iter().position(|w| *w == "RECT") {
            let v: Vec<f64> = [i + 3, i + 4, i + 7, i + 8]
                .iter()
                .filter_map(|&k| t.get(k)?.parse().ok())
                .collect();
            if v.len() == 4 {
                out.entry(name.clone())
                    .or_default()
                    .push(scale((v[0], v[1], v[2], v[3]), 1.0 / units));
            }
        }
    }
    out
}
