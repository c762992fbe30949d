//! The laid-out netlist: the routed DEF's cells and connections written as Verilog, so the
//! project's equivalence proof (`tofprobe_eda::equiv`) covers what was placed and routed
//! — the synthesised cells, the clock buffers qflow added, any cell the flow inserted —
//! and not only the sign-off netlist it came from.
//!
//! The DEF names a bus bit as the synthesised netlist's wire and its index (`y[0][5]` is
//! bit 5 of `wire [38:0] \y[0]`), so every DEF net the synthesised netlist declares keeps
//! its name and width there, and the proof pairs the registers by name as for sign-off; a
//! net the DEF adds (a clock buffer's output) is a new one-bit wire. Cells without a
//! signal connection (fill, tap, decap) are physical only and left out, counted by cell.

use crate::error::{LayoutError, Result};
use crate::repair::def_nets;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::Path;

/// The laid-out netlist and what it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct LaidOut {
    /// The Verilog module.
    pub verilog: String,
    /// Cell instances in it.
    pub cells: u64,
    /// Placed cells with no signal connection, left out, by cell.
    pub physical_only: BTreeMap<String, u64>,
}

/// One declaration of the synthesised netlist.
#[derive(Debug, Clone, PartialEq)]
struct Decl {
    kind: String,
    range: Option<(i64, i64)>,
    name: String,
}

/// The module's port order and its `input`/`output`/`inout`/`wire` declarations (yosys's
/// `write_verilog`: one per line, `  wire [38:0] \y[0] ;`).
fn declarations(v: &str) -> Result<(Vec<String>, Vec<Decl>)> {
    let bad = || LayoutError::Parse {
        tool: "yosys (netlist)",
        what: "`module NAME(PORTS);`".into(),
        path: "synthesised netlist".into(),
    };
    let head = v.find("module ").ok_or_else(bad)?;
    let open = v[head..].find('(').ok_or_else(bad)? + head;
    let close = v[open..].find(')').ok_or_else(bad)? + open;
    let ports = v[open + 1..close]
        .split(',')
        .map(|p| p.trim().trim_start_matches('\\').trim().to_string())
        .filter(|p| !p.is_empty())
        .collect();
    let mut decls = Vec::new();
    for line in v[close..].lines() {
        let t = line.trim().trim_end_matches(';').trim();
        let Some((kind, rest)) = t.split_once(' ') else {
            continue;
        };
        if !matches!(kind, "input" | "output" | "inout" | "wire") {
            continue;
        }
        let rest = rest.trim();
        let (range, name) = match rest.strip_prefix('[') {
            Some(r) => {
                let (bounds, name) = r.split_once(']').ok_or_else(bad)?;
                let (m, l) = bounds.split_once(':').ok_or_else(bad)?;
                let (m, l) = (m.trim().parse().ok(), l.trim().parse().ok());
                let (Some(m), Some(l)) = (m, l) else {
                    return Err(bad());
                };
                (Some((m, l)), name.trim())
            }
            None => (None, rest),
        };
        // `wire x = …;` declarations are not in yosys's netlists; a name ends at a space.
        let name = name.trim_start_matches('\\').split_whitespace().next();
        if let Some(name) = name {
            decls.push(Decl {
                kind: kind.to_string(),
                range,
                name: name.to_string(),
            });
        }
    }
    Ok((ports, decls))
}

/// A Verilog identifier for `name`: plain when it is one, escaped otherwise.
fn ident(name: &str) -> String {
    let plain = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$');
    if plain {
        name.to_string()
    } else {
        format!("\\{name} ")
    }
}

