//! The yosys driver: synthesise the pixel onto a liberty, report area and cell count,
//! and keep the mapped netlist (Verilog for OpenSTA, JSON for the area split).
//!
//! Flow: `read_liberty -lib` (cells as black boxes, so the JSON netlist knows their pin
//! directions) → `chparam` (sweeps) → `synth -top -flatten` → `dfflibmap` → `abc -liberty`
//! → `autoname` (instances named after the nets they drive, so OpenSTA's critical path
//! reads `Y[7]_DFFPOSX1_Q`) → `stat -liberty`. Results are cached by a hash of the RTL
//! text, the top, the parameters, the liberty text and the yosys version.

use crate::error::{EdaError, Result};
use crate::fsutil::{Fnv64, write_atomic};
use crate::liberty::Liberty;
use crate::tools::{Tool, tail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What to synthesise.
#[derive(Debug, Clone)]
pub struct SynthSpec {
    /// Verilog sources (all read; `top` selects the pixel module among them).
    pub sources: Vec<PathBuf>,
    /// The module to synthesise (the pixel, not the chip-level ROM).
    pub top: String,
    /// Verilog parameter overrides (`chparam`), e.g. `[("B", 8)]` for sweeps.
    pub params: Vec<(String, i64)>,
    /// The liberty to map onto.
    pub liberty: PathBuf,
    /// Delay target for ABC (ps), used when the liberty carries timing: ABC then maps for
    /// that delay, builds buffer trees (fanout ≤ [`MAX_FANOUT`]) and resizes gates, as a
    /// placement flow would; without it a 1,000-load reset net makes f_max meaningless.
    pub delay_target_ps: Option<f64>,
    /// Wires marked `keep` before synthesis, so ABC keeps them as nets of the netlist (the
    /// sign-off netlist keeps the write enables `we` the testbench watches); empty for the
    /// size report.
    pub keep: Vec<String>,
}

/// Largest fanout ABC's `buffer` leaves on a net.
pub const MAX_FANOUT: u32 = 8;

/// ABC's script for timing-driven mapping. Yosys's default liberty script maps the AIG as
/// `dc2`/`&dch` leave it, which keeps the ripple structure of the adders (a chain of
/// `maj3` cells: 39 bits took 7 ns on sky130 tt) and never buffers a net driven by a flop
/// (flop outputs are ABC's primary inputs). So: two rounds of delay-oriented restructuring
/// (`&synch2`, SOP balancing `&if -g`) before `&nf`, and buffering and sizing that respect
/// the constraints file (`-c`: primary inputs driven by the library's smallest buffer, see
/// [`abc_constraints`]). Measured on the default pixel at 6250 ps: sky130 tt 8.20 → 4.55 ns
/// at +1% area, osu018 6.34 → 3.13 ns.
pub fn abc_timing_script(delay_ps: f64) -> String {
    let d = delay_ps.round().max(1.0);
    format!(
        "strash; &get -n; &fraig -x; &put; scorr; dc2; dretime; strash; &get -n; \
         &st; &synch2; &if -g -K 6; &st; &synch2; &if -g -K 6; &st; &synch2; &dch -f; \
         &nf -D {d}; &put; buffer -c -N {MAX_FANOUT}; upsize -c -D {d}; dnsize -c -D {d}; \
         stime -c -p\n"
    )
}

/// ABC's constraints file (`abc -constr`): every primary input of the mapped logic (a
/// flop's Q, a port) is driven like the library's smallest buffer `drive_cell`, so ABC
/// sizes and buffers high-fanout flop outputs (the sign and operand flops feed every bit
/// of an adder) instead of assuming an ideal driver.
pub fn abc_constraints(drive_cell: &str) -> String {
    format!("set_driving_cell {drive_cell}\n")
}

/// The result of one synthesis run.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Synthesis {
    /// Cache key (hash of RTL, top, parameters, liberty, yosys version).
    pub key: String,
    /// The synthesised module.
    pub top: String,
    /// Total cell area from `stat -liberty` (liberty area unit, µm²), plus the cells whose
    /// area the liberty leaves at 0 counted at their LEF outline (`area_from_lef`).
    pub total_area_um2: f64,
    /// The cells of the netlist counted at their LEF area (µm² each; osu018's `LATCH`,
    /// which its liberty gives `area : 0`), reported "from LEF".
    #[serde(default)]
    pub area_from_lef: BTreeMap<String, f64>,
    /// Number of cell instances.
    pub cell_count: u64,
    /// Instances per cell type.
    pub cells_by_type: BTreeMap<String, u64>,
    /// Mapped netlist, Verilog (for OpenSTA).
    pub netlist_verilog: PathBuf,
    /// Mapped netlist, yosys JSON (for the area split).
    pub netlist_json: PathBuf,
    /// Wall time of the yosys run that produced it (0 when served from the cache run).
    pub yosys_seconds: f64,
}

