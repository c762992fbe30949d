//! What the GDS holds, read back by klayout: its cells and which of them are empty (a
//! reference with no layout: osu018's cells, whose package ships LEF abstracts and no
//! GDS), and every shape of the top cell's hierarchy measured against the die.

use crate::error::{LayoutError, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// klayout's Python macro: `gds` and the die (`x0 y0 x1 y1`, µm) come from `-rd`.
pub const SCRIPT: &str = "import pya
ly = pya.Layout()
ly.read(gds)
top = ly.top_cell()
dbu = ly.dbu
die = pya.Box(*[int(round(float(v) / dbu)) for v in (x0, y0, x1, y1)])
shapes = outside = worst = 0
for li in ly.layer_indexes():
    it = top.begin_shapes_rec(li)
    while not it.at_end():
        b = it.shape().bbox().transformed(it.trans())
        shapes += 1
        over = max(die.left - b.left, die.bottom - b.bottom, b.right - die.right, b.top - die.top)
        if over > 0:
            outside += 1
            worst = max(worst, over)
        it.next()
print('TOFPROBE-GDS top %s' % top.name)
print('TOFPROBE-GDS shapes %d' % shapes)
print('TOFPROBE-GDS outside %d' % outside)
print('TOFPROBE-GDS worst %.4f' % (worst * dbu))
for c in ly.each_cell():
    if c.cell_index() != top.cell_index():
        print('TOFPROBE-GDS cell %s %d' % (c.name, 1 if (c.is_empty() or c.is_ghost_cell()) else 0))
";

/// The GDS as klayout reads it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GdsFigures {
    /// The top cell.
    pub top: String,
    /// Cells below the top (the standard cells used).
    pub cells: u64,
    /// Of them, those with no layout (an empty or undefined reference).
    pub empty_cells: u64,
    /// The first few empty cells' names.
    pub empty_examples: Vec<String>,
    /// Shapes in the top cell's hierarchy.
    pub shapes: u64,
    /// Of them, reaching past the die.
    pub outside: u64,
    /// The furthest past the die (µm).
    pub worst_um: f64,
}

impl GdsFigures {
    /// Whether the stream stands alone: every cell it uses has its layout in it.
    pub fn standalone(&self) -> bool {
        self.cells > 0 && self.empty_cells == 0
    }

    /// What the stream holds, in words (the report's line).
    pub fn holds(&self) -> String {
        if self.standalone() {
            format!(
                "routing, pins and the layouts of all {} cells: a standalone stream",
                self.cells
            )
        } else {
            format!(
                "routing and pins only: {} of its {} cells are empty references (e.g. {}; the technology ships no cell GDS), so it is not a standalone stream and no foundry or klayout DRC of the cells can run on it",
                self.empty_cells,
                self.cells,
                self.empty_examples.join(", ")
            )
        }
    }
}

/// Parses the script's `TOFPROBE-GDS` lines.
pub fn parse(text: &str, path: &Path) -> Result<GdsFigures> {
    let mut g = GdsFigures::default();
    let mut seen = 0;
    for line in text.lines() {
        let Some(rest) = line.trim().strip_prefix("TOFPROBE-GDS ") else {
            continue;
        };
        let (key, value) = rest.split_once(' ').unwrap_or((rest, ""));
        let num = || value.trim().parse::<f64>().ok();
        match key {
            "top" => g.top = value.trim().to_string(),
            "shapes" => g.shapes = num().unwrap_or(0.0) as u64,
            "outside" => g.outside = num().unwrap_or(0.0) as u64,
            "worst" => g.worst_um = num().unwrap_or(0.0),
            "cell" => {
                g.cells += 1;
                if let Some((name, "1")) = value.rsplit_once(' ') {
                    g.empty_cells += 1;
                    if g.empty_examples.len() < 3 {
                        g.empty_examples.push(name.to_string());
                    }
                }
                continue;
            }
            _ => continue,
        }
        seen += 1;
    }
    if seen < 4 {
        return Err(LayoutError::Parse {
            tool: "klayout",
            what: "the GDS figures (`TOFPROBE-GDS top/shapes/outside/worst`)".into(),
            path: path.to_path_buf(),
        });
    }
    Ok(g)
}

/// Reads `gds` with klayout (the script kept in `dir`), the die `die` in µm.
pub fn inspect(gds: &Path, die: crate::die::Rect, dir: &Path) -> Result<GdsFigures> {
    let script = dir.join("gds_check.py");
    let out = crate::picture::klayout(
        "GDS check",
        SCRIPT,
        &script,
        &[
            ("gds", gds.display().to_string()),
            ("x0", die.0.to_string()),
            ("y0", die.1.to_string()),
            ("x1", die.2.to_string()),
            ("y1", die.3.to_string()),
        ],
    )?;
    parse(&String::from_utf8_lossy(&out.stdout), &script)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_abstract_only_stream_says_so() {
        // What the script printed for the 2-bin pixel's GDS on osu018 before the die was
        // grown (its first lines; all 19 cells were empty): 101 shapes past the die, up to 1.1 µm.
        let text = "TOFPROBE-GDS top tofprobe_pixel\nTOFPROBE-GDS shapes 83209\nTOFPROBE-GDS outside 101\n\
                    TOFPROBE-GDS worst 1.1000\nTOFPROBE-GDS cell FILL 1\nTOFPROBE-GDS cell XNOR2X1 1\nTOFPROBE-GDS cell INVX1 1\n";
        let g = parse(text, Path::new("s")).unwrap();
        assert_eq!((g.cells, g.empty_cells, g.outside), (3, 3, 101));
        assert_eq!(g.worst_um, 1.1);
        assert!(!g.standalone());
        assert!(
            g.holds()
                .contains("routing and pins only: 3 of its 3 cells are empty"),
            "{}",
            g.holds()
        );
        let full = text.replace(" 1\n", " 0\n");
        let g = parse(&full, Path::new("s")).unwrap();
        assert!(g.standalone() && g.holds().contains("standalone stream"));
        assert!(parse("klayout crashed", Path::new("s")).is_err());
    }
}
