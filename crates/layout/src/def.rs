//! What the routed DEF and the cell LEF say about the macro: die and core area, cell area
//! and utilisation, routed wirelength, and the cell sizes of the LEF (also the check that
//! every cell the netlist uses has a layout view).

use crate::error::{LayoutError, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Cell outlines of a LEF (read in `tofprobe_eda::lef`, which the liberty's LEF areas use too).
pub use tofprobe_eda::lef::lef_sizes;

/// The figures of a routed DEF.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct DefFigures {
    /// Die width (µm).
    pub die_width_um: f64,
    /// Die height (µm).
    pub die_height_um: f64,
    /// Core: the bounding box of the placed cells (µm × µm).
    pub core_width_um: f64,
    /// Core height (µm).
    pub core_height_um: f64,
    /// Area of the logic cells (fill cells excluded), from the LEF outlines (µm²).
    pub cell_area_um2: f64,
    /// Logic cells placed.
    pub cells: u64,
    /// Fill cells placed.
    pub fill_cells: u64,
    /// Routed signal wirelength (µm): the Manhattan length of every ROUTED/NEW segment of
    /// the NETS section (power stripes are SPECIALNETS, not counted).
    pub wirelength_um: f64,
}

impl DefFigures {
    /// Die area (µm²).
    pub fn die_area_um2(&self) -> f64 {
        self.die_width_um * self.die_height_um
    }
    /// Core area (µm²).
    pub fn core_area_um2(&self) -> f64 {
        self.core_width_um * self.core_height_um
    }
    /// Cell area / core area.
    pub fn utilisation(&self) -> f64 {
        self.cell_area_um2 / self.core_area_um2()
    }
}

/// Parses a routed DEF against the cell outlines `sizes`; `fill` is the fill cell's name.
pub fn parse_def(
    text: &str,
    sizes: &BTreeMap<String, (f64, f64)>,
    fill: &str,
    path: &Path,
) -> Result<DefFigures> {
    let bad = |what: &str| LayoutError::Parse {
        tool: "qflow (DEF)",
        what: what.to_string(),
        path: path.to_path_buf(),
    };
    let mut units = None;
    let mut die = None;
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    let (mut cell_area, mut cells, mut fills) = (0.0, 0u64, 0u64);
    let mut wire = 0.0;
    let mut section = "";
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["UNITS", "DISTANCE", "MICRONS", u, ..] => units = u.parse::<f64>().ok(),
            ["DIEAREA", "(", a, b, ")", "(", c, d, ..] => {
                let v: Vec<f64> = [a, b, c, d].iter().filter_map(|s| s.parse().ok()).collect();
                if v.len() == 4 {
                    die = Some((v[2] - v[0], v[3] - v[1]));
                }
            }
            ["COMPONENTS", ..] => section = "components",
            ["NETS", ..] => section = "nets",
            ["SPECIALNETS", ..] | ["PINS", ..] => section = "",
            ["END", "COMPONENTS" | "NETS"] => section = "",
            _ => {}
        }
        if section == "components" && t.first() == Some(&"-") {
            // - NAME CELL + PLACED ( x y ) ORIENT ;
            let (Some(cell), Some(i)) = (t.get(2), t.iter().position(|s| *s == "(")) else {
                continue;
            };
            let (Some(x), Some(y)) = (
                t.get(i + 1).and_then(|v| v.parse::<f64>().ok()),
                t.get(i + 2).and_then(|v| v.parse::<f64>().ok()),
            ) else {
                continue;
            };
            let &(w, h) = sizes
                .get(*cell)
                .ok_or_else(|| bad(&format!("a LEF outline for cell `{cell}`")))?;
            let orient = t.get(i + 4).copied().unwrap_or("N");
            let (w, h) = if orient.contains('E') || orient.contains('W') {
                (h, w)
            } else {
                (w, h)
            };
            let u = units.ok_or_else(|| bad("`UNITS DISTANCE MICRONS` before COMPONENTS"))?;
            let (x, y) = (x / u, y / u);
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x + w);
            y1 = y1.max(y + h);
            if *cell == fill {
                fills += 1;
            } else {
                cells += 1;
                cell_area += w * h;
            }
        }
        if section == "nets" && (t.contains(&"ROUTED") || t.contains(&"NEW")) {
            wire += segment_length(&t);
        }
    }
    let u = units.ok_or_else(|| bad("`UNITS DISTANCE MICRONS`"))?;
    let (dw, dh) = die.ok_or_else(|| bad("`DIEAREA ( x y ) ( x y )`"))?;
    if cells == 0 {
        return Err(bad("placed cells in COMPONENTS"));
    }
    Ok(DefFigures {
        die_width_um: dw / u,
        die_height_um: dh / u,
        core_width_um: x1 - x0,
        core_height_um: y1 - y0,
        cell_area_um2: cell_area,
        cells,
        fill_cells: fills,
        wirelength_um: wire / u,
    })
}