pub(crate) fn yosys_version(yosys: &Path) -> String {
    Command::new(yosys)
        .arg("-V")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

/// The yosys script for `spec`, writing into `dir`; `constrained`: a timed run passes
/// `dir/abc.constr` ([`abc_constraints`]) to ABC; `clock_gate_map`: the clock-gate module
/// on the liberty's cells ([`crate::clock_gate`]), read over the behavioural one;
/// `latch_map`: the techmap of a latch register file's latches ([`crate::latch`]).
pub fn yosys_script(
    spec: &SynthSpec,
    dir: &Path,
    constrained: bool,
    clock_gate_map: Option<&Path>,
    latch_map: Option<&Path>,
) -> String {
    let lib = spec.liberty.display();
    let mut s = format!("read_liberty -lib {lib}\n");
    for src in &spec.sources {
        s += &format!("read_verilog -sv {}\n", src.display());
    }
    if let Some(map) = clock_gate_map {
        s += &format!("read_verilog -overwrite {}\n", map.display());
    }
    s += &chparam(&spec.params, &spec.top);
    for w in &spec.keep {
        s += &format!("setattr -set keep 1 {}/w:{w}\n", spec.top);
    }
    let abc = match spec.delay_target_ps {
        Some(_) if constrained => format!(
            "abc -script {} -constr {} -liberty {lib}",
            dir.join("abc.script").display(),
            dir.join("abc.constr").display()
        ),
        Some(_) => format!(
            "abc -script {} -liberty {lib}",
            dir.join("abc.script").display()
        ),
        None => format!("abc -liberty {lib}"),
    };
    s += &format!("synth -top {} -flatten\n", spec.top);
    if let Some(map) = latch_map {
        s += &format!("techmap -map {}\n", map.display());
    }
    s += &format!(
        "dfflibmap -liberty {lib}\n\
         {abc}\n\
         opt_clean\n\
         autoname\n\
         stat -liberty {lib}\n\
         write_verilog -noattr {net_v}\n\
         write_json {net_json}\n",
        net_v = dir.join("netlist.v").display(),
        net_json = dir.join("netlist.json").display(),
    );
    s
}

/// Synthesises `spec` under `cache_root/<key>/`, or returns the cached result.
pub fn synthesise(spec: &SynthSpec, cache_root: &Path) -> Result<Synthesis> {
    let yosys = Tool::Yosys.locate()?;
    let lib = Liberty::load(&spec.liberty)?;
    lib.require_pixel_cells()?;
    // Timing-driven mapping only makes sense on a liberty with timing.
    let spec = &SynthSpec {
        delay_target_ps: spec
            .delay_target_ps
            .filter(|d| lib.has_timing && d.is_finite() && *d > 0.0),
        ..spec.clone()
    };
    let mut h = Fnv64::default();
    h.feed(b"tofprobe-synth-v2").feed(spec.top.as_bytes());
    // A clock-gated register file's gates become the liberty's cells (refused, naming the
    // option, on a liberty without them).
    let mut clock_gate_map = None;
    for src in &spec.sources {
        let text = std::fs::read(src).map_err(|_| EdaError::RtlMissing { path: src.clone() })?;
        h.feed(&text);
        if let Some(module) =
            crate::clock_gate::module_in(&String::from_utf8_lossy(&text), &spec.top)
        {
            let cells = crate::clock_gate::ClockGateCells::from_liberty(&lib)?;
            clock_gate_map = Some(cells.module_verilog(&module));
        }
    }
    if let Some(m) = &clock_gate_map {
        h.feed(b"clock_gate").feed(m.as_bytes());
    }
    // A latch register file's latches become the liberty's D latch (refused, naming the
    // option, on a liberty without one).
    let latch_map = if spec
        .sources
        .iter()
        .any(|src| std::fs::read_to_string(src).is_ok_and(|t| crate::latch::in_source(&t)))
    {
        let m = crate::latch::LatchCells::from_liberty(&lib)?.techmap_verilog();
        h.feed(b"latch").feed(m.as_bytes());
        Some(m)
    } else {
        None
    };
    for (cell, area) in &lib.area_from_lef {
        h.feed(b"lef-area")
            .feed(cell.as_bytes())
            .feed(&area.to_le_bytes());
    }
    for (k, v) in &spec.params {
        h.feed(k.as_bytes()).feed(&v.to_le_bytes());
    }
    if let Some(d) = spec.delay_target_ps {
        h.feed(abc_timing_script(d).as_bytes());
    }
    for w in &spec.keep {
        h.feed(b"keep").feed(w.as_bytes());
    }
    let lib_text =
        tofprobe_io::read_bounded(&spec.liberty, tofprobe_io::bounded::MAX_LIBERTY_BYTES).map_err(
            |e| EdaError::LibertyUnreadable {
                path: spec.liberty.clone(),
                reason: e.to_string(),
            },
        )?;
    h.feed(&lib_text).feed(yosys_version(&yosys).as_bytes());
    let key = h.hex();
    let dir = cache_root.join(&key);
    let result_path = dir.join("synthesis.json");
    // Built in a private directory and published whole under the key's lock, checked on
    // every read (tofprobe_io::cache::entry): a concurrent run waits for this synthesis and
    // reuses it, and never reads a netlist half written.
    let (_, reused) = tofprobe_io::cache::entry(
        cache_root,
        &key,
        |tmp| {
            build_entry(
                &BuildInputs {
                    spec,
                    lib: &lib,
                    lib_text: &lib_text,
                    yosys: &yosys,
                    clock_gate_map: clock_gate_map.as_deref(),
                    latch_map: latch_map.as_deref(),
                    key: &key,
                    cache_root,
                },
                tmp,
                &dir,
            )
        },
        |p, e| EdaError::io("publishing the synthesis cache entry", p, e),
    )?;
    let text = std::fs::read_to_string(&result_path)
        .map_err(|e| EdaError::io("reading", &result_path, e))?;
    let mut syn: Synthesis = serde_json::from_str(&text).map_err(|e| EdaError::Json {
        what: result_path.display().to_string(),
        source: e,
    })?;
    if reused {
        syn.yosys_seconds = 0.0;
    }
    Ok(syn)
}

/// What one synthesis entry is built from.
struct BuildInputs<'a> {
    spec: &'a SynthSpec,
    lib: &'a Liberty,
    lib_text: &'a [u8],
    yosys: &'a Path,
    clock_gate_map: Option<&'a str>,
    latch_map: Option<&'a str>,
    key: &'a str,
    cache_root: &'a Path,
}

