//! The macro's boundary: every shape inside the die, so macros abut without overlapping.
//!
//! qflow's placement puts the die's edges on routing tracks and the pins on those edges,
//! and qrouter routes on the edge tracks and one beyond (the 2-bin pixel on osu018: 101
//! metal shapes up to 1.1 µm past the die, `rd_data[14]` jogging along y = 364.0 µm above a
//! 363.0 µm edge). Three steps keep the shapes in:
//!
//! - [`keep_out`]: router obstructions on every routing layer beyond the edge tracks
//!   (from half a pitch past each edge), so no wire leaves the outermost tracks;
//! - [`grow_die`]: the routed die grown by one track pitch on each side (the wires and vias
//!   on the edge tracks reach half a width or a via pad beyond them), each pin near an edge
//!   extended to the new edge, so the pins stay on the macro's boundary;
//! - [`crate::boundary::outside_die`]: every shape of the DEF (cells, pins, wires, vias,
//!   power stripes) measured against the die, reported (the GDS by `crate::gds`).

use crate::error::{LayoutError, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A rectangle (DEF units or µm, as the caller says).
pub type Rect = (f64, f64, f64, f64);

/// How far beyond the die (µm) the keep-out strips reach: past any track qrouter builds.
const KEEP_OUT_REACH_UM: f64 = 10.0;

/// The die, the track pitches and the routing layers of a DEF (DEF units).
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// DEF units per µm.
    pub units: f64,
    /// DIEAREA.
    pub die: Rect,
    /// The smallest track pitch across x (vertical tracks) and across y.
    pub pitch: (f64, f64),
    /// The layers with tracks, in order of first appearance.
    pub layers: Vec<String>,
}

/// Reads the DEF's UNITS, DIEAREA and TRACKS.
pub fn frame(def: &str, path: &Path) -> Result<Frame> {
    let bad = |what: &str| LayoutError::Parse {
        tool: "qflow (DEF)",
        what: what.into(),
        path: path.to_path_buf(),
    };
    let (mut units, mut die) = (None, None);
    let (mut px, mut py) = (f64::MAX, f64::MAX);
    let mut layers: Vec<String> = Vec::new();
    for line in def.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["UNITS", "DISTANCE", "MICRONS", u, ..] => units = u.parse::<f64>().ok(),
            ["DIEAREA", "(", a, b, ")", "(", c, d, ..] => {
                let v: Vec<f64> = [a, b, c, d].iter().filter_map(|s| s.parse().ok()).collect();
                if v.len() == 4 {
                    die = Some((v[0], v[1], v[2], v[3]));
                }
            }
            ["TRACKS", axis, _, "DO", _, "STEP", step, "LAYER", layer, ..] => {
                let Ok(step) = step.parse::<f64>() else {
                    continue;
                };
                if *axis == "X" {
                    px = px.min(step);
                } else {
                    py = py.min(step);
                }
                if !layers.iter().any(|l| l == layer) {
                    layers.push(layer.to_string());
                }
            }
            ["COMPONENTS", ..] => break,
            _ => {}
        }
    }
    let units = units.ok_or_else(|| bad("`UNITS DISTANCE MICRONS`"))?;
    let die = die.ok_or_else(|| bad("`DIEAREA ( x y ) ( x y )`"))?;
    if px == f64::MAX || py == f64::MAX {
        return Err(bad("`TRACKS X …` and `TRACKS Y …`"));
    }
    Ok(Frame {
        units,
        die,
        pitch: (px, py),
        layers,
    })
}

/// qrouter `obstruction` lines (µm) on every routing layer beyond the die's edge tracks:
/// four strips from half a pitch past each edge outwards.
pub fn keep_out(f: &Frame) -> Vec<String> {
    let u = f.units;
    let (x0, y0, x1, y1) = (f.die.0 / u, f.die.1 / u, f.die.2 / u, f.die.3 / u);
    let (hx, hy) = (f.pitch.0 / u / 2.0, f.pitch.1 / u / 2.0);
    let r = KEEP_OUT_REACH_UM;
    let strips = [
        (x0 - r, y1 + hy, x1 + r, y1 + r),
        (x0 - r, y0 - r, x1 + r, y0 - hy),
        (x0 - r, y0 - r, x0 - hx, y1 + r),
        (x1 + hx, y0 - r, x1 + r, y1 + r),
    ];
    let mut out = Vec::new();
    for l in &f.layers {
        for (a, b, c, d) in strips {
            out.push(format!("obstruction {a:.3} {b:.3} {c:.3} {d:.3} {l}"));
        }
    }
    out
}

/// qflow's router configuration with `lines` inserted before its `read_def` (qrouter
/// applies obstructions when it reads the DEF); `None` when it has no `read_def`.
pub fn with_keep_out(cfg: &str, lines: &[String]) -> Option<String> {
    let at = cfg
        .lines()
        .position(|l| l.trim_start().starts_with("read_def"))?;
    let mut out = String::new();
    for (i, l) in cfg.lines().enumerate() {
        if i == at {
            out += "# tofprobe: keep the routes on the die's tracks (crate::die)\n";
            for k in lines {
                out += k;
                out.push('\n');
            }
        }
        out += l;
        out.push('\n');
    }
    Some(out)
}