/// One item of a routed segment, in order: a point `( x y )` (DEF units, a `*` coordinate
/// taken from the previous point) or any other word (a via name, a width, `;`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RouteItem<'a> {
    /// A point.
    Point(f64, f64),
    /// Another word.
    Word(&'a str),
}

/// The items of one routed segment's words `( x y ) ( x * ) VIA …` (a point whose
/// coordinates cannot be read is skipped).
pub(crate) fn route_items<'a>(t: &[&'a str]) -> Vec<RouteItem<'a>> {
    let mut out = Vec::new();
    let mut last: Option<(f64, f64)> = None;
    let mut i = 0;
    while i < t.len() {
        if t[i] == "(" && i + 3 < t.len() && t[i + 3] == ")" {
            let coord = |s: &str, prev: Option<f64>| {
                if s == "*" {
                    prev
                } else {
                    s.parse::<f64>().ok()
                }
            };
            let x = coord(t[i + 1], last.map(|p| p.0));
            let y = coord(t[i + 2], last.map(|p| p.1));
            if let (Some(x), Some(y)) = (x, y) {
                out.push(RouteItem::Point(x, y));
                last = Some((x, y));
            }
            i += 4;
        } else {
            out.push(RouteItem::Word(t[i]));
            i += 1;
        }
    }
    out
}

/// The Manhattan length (DEF units) of one routed segment's points `( x y ) ( x * ) …`.
fn segment_length(t: &[&str]) -> f64 {
    let mut last: Option<(f64, f64)> = None;
    let mut len = 0.0;
    for item in route_items(t) {
        if let RouteItem::Point(x, y) = item {
            if let Some((px, py)) = last {
                len += (x - px).abs() + (y - py).abs();
            }
            last = Some((x, y));
        }
    }
    len
}

/// One DEF section's declared count (`NETS 2702 ;`) and the entries it lists.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SectionCount {
    /// The section (`SPECIALNETS`).
    pub section: String,
    /// The count its header declares.
    pub declared: u64,
    /// The entries (`- NAME …`) it lists.
    pub listed: u64,
}

/// Every counted section of a DEF (a header `NAME N ;` closed by `END NAME`) with its
/// declared and listed counts.
pub fn section_counts(text: &str) -> Vec<SectionCount> {
    let mut out: Vec<SectionCount> = Vec::new();
    let mut open: Option<usize> = None;
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if let Some(i) = open {
            if t.as_slice() == ["END", out[i].section.as_str()] {
                open = None;
            } else if t.first() == Some(&"-") {
                out[i].listed += 1;
            }
            continue;
        }
        if let [name, n, ";"] = t.as_slice()
            && name.chars().all(|c| c.is_ascii_uppercase())
            && let Ok(declared) = n.parse::<u64>()
        {
            out.push(SectionCount {
                section: name.to_string(),
                declared,
                listed: 0,
            });
            open = Some(out.len() - 1);
        }
    }
    out
}