/// Runs yosys for `inputs` in the private directory `tmp`, leaving the netlists, the log
/// and `synthesis.json` there; the result names the files at `dir`, where the entry is
/// published.
fn build_entry(inputs: &BuildInputs, tmp: &Path, dir: &Path) -> Result<()> {
    let BuildInputs {
        spec,
        lib,
        lib_text,
        yosys,
        clock_gate_map,
        latch_map,
        key,
        cache_root,
    } = *inputs;
    let result_path = tmp.join("synthesis.json");
    // Map onto a copy with the cells synthesis must not use marked `dont_use` (ABC honours
    // it), when the liberty has such cells; the area and timing of the others are the same.
    let text = String::from_utf8_lossy(lib_text);
    let marked = crate::liberty::mark_not_for_synthesis(&text);
    let map_spec = match &marked {
        Some(m) => {
            // One copy per liberty text beside the cache entries, not one per entry (12 MB
            // for a sky130 corner).
            let mut lh = Fnv64::default();
            lh.feed(m.as_bytes());
            let map_lib = cache_root.join(format!("map-{}.lib", lh.hex()));
            if !map_lib.exists() {
                write_atomic(&map_lib, m.as_bytes())?;
            }
            SynthSpec {
                liberty: map_lib,
                ..spec.clone()
            }
        }
        None => spec.clone(),
    };
    let mut constrained = false;
    if let Some(d) = spec.delay_target_ps {
        write_atomic(&tmp.join("abc.script"), abc_timing_script(d).as_bytes())?;
        // `drive_cell` already skips the cells the map copy marks: no second parse.
        if let Some(cell) = lib.drive_cell() {
            write_atomic(&tmp.join("abc.constr"), abc_constraints(cell).as_bytes())?;
            constrained = true;
        }
    }
    let latch_path = tmp.join("latch_map.v");
    if let Some(m) = latch_map {
        write_atomic(&latch_path, m.as_bytes())?;
    }
    let map_path = tmp.join("clock_gate_map.v");
    if let Some(m) = clock_gate_map {
        write_atomic(&map_path, m.as_bytes())?;
    }
    let script_path = tmp.join("synth.ys");
    write_atomic(
        &script_path,
        yosys_script(
            &map_spec,
            tmp,
            constrained,
            clock_gate_map.map(|_| map_path.as_path()),
            latch_map.map(|_| latch_path.as_path()),
        )
        .as_bytes(),
    )?;
    let start = std::time::Instant::now();
    let out = Command::new(yosys)
        .arg("-q")
        .arg("-l")
        .arg(tmp.join("yosys.log"))
        .arg(&script_path)
        .output()
        .map_err(|e| EdaError::io("running", yosys, e))?;
    let seconds = start.elapsed().as_secs_f64();
    let log = std::fs::read_to_string(tmp.join("yosys.log")).unwrap_or_default();
    if !out.status.success() {
        let mut text = log.clone();
        text += &String::from_utf8_lossy(&out.stderr);
        // ABC gives up when the liberty's gates cannot express the logic (e.g. only an
        // inverter): say that about the liberty rather than dumping ABC's script.
        if text.contains("Current library is not available")
            || text.contains("Can't open ABC output file")
        {
            return Err(EdaError::LibertyIncomplete {
                path: spec.liberty.clone(),
                what: "combinational gate set that abc can map logic onto (abc rejected it)",
                why: "a functionally complete set of gates (e.g. NAND/NOR, AND/OR with inverters, XOR, MUX) for its adders and control",
            });
        }
        return Err(EdaError::ToolFailed {
            tool: "yosys",
            status: out
                .status
                .code()
                .map_or("killed by a signal".into(), |c| c.to_string()),
            log_tail: tail(&text, 15),
        });
    }
    let (cells_by_type, cell_count, mut total_area_um2) = parse_stat(&log)?;
    // `stat -liberty` counts a cell of liberty area 0 as nothing: count it at its LEF outline.
    let mut area_from_lef = BTreeMap::new();
    for (cell, area) in &lib.area_from_lef {
        if let Some(&n) = cells_by_type.get(cell) {
            total_area_um2 += n as f64 * area;
            area_from_lef.insert(cell.clone(), *area);
        }
    }
    let unmapped: Vec<&str> = cells_by_type
        .keys()
        .filter(|t| t.starts_with('$'))
        .map(String::as_str)
        .collect();
    if !unmapped.is_empty() {
        return Err(EdaError::Unmapped {
            path: spec.liberty.clone(),
            cells: unmapped.join(", "),
        });
    }
    let syn = Synthesis {
        key: key.to_string(),
        top: spec.top.clone(),
        total_area_um2,
        area_from_lef,
        cell_count,
        cells_by_type,
        netlist_verilog: dir.join("netlist.v"),
        netlist_json: dir.join("netlist.json"),
        yosys_seconds: seconds,
    };
    let json = serde_json::to_vec_pretty(&syn).map_err(|e| EdaError::Json {
        what: result_path.display().to_string(),
        source: e,
    })?;
    write_atomic(&result_path, &json)?;
    Ok(())
}