/// The laid-out netlist of module `top` from the routed `def`, with the names and widths of
/// the `synthesised` netlist's wires and ports.
pub fn from_def(def: &str, synthesised: &str, top: &str, path: &Path) -> Result<LaidOut> {
    let bad = |what: String| LayoutError::Parse {
        tool: "qflow (DEF)",
        what,
        path: path.to_path_buf(),
    };
    let (ports, decls) = declarations(synthesised)?;
    // DEF name → Verilog expression and its declaration's kind.
    let mut expr: BTreeMap<String, (String, &str)> = BTreeMap::new();
    let mut declared: BTreeSet<&str> = BTreeSet::new();
    for d in &decls {
        if !declared.insert(&d.name) {
            continue; // `input clk; wire clk;`: the first is the port
        }
        let keys: Vec<(String, String)> = match d.range {
            None => vec![(d.name.clone(), ident(&d.name))],
            Some((m, l)) => (m.min(l)..=m.max(l))
                .map(|i| {
                    (
                        format!("{}[{i}]", d.name),
                        format!("{}[{i}]", ident(&d.name)),
                    )
                })
                .collect(),
        };
        for (k, e) in keys {
            if expr.insert(k.clone(), (e, &d.kind)).is_some() {
                return Err(bad(format!(
                    "one wire per DEF name (`{k}` is a bus bit and a wire of the netlist)"
                )));
            }
        }
    }
    let nets = def_nets(def);
    let mut cells: BTreeMap<String, String> = BTreeMap::new();
    let mut in_components = false;
    for line in def.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["COMPONENTS", ..] => in_components = true,
            ["END", "COMPONENTS"] => break,
            ["-", inst, cell, ..] if in_components => {
                cells.insert(inst.to_string(), cell.to_string());
            }
            _ => {}
        }
    }
    let mut pins: BTreeMap<&str, Vec<(&str, &str)>> = BTreeMap::new();
    let mut assigns = String::new();
    for ((inst, pin), net) in &nets.pins {
        if inst == "PIN" {
            let (port, kind) = expr
                .get(pin)
                .ok_or_else(|| bad(format!("the port of DEF pin `{pin}` in the netlist")))?;
            if pin != net {
                let n = net_expr(&expr, net);
                let _ = match *kind {
                    "input" => writeln!(assigns, "  assign {n} = {port};"),
                    _ => writeln!(assigns, "  assign {port} = {n};"),
                };
            }
            continue;
        }
        if !cells.contains_key(inst) {
            return Err(bad(format!("component `{inst}` (on net `{net}`)")));
        }
        pins.entry(inst).or_default().push((pin, net));
    }
    let mut v = format!(
        "// The laid-out netlist of {top}: the routed DEF's cells and nets (tofprobe layout).\nmodule {}({});\n",
        ident(top),
        ports
            .iter()
            .map(|p| ident(p))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut seen = BTreeSet::new();
    for d in &decls {
        if !seen.insert(&d.name) {
            continue;
        }
        let range = d
            .range
            .map_or(String::new(), |(m, l)| format!("[{m}:{l}] "));
        let _ = writeln!(v, "  {} {range}{};", d.kind, ident(&d.name));
    }
    for n in &nets.names {
        if !expr.contains_key(n) {
            let _ = writeln!(v, "  wire {};", ident(n));
        }
    }
    v += &assigns;
    v += &aliases(synthesised, &decls, &expr, &nets.names);
    let mut physical_only: BTreeMap<String, u64> = BTreeMap::new();
    let mut count = 0;
    for (inst, cell) in &cells {
        let Some(conns) = pins.get(inst.as_str()) else {
            *physical_only.entry(cell.clone()).or_default() += 1;
            continue;
        };
        count += 1;
        let conns: Vec<String> = conns
            .iter()
            .map(|(p, n)| format!(".{}({})", ident(p), net_expr(&expr, n)))
            .collect();
        let _ = writeln!(
            v,
            "  {} {}({});",
            ident(cell),
            ident(inst),
            conns.join(", ")
        );
    }
    v += "endmodule\n";
    Ok(LaidOut {
        verilog: v,
        cells: count,
        physical_only,
    })
}

/// The Verilog expression of DEF net `net`.
fn net_expr(expr: &BTreeMap<String, (String, &str)>, net: &str) -> String {
    expr.get(net).map_or_else(|| ident(net), |(e, _)| e.clone())
}

/// One bit of an `assign`'s side: a net (its DEF name) or a constant (`0`, `1`, `x`).
#[derive(Debug, Clone, PartialEq)]
enum Bit {
    Net(String),
    Const(char),
}