/// The DEF with every section's declared count set to the entries it lists. qrouter 1.4
/// declares its routed DEF's SPECIALNETS as the nets it wrote plus the input's special
/// nets, which it had written among them (the 2-bin pixel: 359 declared, 357 listed).
pub fn fix_counts(text: &str) -> String {
    let counts = section_counts(text);
    let mut out = String::with_capacity(text.len());
    let mut next = counts.iter();
    let mut want = next.next();
    for line in text.lines() {
        if let Some(c) = want {
            let t: Vec<&str> = line.split_whitespace().collect();
            if t.len() == 3 && t[0] == c.section && t[2] == ";" && t[1].parse::<u64>().is_ok() {
                out += &format!("{} {} ;\n", c.section, c.listed);
                want = next.next();
                continue;
            }
        }
        out += line;
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const LEF: &str = "MACRO INVX1\n  SIZE 2.4 BY 10.0 ;\nEND INVX1\nMACRO FILL\n  SIZE 0.8 BY 10.000 ;\nEND FILL\n";

    #[test]
    fn figures_of_a_small_def() {
        let sizes = lef_sizes(LEF);
        assert_eq!(sizes["INVX1"], (2.4, 10.0));
        let def = "UNITS DISTANCE MICRONS 100 ;\nDIEAREA ( -320 -300 ) ( 1680 2300 ) ;\n\
                   COMPONENTS 3 ;\n- a INVX1 + PLACED ( 0 0 ) N ;\n- b INVX1 + PLACED ( 240 1000 ) FS ;\n\
                   - f FILL + PLACED ( 480 1000 ) N ;\nEND COMPONENTS\nNETS 1 ;\n- n ( a Y ) ( b A )\n\
                   + ROUTED metal1 ( 100 500 ) ( 900 * ) M2_M1\n  NEW metal2 ( 900 500 ) ( * 1500 ) ;\nEND NETS\n\
                   SPECIALNETS 1 ;\n- vdd + ROUTED metal4 120 ( 0 0 ) ( 0 9000 ) ;\nEND SPECIALNETS\n";
        let f = parse_def(def, &sizes, "FILL", Path::new("x.def")).unwrap();
        assert_eq!((f.die_width_um, f.die_height_um), (20.0, 26.0));
        // Cells span x 0 … 4.8 + 0.8 = 5.6, y 0 … 20.
        assert!((f.core_width_um - 5.6).abs() < 1e-12 && (f.core_height_um - 20.0).abs() < 1e-12);
        assert_eq!((f.cells, f.fill_cells), (2, 1));
        assert!((f.cell_area_um2 - 48.0).abs() < 1e-12);
        assert!((f.utilisation() - 48.0 / 112.0).abs() < 1e-12);
        // 800 + 1000 DEF units; the power stripe is not a signal wire.
        assert!(
            (f.wirelength_um - 18.0).abs() < 1e-12,
            "{}",
            f.wirelength_um
        );
    }

    #[test]
    fn a_cell_without_a_lef_outline_is_named() {
        let def = "UNITS DISTANCE MICRONS 100 ;\nDIEAREA ( 0 0 ) ( 10 10 ) ;\nCOMPONENTS 1 ;\n\
                   - a NAND9 + PLACED ( 0 0 ) N ;\nEND COMPONENTS\n";
        let e = parse_def(def, &lef_sizes(LEF), "FILL", Path::new("x.def")).unwrap_err();
        assert!(e.to_string().contains("`NAND9`"), "{e}");
    }

    #[test]
    fn declared_counts_are_set_to_the_entries_listed() {
        // The 2-bin pixel's routed DEF as qrouter wrote it: SPECIALNETS declared 359 and
        // listed 357 (shortened here to 3 declared, 2 listed, with an empty entry).
        let def = "VERSION 5.6 ;\nPINS 1 ;\n- clk + NET clk\n  + LAYER metal2 ( -15 -15 ) ( 15 15 )\n  + PLACED ( 0 0 ) N ;\nEND PINS\n\
                   NETS 1 ;\n- clk\n  ( PIN clk )\n+ ROUTED metal2 ( 0 0 ) ( 0 100 ) ;\nEND NETS\n\
                   SPECIALNETS 3 ;\n- clk_bF$buf50\n;\n- vdd\n+ FIXED metal1 40 ( 0 0 ) ( 100 0 ) ;\nEND SPECIALNETS\nEND DESIGN\n";
        let before = section_counts(def);
        assert_eq!(
            before
                .iter()
                .map(|c| (c.section.as_str(), c.declared, c.listed))
                .collect::<Vec<_>>(),
            vec![("PINS", 1, 1), ("NETS", 1, 1), ("SPECIALNETS", 3, 2)]
        );
        let fixed = fix_counts(def);
        assert!(fixed.contains("SPECIALNETS 2 ;\n"), "{fixed}");
        assert!(
            section_counts(&fixed)
                .iter()
                .all(|c| c.declared == c.listed)
        );
        // Nothing else changed.
        assert_eq!(fixed.replace("SPECIALNETS 2 ;", "SPECIALNETS 3 ;"), def);
    }
}
