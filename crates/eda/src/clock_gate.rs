//! Mapping the clock gates of a clock-gated register file (`[pixel] register_file =
//! "clock_gated"`, the pixel's `<pixel>_clock_gate` module) onto a liberty's own cells,
//! chosen from the liberty: its integrated clock-gating cell (`clock_gating_integrated_cell
//! : "latch_posedge"`, sky130's `dlclkp`), or, where it has none (osu018), its latch and an
//! AND gate (with an inverter on the clock when the latch is transparent while its enable
//! is high). Synthesis replaces the module's behavioural body with instances of those
//! cells before flattening, so ABC never sees (nor restructures, nor duplicates) the gated
//! clock: the gates are fixed instances, the flops behind them plain flops.

use crate::cells::{inputs, outputs, smallest, smallest_inverter};
use crate::error::{EdaError, Result};
use crate::liberty::Liberty;

/// The cells that implement one clock gate, with their pin names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClockGateCells {
    /// An integrated clock gate: `cell (.clock(clk), .enable(en), .out(gclk))`.
    Integrated {
        cell: String,
        clock: String,
        enable: String,
        out: String,
    },
    /// A latch transparent while the clock is low (through `inverter` when the liberty's
    /// latch is transparent-high) and an AND gate of the clock and the latched enable.
    LatchAnd {
        /// (cell, enable pin, data pin, output pin).
        latch: (String, String, String, String),
        /// (cell, input pin, output pin), when the latch's enable is active-high.
        inverter: Option<(String, String, String)>,
        /// (cell, input pin, input pin, output pin).
        and: (String, String, String, String),
    },
}

/// The instance names inside the mapped module; flattening prefixes them with the
/// register's instance (`cg_<r>.`), which is how the area split finds the clock gates.
pub const INSTANCES: [&str; 4] = ["icg", "clk_inv", "enable_latch", "clk_and"];

/// The prefix of the pixel's clock-gate instances (`cg_<r>`), see templates/pixel.v.
pub const INSTANCE_PREFIX: &str = "cg_";