/// Parses the LAST `stat -liberty` block of a yosys log: cells per type, the cell count
/// and the chip area.
pub fn parse_stat(log: &str) -> Result<(BTreeMap<String, u64>, u64, f64)> {
    let parse_err = |what| EdaError::Parse {
        tool: "yosys",
        what,
        tail: tail(log, 20),
    };
    let area_pos = log
        .rfind("Chip area for module")
        .ok_or_else(|| parse_err("`Chip area for module` (stat -liberty)"))?;
    let block_start = log[..area_pos]
        .rfind("Number of cells:")
        .ok_or_else(|| parse_err("`Number of cells:`"))?;
    let area_line = log[area_pos..].lines().next().unwrap_or_default();
    let area: f64 = area_line
        .rsplit(':')
        .next()
        .and_then(|v| v.trim().parse().ok())
        .filter(|a: &f64| a.is_finite())
        .ok_or_else(|| parse_err("a number after `Chip area for module`"))?;
    let mut lines = log[block_start..area_pos].lines();
    let count: u64 = lines
        .next()
        .and_then(|l| l.rsplit(':').next())
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| parse_err("a number after `Number of cells:`"))?;
    let mut by_type = BTreeMap::new();
    for line in lines {
        let mut it = line.split_whitespace();
        if let (Some(name), Some(n), None) = (it.next(), it.next(), it.next())
            && let Ok(n) = n.parse::<u64>()
        {
            by_type.insert(name.to_string(), n);
        }
    }
    Ok((by_type, count, area))
}