/// The bits of one item of an `assign` side, most significant first: `NAME`, `NAME[i]`,
/// `NAME[m:l]`, an escaped `\NAME [i]`, or a constant `N'hX` / `N'bX` / `N'dX`.
fn item_bits(item: &str, decls: &[Decl]) -> Option<Vec<Bit>> {
    let item = item.trim();
    if let Some((w, v)) = item.split_once('\'') {
        let width: usize = w.trim().parse().ok()?;
        let (base, digits) = v.split_at(1);
        let per = match base {
            "h" => 4,
            "b" => 1,
            "d" => return None,
            _ => return None,
        };
        let mut bits: Vec<Bit> = Vec::new();
        for c in digits.chars().filter(|c| *c != '_') {
            if c == 'x' || c == 'z' {
                bits.extend((0..per).map(|_| Bit::Const('x')));
            } else {
                let d = c.to_digit(16)?;
                bits.extend(
                    (0..per)
                        .rev()
                        .map(|k| Bit::Const(if d >> k & 1 == 1 { '1' } else { '0' })),
                );
            }
        }
        // Keep the low `width` bits (an `x` digit fills them all).
        let cut = bits.len().saturating_sub(width);
        let mut bits = bits.split_off(cut);
        while bits.len() < width {
            bits.insert(0, Bit::Const('0'));
        }
        return Some(bits);
    }
    let (name, sel) = match item.strip_prefix('\\') {
        Some(esc) => {
            let (n, rest) = esc.split_once(' ').unwrap_or((esc, ""));
            (n, rest.trim())
        }
        None => match item.find('[') {
            Some(i) => (&item[..i], &item[i..]),
            None => (item, ""),
        },
    };
    let d = decls.iter().find(|d| d.name == name)?;
    let key = |i: i64| Bit::Net(format!("{name}[{i}]"));
    let sel = sel.trim();
    if sel.is_empty() {
        return Some(match d.range {
            None => vec![Bit::Net(name.to_string())],
            Some((m, l)) => {
                let step = if m >= l { -1 } else { 1 };
                let mut out = Vec::new();
                let mut i = m;
                loop {
                    out.push(key(i));
                    if i == l {
                        break;
                    }
                    i += step;
                }
                out
            }
        });
    }
    let inner = sel.strip_prefix('[')?.strip_suffix(']')?;
    match inner.split_once(':') {
        Some((m, l)) => {
            let (m, l): (i64, i64) = (m.trim().parse().ok()?, l.trim().parse().ok()?);
            Some((l.min(m)..=m.max(l)).rev().map(key).collect())
        }
        None => Some(vec![key(inner.trim().parse().ok()?)]),
    }
}

/// The bits of an `assign` side: a concatenation `{ a, b }` or one item.
fn side_bits(side: &str, decls: &[Decl]) -> Option<Vec<Bit>> {
    let side = side.trim();
    match side.strip_prefix('{').and_then(|s| s.strip_suffix('}')) {
        Some(items) => {
            let mut out = Vec::new();
            for it in items.split(',') {
                out.extend(item_bits(it, decls)?);
            }
            Some(out)
        }
        None => item_bits(side, decls),
    }
}

/// The synthesised netlist's `assign` aliases (a wire that is another's name, or a
/// constant) as one-bit assigns between the laid-out nets: only an alias whose name is not
/// a DEF net is kept (or turned round when its source is the missing one), so an alias
/// names a laid-out net and never joins two. Without them a wire the netlist declares but
/// the DEF never names (`d = {1'h0, tdc}`) would be undriven, and the proof pairs it.
fn aliases(
    synthesised: &str,
    decls: &[Decl],
    expr: &BTreeMap<String, (String, &str)>,
    def_names: &BTreeSet<String>,
) -> String {
    let bit_expr = |b: &Bit| match b {
        Bit::Net(k) => net_expr(expr, k),
        Bit::Const(c) => format!("1'b{c}"),
    };
    let laid_out = |b: &Bit| matches!(b, Bit::Net(k) if def_names.contains(k));
    let mut out = String::new();
    for line in synthesised.lines() {
        let Some(a) = line.trim().strip_prefix("assign ") else {
            continue;
        };
        let Some((lhs, rhs)) = a.trim_end_matches(';').split_once(" = ") else {
            continue;
        };
        let (Some(l), Some(r)) = (side_bits(lhs, decls), side_bits(rhs, decls)) else {
            continue;
        };
        // LSB-aligned, as Verilog assigns.
        for (lb, rb) in l.iter().rev().zip(r.iter().rev()) {
            let (to, from) = match (laid_out(lb), laid_out(rb)) {
                (false, _) => (lb, rb),
                (true, false) if matches!(rb, Bit::Net(_)) => (rb, lb),
                _ => continue,
            };
            let _ = writeln!(out, "  assign {} = {};", bit_expr(to), bit_expr(from));
        }
    }
    out
}

/// The proof of the laid-out netlist (JSON: `equivalence` of the layout report).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LaidOutProof {
    /// The netlist proven (kept in the qflow project, and in the output set).
    pub netlist: String,
    /// Its cell instances (the DEF's placed cells less the physical-only ones).
    pub cells: u64,
    /// Placed cells with no signal connection (fill, tap, decap), by cell.
    pub physical_only: BTreeMap<String, u64>,
    /// Paired signal bits (registers and outputs).
    pub points: u64,
    /// Of them proven.
    pub proven: u64,
    /// The first unproven pair (empty when all are proven).
    pub first_unproven: String,
    /// Wall time of the proof (s; that of the run that proved it when cached).
    pub seconds: f64,
    /// Served from the equivalence cache.
    pub cached: bool,
}

impl LaidOutProof {
    /// Every pair proven.
    pub fn proven(&self) -> bool {
        self.points > 0 && self.proven == self.points
    }
}

#[cfg(test)]
#[path = "netlist_tests.rs"]
mod tests;