/// How [`grow_die`] changed the DEF.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Growth {
    /// The margin added on the left and right (µm): one track pitch across x.
    pub margin_x_um: f64,
    /// The margin added at the bottom and top (µm): one track pitch across y.
    pub margin_y_um: f64,
    /// Pins extended to the new edge.
    pub pins_extended: usize,
}

/// The DEF with its die grown by one track pitch on each side and every pin within a pitch
/// of an edge extended to the new edge (re-written in orientation N, its shapes relative to
/// its placement), so the wires and vias on the edge tracks lie inside and the pins on the
/// boundary.
pub fn grow_die(def: &str, path: &Path) -> Result<(String, Growth)> {
    let f = frame(def, path)?;
    let (mx, my) = f.pitch;
    let (x0, y0, x1, y1) = f.die;
    let new = (x0 - mx, y0 - my, x1 + mx, y1 + my);
    let mut out = String::with_capacity(def.len() + 4096);
    let mut pins_extended = 0;
    let mut in_pins = false;
    let mut entry: Vec<String> = Vec::new();
    for line in def.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["DIEAREA", ..] => {
                out += &format!(
                    "DIEAREA ( {} {} ) ( {} {} ) ;\n",
                    fmt(new.0),
                    fmt(new.1),
                    fmt(new.2),
                    fmt(new.3)
                );
                continue;
            }
            ["PINS", ..] => in_pins = true,
            ["END", "PINS"] => in_pins = false,
            _ => {}
        }
        if !in_pins || t.first() == Some(&"PINS") {
            out += line;
            out.push('\n');
            continue;
        }
        entry.extend(t.iter().map(|s| s.to_string()));
        if t.last() == Some(&";") {
            let (text, extended) = grow_pin(&entry, (x0, y0, x1, y1), new, (mx, my));
            pins_extended += usize::from(extended);
            out += &text;
            entry.clear();
        }
    }
    let u = f.units;
    Ok((
        out,
        Growth {
            margin_x_um: mx / u,
            margin_y_um: my / u,
            pins_extended,
        },
    ))
}

/// A DEF number as qflow writes it (integers without a fraction).
fn fmt(v: f64) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v}")
    }
}

/// One PINS entry's words: each `LAYER l ( a b ) ( c d )` shape made absolute, extended to
/// the new die edge when within a pitch of the old one, re-written relative to the
/// placement in orientation N. Returns the entry's text and whether a shape was extended.
fn grow_pin(words: &[String], old: Rect, new: Rect, pitch: (f64, f64)) -> (String, bool) {
    let num = |i: usize| words.get(i).and_then(|w| w.parse::<f64>().ok());
    let placed = words
        .iter()
        .position(|w| w == "PLACED" || w == "FIXED")
        .and_then(|i| Some((i, num(i + 2)?, num(i + 3)?, words.get(i + 5)?.clone())));
    let Some((pi, px, py, orient)) = placed else {
        return (format!("{}\n", words.join(" ")), false);
    };
    let mut w: Vec<String> = words.to_vec();
    let mut extended = false;
    for i in 0..w.len() {
        if w[i] != "LAYER" {
            continue;
        }
        let (Some(a), Some(b), Some(c), Some(d)) = (num(i + 3), num(i + 4), num(i + 7), num(i + 8))
        else {
            continue;
        };
        let r = orient_rect((a, b, c, d), &orient);
        let mut abs = (px + r.0, py + r.1, px + r.2, py + r.3);
        if abs.0 - old.0 <= pitch.0 {
            abs.0 = new.0;
            extended = true;
        }
        if old.2 - abs.2 <= pitch.0 {
            abs.2 = new.2;
            extended = true;
        }
        if abs.1 - old.1 <= pitch.1 {
            abs.1 = new.1;
            extended = true;
        }
        if old.3 - abs.3 <= pitch.1 {
            abs.3 = new.3;
            extended = true;
        }
        w[i + 3] = fmt(abs.0 - px);
        w[i + 4] = fmt(abs.1 - py);
        w[i + 7] = fmt(abs.2 - px);
        w[i + 8] = fmt(abs.3 - py);
    }
    w[pi + 5] = "N".into();
    let mut text = String::new();
    for (i, word) in w.iter().enumerate() {
        // `- NAME + NET n` stays on one line, as qflow writes it; each other item its own.
        if word == "+" && i > 2 {
            text += "\n  +";
        } else {
            if i > 0 {
                text.push(' ');
            }
            text += word;
        }
    }
    (format!("{}\n", text.trim_start()), extended)
}

/// A rectangle in a placement's frame for a DEF orientation (about the placement point).
pub(crate) fn orient_rect(r: Rect, orient: &str) -> Rect {
    let pts = [(r.0, r.1), (r.2, r.3)].map(|(x, y)| match orient {
        "S" => (-x, -y),
        "E" => (y, -x),
        "W" => (-y, x),
        "FN" => (-x, y),
        "FS" => (x, -y),
        "FE" => (y, x),
        "FW" => (-y, -x),
        _ => (x, y),
    });
    (
        pts[0].0.min(pts[1].0),
        pts[0].1.min(pts[1].1),
        pts[0].0.max(pts[1].0),
        pts[0].1.max(pts[1].1),
    )
}

#[cfg(test)]
#[path = "die_tests.rs"]
mod tests;
