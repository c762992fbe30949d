//! Splitting the synthesised area between register file, adders, hold/prefilter and
//! control, from the flattened mapped netlist.
//!
//! Method (flattening loses module boundaries, so cells are attributed by structure):
//! 1. Every flop is named by the RTL signal it drives (`autoname` keeps the net names):
//!    flops of the register file (`Y…`, `regs…`), of the hold/prefilter (`held`, `x`,
//!    `primed`, …), or else control (`slot`, `pcount`, `refused`, `bits`, readout state…).
//!    A register-file flop belongs to register `(net, bit / W)`, so one wide vector or
//!    one net per register both work.
//! 2. Each combinational cell is followed forward (through combinational cells only) to
//!    the flops and outputs it feeds. It is charged to
//!    - hold/prefilter if it feeds any hold/prefilter flop;
//!    - the register file if it feeds register-file flops of exactly ONE register (the
//!      register's private write enable / hold mux);
//!    - the adders if it feeds flops of two or more registers (the shared adder, its
//!      operand and register selection and the sum's fan-out: logic that exists because
//!      registers share an adder);
//!    - control otherwise (counters, readout mux, status).
//!
//! A clock-gated register file's gates (`cg_<r>.icg`, or its latch, inverter and AND) are
//! charged to the register file and are not flops; the logic behind a gate feeds only its
//! register's flops, so the enable decode lands in the register file as the enable
//! multiplexer's does.
//!
//! The split is a structural attribution, not a layout: logic that serves two purposes is
//! charged to the first class in the order above.

use crate::error::{EdaError, Result};
use crate::liberty::Liberty;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// Which RTL signal names belong to which block.
#[derive(Debug, Clone)]
pub struct BlockNames {
    /// Base names of the register file (default `Y`, `y`, `regs`, `acc`).
    pub register_file: Vec<String>,
    /// Base names of the hold and prefilter state (default `held`, `x`, `primed`, `op` —
    /// the latched prefilter output —, `diff`).
    pub hold_prefilter: Vec<String>,
    /// Base names of the flops a latch register file captures each write in (`we_q`, the
    /// enables; `wd_<a>`, adder a's word): charged to the register file but traversed like
    /// logic, so the adder in front of a word still reaches the several registers it
    /// writes (and is charged to the adders).
    pub register_file_stage: Vec<String>,
    /// Register width W: register-file bits of one net are grouped W at a time.
    pub width: u32,
}

impl BlockNames {
    /// The names of docs/pixel-contract.md's state, for registers of width `width`.
    pub fn contract(width: u32) -> Self {
        Self {
            register_file: ["Y", "y", "regs", "acc"].map(String::from).to_vec(),
            hold_prefilter: ["held", "x", "primed", "op", "x_new", "h_new", "diff"]
                .map(String::from)
                .to_vec(),
            register_file_stage: ["we_q", "wd"].map(String::from).to_vec(),
            width: width.max(1),
        }
    }
}

/// Area (µm²) and cell count of one block.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, PartialEq)]
pub struct BlockArea {
    /// Summed cell area.
    pub area_um2: f64,
    /// Cell instances.
    pub cells: u64,
    /// Of which flops.
    pub flops: u64,
}

/// The four-way split.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, PartialEq)]
pub struct AreaSplit {
    /// Y registers and their private write logic.
    pub register_file: BlockArea,
    /// Shared adders with operand/register selection.
    pub adders: BlockArea,
    /// 1NN hold and shift prefilter.
    pub hold_prefilter: BlockArea,
    /// Schedule counters, ROM-bit latch, readout, status.
    pub control: BlockArea,
    /// Number of distinct registers found in the register file.
    pub registers_found: u64,
}