/// `function` is the AND of pins `a` and `b`: `A&B`, `A*B` or liberty's juxtaposition
/// `A B` (osu018), in either order, with any parentheses.
fn is_and(function: &str, a: &str, b: &str) -> bool {
    let f = function.replace(['(', ')'], " ");
    if f.contains(['|', '+', '!', '\'', '^']) {
        return false;
    }
    let mut terms: Vec<&str> = f
        .split(|c: char| c == '&' || c == '*' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    terms.sort_unstable();
    let mut want = [a, b];
    want.sort_unstable();
    terms == want
}

impl ClockGateCells {
    /// The liberty's cells for a clock gate: its smallest `latch_posedge` integrated clock
    /// gate, else its smallest latch with the smallest two-input AND (and inverter). The
    /// error names the option and what the liberty lacks.
    pub fn from_liberty(lib: &Liberty) -> Result<Self> {
        let icg = smallest(lib, |n, c| {
            if c.clock_gating.as_deref() != Some("latch_posedge") {
                return None;
            }
            let role = |r| c.pins.iter().find(|p| p.clock_gate_role == r);
            Some(ClockGateCells::Integrated {
                cell: n.clone(),
                clock: role("clock")?.name.clone(),
                enable: role("enable")?.name.clone(),
                out: role("out")?.name.clone(),
            })
        });
        if let Some(icg) = icg {
            return Ok(icg);
        }
        let missing = |what| EdaError::ClockGateCells {
            path: lib.path.clone(),
            missing: what,
        };
        // A plain D latch, either polarity (crate::latch reads them).
        let latch = crate::latch::smallest(crate::latch::d_latches(lib))
            .map(|l| (l.cell, l.enable, l.data, l.q, l.transparent_low))
        .ok_or_else(|| {
            missing(
                "integrated clock-gating cell (`clock_gating_integrated_cell : \"latch_posedge\"`) nor a D latch (`latch` group)",
            )
        })?;
        let and = smallest(lib, |n, c| {
            let ins = inputs(c);
            let outs = outputs(c);
            if c.sequential || ins.len() != 2 || outs.len() != 1 {
                return None;
            }
            let (a, b) = (ins[0], ins[1]);
            is_and(&outs[0].1, a, b).then(|| {
                (
                    n.clone(),
                    a.to_string(),
                    b.to_string(),
                    outs[0].0.to_string(),
                )
            })
        })
        .ok_or_else(|| {
            missing("two-input AND gate beside its latch (for a latch-based clock gate)")
        })?;
        let inverter = if latch.4 {
            None
        } else {
            let inv = smallest_inverter(lib).ok_or_else(|| {
                missing("inverter for its transparent-high latch (for a latch-based clock gate)")
            })?;
            Some(inv)
        };
        Ok(ClockGateCells::LatchAnd {
            latch: (latch.0, latch.1, latch.2, latch.3),
            inverter,
            and,
        })
    }

    /// The cell names used (for the report).
    pub fn cell_names(&self) -> Vec<&str> {
        match self {
            ClockGateCells::Integrated { cell, .. } => vec![cell],
            ClockGateCells::LatchAnd {
                latch,
                inverter,
                and,
            } => {
                let mut v = vec![latch.0.as_str()];
                v.extend(inverter.iter().map(|i| i.0.as_str()));
                v.push(and.0.as_str());
                v
            }
        }
    }

    /// Verilog of `module` (ports `clk`, `en`, `gclk`, as the pixel's `_clock_gate`)
    /// built of these cells, read with `read_verilog -overwrite` over the behavioural one.
    pub fn module_verilog(&self, module: &str) -> String {
        let mut s = format!(
            "// Generated by tofprobe-eda: the pixel's clock gate on the liberty's cells.\n\
             module {module} (input wire clk, input wire en, output wire gclk);\n"
        );
        match self {
            ClockGateCells::Integrated {
                cell,
                clock,
                enable,
                out,
            } => {
                s += &format!(
                    "    {cell} {} (.{clock}(clk), .{enable}(en), .{out}(gclk));\n",
                    INSTANCES[0]
                );
            }
            ClockGateCells::LatchAnd {
                latch,
                inverter,
                and,
            } => {
                s += "    wire en_l;\n";
                let latch_clk = match inverter {
                    Some((inv, a, y)) => {
                        s += "    wire clk_n;\n";
                        s += &format!("    {inv} {} (.{a}(clk), .{y}(clk_n));\n", INSTANCES[1]);
                        "clk_n"
                    }
                    None => "clk",
                };
                s += &format!(
                    "    {} {} (.{}({latch_clk}), .{}(en), .{}(en_l));\n",
                    latch.0, INSTANCES[2], latch.1, latch.2, latch.3
                );
                s += &format!(
                    "    {} {} (.{}(clk), .{}(en_l), .{}(gclk));\n",
                    and.0, INSTANCES[3], and.1, and.2, and.3
                );
            }
        }
        s += "endmodule\n";
        s
    }
}

/// Behavioural Verilog of the `latch_posedge` integrated clock gates of `lib` that
/// `netlist` instantiates (the latch open while the clock is low, ANDed with the clock: what
/// `clock_gating_integrated_cell : "latch_posedge"` declares), for the equivalence check;
/// `None` when it uses none.
pub fn icg_models(lib: &Liberty, netlist: &str) -> Option<String> {
    let mut s = String::new();
    for (name, c) in &lib.cells {
        if c.clock_gating.as_deref() != Some("latch_posedge") || !netlist.contains(name.as_str()) {
            continue;
        }
        let role = |r| {
            c.pins
                .iter()
                .find(|p| p.clock_gate_role == r)
                .map(|p| &p.name)
        };
        let (Some(ck), Some(en), Some(out)) = (role("clock"), role("enable"), role("out")) else {
            continue;
        };
        s += &format!(
            "module {name} ({ck}, {en}, {out});\n    input {ck};\n    input {en};\n    output {out};\n    reg m;\n    always @({ck} or {en}) if (!{ck}) m = {en};\n    assign {out} = {ck} & m;\nendmodule\n"
        );
    }
    (!s.is_empty()).then_some(s)
}

/// Whether `verilog` defines the clock-gate module of pixel `top` (`<top>_clock_gate`):
/// the pixel was rendered with `register_file = "clock_gated"`.
pub fn module_in(verilog: &str, top: &str) -> Option<String> {
    let name = format!("{top}_clock_gate");
    verilog
        .lines()
        .any(|l| {
            l.trim_start().strip_prefix("module ").is_some_and(|r| {
                r.trim_start().starts_with(&format!("{name} ")) || r.trim() == name
            })
        })
        .then_some(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const BASE: &str = r#"library (t) {
  cell (AND2) { area : 8 ; pin (A) { direction : input ; } pin (B) { direction : input ; }
    pin (Y) { direction : output ; function : "(A&B)" ; } }
  cell (OR2) { area : 6 ; pin (A) { direction : input ; } pin (B) { direction : input ; }
    pin (Y) { direction : output ; function : "(A|B)" ; } }
  cell (INV) { area : 4 ; pin (A) { direction : input ; }
    pin (Y) { direction : output ; function : "!A" ; } }
  cell (DFF) { area : 20 ; ff (IQ, IQN) { next_state : "D" ; clocked_on : "CK" ; }
    pin (CK) { direction : input ; } pin (D) { direction : input ; }
    pin (Q) { direction : output ; function : "IQ" ; } }
"#;
    const LATCH: &str = r#"  cell (LAT) { area : 12 ; latch (IQ, IQN) { enable : "G" ; data_in : "D" ; }
    pin (G) { direction : input ; } pin (D) { direction : input ; }
    pin (Q) { direction : output ; function : "IQ" ; } }
"#;
    const ICG: &str = r#"  cell (CG_2) { area : 18 ; clock_gating_integrated_cell : "latch_posedge" ;
    pin (CLK) { clock_gate_clock_pin : true ; direction : input ; }
    pin (GATE) { clock_gate_enable_pin : true ; direction : input ; }
    pin (GCLK) { clock_gate_out_pin : true ; direction : output ; state_function : "CLK*M0" ; }
    statetable ("CLK GATE", "M0") { table : "L L : - : L" ; } }
  cell (CG_1) { area : 17 ; clock_gating_integrated_cell : "latch_posedge" ;
    pin (CLK) { clock_gate_clock_pin : true ; direction : input ; }
    pin (GATE) { clock_gate_enable_pin : true ; direction : input ; }
    pin (GCLK) { clock_gate_out_pin : true ; direction : output ; } }
"#;

    fn lib(parts: &[&str]) -> Liberty {
        let text = parts.concat() + "}\n";
        Liberty::parse(Path::new("t.lib"), &text).unwrap()
    }

    #[test]
    fn integrated_cell_is_preferred_and_the_smallest() {
        let c = ClockGateCells::from_liberty(&lib(&[BASE, LATCH, ICG])).unwrap();
        assert_eq!(
            c,
            ClockGateCells::Integrated {
                cell: "CG_1".into(),
                clock: "CLK".into(),
                enable: "GATE".into(),
                out: "GCLK".into()
            }
        );
        let v = c.module_verilog("pix_clock_gate");
        assert!(
            v.contains("module pix_clock_gate (input wire clk, input wire en, output wire gclk);")
        );
        assert!(
            v.contains("CG_1 icg (.CLK(clk), .GATE(en), .GCLK(gclk));"),
            "{v}"
        );
    }

    #[test]
    fn latch_and_gate_where_there_is_no_integrated_cell() {
        let c = ClockGateCells::from_liberty(&lib(&[BASE, LATCH])).unwrap();
        let v = c.module_verilog("pix_clock_gate");
        // Transparent-high latch: clocked by the inverted clock, so it is open while clk is low.
        assert!(v.contains("INV clk_inv (.A(clk), .Y(clk_n));"), "{v}");
        assert!(
            v.contains("LAT enable_latch (.G(clk_n), .D(en), .Q(en_l));"),
            "{v}"
        );
        assert!(
            v.contains("AND2 clk_and (.A(clk), .B(en_l), .Y(gclk));"),
            "{v}"
        );
        // A transparent-low latch needs no inverter.
        let low = LATCH.replace("enable : \"G\"", "enable : \"!G\"");
        let c = ClockGateCells::from_liberty(&lib(&[BASE, &low])).unwrap();
        assert_eq!(c.cell_names(), vec!["LAT", "AND2"]);
    }

    #[test]
    fn osu018_gets_its_latch_inverter_and_and_gate() {
        // CI installs the package (scripts/install-tools.sh): its absence is a failure.
        let p = Path::new("/usr/share/qflow/tech/osu018/osu018_stdcells.lib");
        let c = ClockGateCells::from_liberty(&Liberty::load(p).unwrap()).unwrap();
        assert_eq!(c.cell_names(), vec!["LATCH", "INVX1", "AND2X1"]);
    }

    #[test]
    fn a_liberty_without_either_is_refused_naming_the_option() {
        let msg = ClockGateCells::from_liberty(&lib(&[BASE]))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("t.lib")
                && msg.contains("pixel.register_file = \"clock_gated\"")
                && msg.contains("clock-gating cell")
                && msg.contains("latch")
                && msg.contains("register_file = \"flops\""),
            "{msg}"
        );
        assert!(is_and("(A B)", "B", "A") && is_and("A*B", "A", "B"));
        assert!(!is_and("(!(A B))", "A", "B") && !is_and("A&C", "A", "B"));
        let no_and = BASE.replace("(A&B)", "(A^B)");
        let msg = ClockGateCells::from_liberty(&lib(&[&no_and, LATCH]))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("AND gate"), "{msg}");
    }

    #[test]
    fn icg_models_cover_the_used_integrated_cells() {
        let l = lib(&[BASE, LATCH, ICG]);
        let m = icg_models(&l, "CG_2 cg_0.icg (.CLK(clk));").unwrap();
        assert!(m.contains("module CG_2 (CLK, GATE, GCLK);"), "{m}");
        assert!(m.contains("if (!CLK) m = GATE;") && m.contains("assign GCLK = CLK & m;"));
        assert!(!m.contains("module CG_1 "), "unused cell modelled: {m}");
        assert_eq!(icg_models(&l, "DFF f (.CK(clk));"), None);
    }

    #[test]
    fn finds_the_clock_gate_module_of_the_pixel() {
        let v = "module pix (input clk);\nendmodule\nmodule pix_clock_gate (\n";
        assert_eq!(module_in(v, "pix").as_deref(), Some("pix_clock_gate"));
        assert_eq!(module_in(v, "other"), None);
        assert_eq!(module_in("module pix (", "pix"), None);
    }
}