/// The parameter overrides of `top` as one yosys `chparam` line (empty without any): the
/// synthesis script's and the equivalence script's gold side (crates/eda/src/equiv.rs).
pub(crate) fn chparam(params: &[(String, i64)], top: &str) -> String {
    if params.is_empty() {
        return String::new();
    }
    let sets: String = params
        .iter()
        .map(|(k, v)| format!(" -set {k} {v}"))
        .collect();
    format!("chparam{sets} {top}\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_last_stat_block() {
        let log = "   Number of cells:   5\n     $_AND_  5\n\n\
                   === top ===\n   Number of cells:                799\n\
                   \x20    AND2X1                         24\n     DFFPOSX1   120\n\n\
                   \x20  Chip area for module '\\top': 32690.000000\n";
        let (types, count, area) = parse_stat(log).unwrap();
        assert_eq!(count, 799);
        assert_eq!(area, 32690.0);
        assert_eq!(types.get("DFFPOSX1"), Some(&120));
        assert!(
            !types.contains_key("$_AND_"),
            "earlier generic stat must be ignored"
        );
    }

    #[test]
    fn script_sets_parameters_and_keeps_rom_out_by_top() {
        let spec = SynthSpec {
            sources: vec!["a.v".into()],
            top: "pixel".into(),
            params: vec![("B".into(), 4), ("W".into(), 12)],
            liberty: "l.lib".into(),
            delay_target_ps: None,
            keep: vec![],
        };
        let s = yosys_script(&spec, Path::new("/d"), false, None, None);
        assert!(!s.contains("setattr") && !s.contains("-overwrite"));
        assert!(s.contains("chparam -set B 4 -set W 12 pixel"));
        assert!(s.contains("synth -top pixel -flatten"));
        assert!(s.contains("abc -liberty l.lib"));
        let timed = SynthSpec {
            delay_target_ps: Some(6250.0),
            ..spec
        };
        let s = yosys_script(&timed, Path::new("/d"), false, None, None);
        assert!(
            s.contains("abc -script /d/abc.script -liberty l.lib"),
            "{s}"
        );
        let s = yosys_script(
            &timed,
            Path::new("/d"),
            true,
            Some(Path::new("/d/cg.v")),
            None,
        );
        // The clock gates' cells are read over the behavioural module, before synthesis.
        let (read, synth) = (
            s.find("-overwrite /d/cg.v").unwrap(),
            s.find("synth -top").unwrap(),
        );
        assert!(read < synth, "{s}");
        // A latch register file's latches are mapped after synthesis, before the flops.
        let sl = yosys_script(
            &timed,
            Path::new("/d"),
            false,
            None,
            Some(Path::new("/d/l.v")),
        );
        let (synth, map, dff) = (
            sl.find("synth -top").unwrap(),
            sl.find("techmap -map /d/l.v").unwrap(),
            sl.find("dfflibmap").unwrap(),
        );
        assert!(synth < map && map < dff, "{sl}");
        assert!(
            s.contains("abc -script /d/abc.script -constr /d/abc.constr -liberty l.lib"),
            "{s}"
        );
        let abc = abc_timing_script(6250.0);
        assert!(
            abc.contains("&if -g -K 6;")
                && abc.contains("&nf -D 6250;")
                && abc.contains("buffer -c -N 8;")
                && abc.contains("upsize -c -D 6250;"),
            "{abc}"
        );
        assert_eq!(abc_constraints("BUFX2"), "set_driving_cell BUFX2\n");
    }
}