impl AreaSplit {
    /// Sum of the four blocks.
    pub fn total_area_um2(&self) -> f64 {
        self.register_file.area_um2
            + self.adders.area_um2
            + self.hold_prefilter.area_um2
            + self.control.area_um2
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Sink {
    Reg(usize),
    Hold,
    Control,
}

fn base_name(net: &str) -> &str {
    let n = net.rsplit(['.', '/']).next().unwrap_or(net);
    let n = n.trim_start_matches('\\');
    n.split('[').next().unwrap_or(n)
}

fn matches(base: &str, names: &[String]) -> bool {
    names.iter().any(|p| {
        base == p
            || base.strip_prefix(p.as_str()).is_some_and(|rest| {
                rest.starts_with('_') && rest[1..].chars().all(|c| c.is_ascii_digit())
            })
    })
}

/// A cell of a clock-gated register file's gate: flattening names it `cg_<r>.<instance>`
/// after the pixel's gate instance and the mapped module's cell (crate::clock_gate).
fn is_clock_gate(cell: &str) -> bool {
    cell.split_once('.').is_some_and(|(inst, leaf)| {
        inst.strip_prefix(crate::clock_gate::INSTANCE_PREFIX)
            .is_some_and(|r| !r.is_empty() && r.chars().all(|c| c.is_ascii_digit()))
            && crate::clock_gate::INSTANCES.contains(&leaf)
    })
}

fn bit_id(v: &serde_json::Value) -> Option<u64> {
    v.as_u64()
}

/// Attributes the cells of the yosys JSON netlist at `json_path` (module `top`) to blocks.
pub fn split_area(
    json_path: &Path,
    top: &str,
    lib: &Liberty,
    names: &BlockNames,
) -> Result<AreaSplit> {
    let text =
        std::fs::read_to_string(json_path).map_err(|e| EdaError::io("reading", json_path, e))?;
    let doc: serde_json::Value = serde_json::from_str(&text).map_err(|e| EdaError::Json {
        what: json_path.display().to_string(),
        source: e,
    })?;
    let module = doc
        .get("modules")
        .and_then(|m| m.get(top))
        .ok_or_else(|| EdaError::Parse {
            tool: "yosys",
            what: "the top module in the JSON netlist",
            tail: json_path.display().to_string(),
        })?;
    // Net bit -> every public (net name, position in the net); a bit can carry several
    // names when the RTL aliases a register through a wire (e.g. `op = x` sign-extended).
    let mut bit_names: HashMap<u64, Vec<(String, usize)>> = HashMap::new();
    if let Some(nets) = module.get("netnames").and_then(|n| n.as_object()) {
        for (name, net) in nets {
            if net.get("hide_name").and_then(|h| h.as_u64()) == Some(1) {
                continue;
            }
            let bits = net
                .get("bits")
                .and_then(|b| b.as_array())
                .cloned()
                .unwrap_or_default();
            for (pos, b) in bits.iter().enumerate() {
                if let Some(id) = bit_id(b) {
                    bit_names.entry(id).or_default().push((name.clone(), pos));
                }
            }
        }
    }
    struct Cell {
        area: f64,
        flop: bool,
        /// A cell of a register's clock gate (charged to the register file, traversed like
        /// logic: the enable logic behind it belongs to the register it clocks).
        clock_gate: bool,
        inputs: Vec<u64>,
        outputs: Vec<u64>,
    }
    let mut cells = Vec::new();
    if let Some(cs) = module.get("cells").and_then(|c| c.as_object()) {
        for (name, c) in cs {
            let ty = c.get("type").and_then(|t| t.as_str()).unwrap_or_default();
            let lc = lib.cells.get(ty);
            let dirs = c.get("port_directions").and_then(|d| d.as_object());
            let clock_gate = is_clock_gate(name);
            let mut cell = Cell {
                area: lc.map_or(0.0, |l| l.area),
                flop: lc.is_some_and(|l| l.sequential) && !clock_gate,
                clock_gate,
                inputs: vec![],
                outputs: vec![],
            };
            if let Some(conns) = c.get("connections").and_then(|c| c.as_object()) {
                for (port, bits) in conns {
                    let out =
                        dirs.and_then(|d| d.get(port)).and_then(|d| d.as_str()) == Some("output");
                    for id in bits.as_array().into_iter().flatten().filter_map(bit_id) {
                        if out {
                            cell.outputs.push(id)
                        } else {
                            cell.inputs.push(id)
                        }
                    }
                }
            }
            cells.push(cell);
        }
    }
    // Classify flops by the net they drive.
    let mut reg_index: HashMap<(String, usize), usize> = HashMap::new();
    let mut flop_sink: HashMap<usize, Sink> = HashMap::new();
    let mut stage = Vec::new();
    for (i, c) in cells.iter().enumerate().filter(|(_, c)| c.flop) {
        let names_of: Vec<&(String, usize)> = c
            .outputs
            .iter()
            .filter_map(|b| bit_names.get(b))
            .flatten()
            .collect();
        if names_of
            .iter()
            .any(|(net, _)| matches(base_name(net), &names.register_file_stage))
        {
            stage.push(i);
            continue;
        }
        let reg = names_of
            .iter()
            .find(|(net, _)| matches(base_name(net), &names.register_file));
        let sink = if let Some((net, pos)) = reg {
            let key = (net.clone(), pos / names.width as usize);
            let n = reg_index.len();
            Sink::Reg(*reg_index.entry(key).or_insert(n))
        } else if names_of
            .iter()
            .any(|(net, _)| matches(base_name(net), &names.hold_prefilter))
        {
            Sink::Hold
        } else {
            Sink::Control
        };
        flop_sink.insert(i, sink);
    }
    for i in stage {
        cells[i].flop = false;
        cells[i].clock_gate = true;
    }
    // Readers of each bit.
    let mut readers: HashMap<u64, Vec<usize>> = HashMap::new();
    for (i, c) in cells.iter().enumerate() {
        for &b in &c.inputs {
            readers.entry(b).or_default().push(i);
        }
    }
    // Forward cone of each combinational cell, memoised (the mapped logic is acyclic
    // between flops; the `visiting` guard keeps a malformed loop from recursing forever).
    fn sinks_of(
        i: usize,
        cells: &[Cell],
        readers: &HashMap<u64, Vec<usize>>,
        flop_sink: &HashMap<usize, Sink>,
        memo: &mut HashMap<usize, BTreeSet<Sink>>,
        visiting: &mut BTreeSet<usize>,
    ) -> BTreeSet<Sink> {
        if let Some(s) = memo.get(&i) {
            return s.clone();
        }
        if !visiting.insert(i) {
            return BTreeSet::new();
        }
        let mut out = BTreeSet::new();
        for b in &cells[i].outputs {
            for &r in readers.get(b).into_iter().flatten() {
                match flop_sink.get(&r) {
                    Some(s) => {
                        out.insert(*s);
                    }
                    None => out.extend(sinks_of(r, cells, readers, flop_sink, memo, visiting)),
                }
            }
        }
        visiting.remove(&i);
        memo.insert(i, out.clone());
        out
    }
    let mut memo = HashMap::new();
    let mut split = AreaSplit {
        registers_found: reg_index.len() as u64,
        ..AreaSplit::default()
    };
    for (i, c) in cells.iter().enumerate() {
        let block = match flop_sink.get(&i) {
            _ if c.clock_gate => &mut split.register_file,
            Some(Sink::Reg(_)) => &mut split.register_file,
            Some(Sink::Hold) => &mut split.hold_prefilter,
            Some(Sink::Control) => &mut split.control,
            None => {
                let s = sinks_of(
                    i,
                    &cells,
                    &readers,
                    &flop_sink,
                    &mut memo,
                    &mut BTreeSet::new(),
                );
                let regs = s.iter().filter(|k| matches!(k, Sink::Reg(_))).count();
                if s.contains(&Sink::Hold) {
                    &mut split.hold_prefilter
                } else if regs == 1 {
                    &mut split.register_file
                } else if regs >= 2 {
                    &mut split.adders
                } else {
                    &mut split.control
                }
            }
        };
        block.area_um2 += c.area;
        block.cells += 1;
        block.flops += u64::from(c.flop);
    }
    Ok(split)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_match_contract_state() {
        let n = BlockNames::contract(8);
        assert!(matches(base_name("Y[3]"), &n.register_file));
        // The clock gates' own cells, not the enable logic autoname puts under `cg_<r>.`.
        assert!(is_clock_gate("cg_12.icg") && is_clock_gate("cg_0.enable_latch"));
        assert!(!is_clock_gate("cg_0.en_NAND2X1_Y") && !is_clock_gate("cgx_0.icg"));
        assert!(matches(base_name("Y_12"), &n.register_file));
        assert!(matches(base_name("\\u_pix.held"), &n.hold_prefilter));
        assert!(!matches(base_name("x_lat_enable"), &n.hold_prefilter));
        assert!(!matches(base_name("rd_index"), &n.register_file));
    }
}
