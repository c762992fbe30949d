//! Gate-level simulation: the synthesised netlist of the pixel, compiled with the standard
//! cells' own Verilog models, replays the golden vectors through the plain testbench
//! (testbench/tb.v) under Icarus — bit-exact, first mismatch reported as for the RTL.
//!
//! What is simulated: the RTL directory's top and probe ROM (chip level, `$readmemh`, kept
//! as RTL) around the netlist of the pixel module. The testbench watches the pixel's
//! write-enable vector `we` and its registers `y[r]`; the netlist keeps `we` as a net (the
//! synthesis marks it `keep`) and names each register's flop outputs `\y[r]`, and a thin
//! wrapper module with the pixel's name and ports instantiates the netlist (renamed
//! `<pixel>_gates`) and presents `we` and the array `y` by hierarchical reference. The
//! wrapper holds no logic: every output comes from the netlist.
//!
//! Cell models are simulated functionally, as gate-level sign-off does (timing is
//! OpenSTA's job; the testbench's 2 ns cycle is no physical clock): combinational cells
//! with zero delay, and a 10 ps delay on every sequential primitive so that flops fed by
//! flops of the same edge do not race. sky130 gets it from its own switches
//! (`-DFUNCTIONAL -DUNIT_DELAY=#0.01`); osu018's models have no such switch, so the
//! driver writes a copy whose `udp_dff`/`udp_tlat`/`udp_rslat` instances carry `#0.01`
//! (its `specify` delays are ignored: Icarus runs without `-gspecify`).

use crate::error::CosimError;
use crate::harness::{RunOutcome, parse_output};
use crate::icarus::TB_V;
use crate::tools::require;
use std::io::{Error, ErrorKind};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The standard-cell Verilog models a netlist is compiled with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CellModels {
    /// osu018 (Debian `qflow-tech-osu018`): one file of cells and UDPs.
    Osu018 { models: PathBuf },
    /// sky130_fd_sc_hd: the cells (`sky130_fd_sc_hd.v`, maybe gzipped) and the UDPs
    /// they instantiate (`primitives.v`).
    Sky130 {
        models: PathBuf,
        primitives: PathBuf,
    },
}

/// Debian's osu018 cell models.
pub const OSU018_MODELS: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.v";

/// The delay given to sequential primitives (ns, the models' time unit).
pub const SEQUENTIAL_DELAY_NS: &str = "0.01";

/// What to simulate.
#[derive(Debug, Clone)]
pub struct GateLevelRun<'a> {
    /// The mapped netlist of the pixel module (`write_verilog -noattr`), `we` kept.
    pub netlist: &'a Path,
    /// Its cell library's models.
    pub cells: &'a CellModels,
    /// The RTL directory (top, ROM and its hex; its pixel file is replaced by the netlist).
    pub rtl_dir: &'a Path,
    /// The golden vectors (with `tb_params.vh`).
    pub vec_dir: &'a Path,
    /// The top module (e.g. `tofprobe_top`).
    pub top: &'a str,
    /// The pixel module the netlist implements (e.g. `tofprobe_pixel`).
    pub pixel: &'a str,
    /// Scratch directory.
    pub work: &'a Path,
}

fn invalid(path: &Path, msg: String) -> CosimError {
    CosimError::io(path, Error::new(ErrorKind::InvalidData, msg))
}

fn read(path: &Path) -> Result<String, CosimError> {
    std::fs::read_to_string(path).map_err(|e| CosimError::io(path, e))
}

fn write(path: &Path, text: &str) -> Result<(), CosimError> {
    std::fs::write(path, text).map_err(|e| CosimError::io(path, e))
}

/// The netlist's module header, port declarations, and the registers it exposes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NetlistShape {
    /// `input ...;` / `output ...;` declarations, verbatim.
    pub ports: Vec<String>,
    /// Port names in header order.
    pub port_names: Vec<String>,
    /// Width of the `we` vector (= registers R).
    pub registers: usize,
    /// Width of each `\y[r]` (= W).
    pub width: usize,
}

fn range_width(decl: &str) -> usize {
    // `[38:0]` → 39; no range → 1.
    decl.split_once('[')
        .and_then(|(_, r)| r.split_once(']'))
        .and_then(|(r, _)| r.split_once(':'))
        .and_then(|(a, b)| {
            Some(
                a.trim()
                    .parse::<i64>()
                    .ok()?
                    .abs_diff(b.trim().parse::<i64>().ok()?) as usize
                    + 1,
            )
        })
        .unwrap_or(1)
}

/// Reads the shape of `pixel` in a yosys netlist. Errors name the netlist and what is
/// missing (a netlist synthesised without `keep` on `we` cannot feed the testbench).
pub fn netlist_shape(path: &Path, text: &str, pixel: &str) -> Result<NetlistShape, CosimError> {
    let header = format!("module {pixel}(");
    let start = text.find(&header).ok_or_else(|| {
        invalid(
            path,
            format!("no `{header}...` line: not a yosys netlist of the pixel module `{pixel}`"),
        )
    })?;
    let body = &text[start..];
    let body = &body[..body.find("endmodule").unwrap_or(body.len())];
    let names_end = body.find(");").unwrap_or(0);
    let port_names: Vec<String> = body[header.len()..names_end]
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    let ports: Vec<String> = body
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("input ") || l.starts_with("output "))
        .map(str::to_string)
        .collect();
    if ports.len() != port_names.len() {
        return Err(invalid(
            path,
            format!(
                "{} port names but {} declarations in `{pixel}`",
                port_names.len(),
                ports.len()
            ),
        ));
    }
    let we = body
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("wire ") && l.trim_end_matches(';').ends_with(" we"))
        .ok_or_else(|| {
            invalid(
                path,
                "has no `we` net: synthesise the pixel with `keep` on `we` (tofprobe_eda::signoff) so the testbench can watch the register writes".into(),
            )
        })?;
    let registers = range_width(we);
    let y0 = body
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("wire ") && l.contains("\\y[0] "))
        .ok_or_else(|| {
            invalid(
                path,
                "has no `\\y[0]` register net (the pixel's register file)".into(),
            )
        })?;
    Ok(NetlistShape {
        ports,
        port_names,
        registers,
        width: range_width(y0),
    })
}

/// The wrapper: module `pixel` with the netlist's ports, the netlist instance, and `we`/`y`
/// by hierarchical reference (observation only).
pub fn wrapper(pixel: &str, shape: &NetlistShape) -> String {
    let mut s = format!(
        "// Generated by tofprobe-cosim (gate_level): the pixel's ports around its netlist, with the\n\
         // write enables and registers the testbench watches. DO NOT EDIT.\n\
         module {pixel}({});\n",
        shape.port_names.join(", ")
    );
    for p in &shape.ports {
        s += &format!("  {p}\n");
    }
    let conns: Vec<String> = shape
        .port_names
        .iter()
        .map(|n| format!(".{n}({n})"))
        .collect();
    s += &format!("  {pixel}_gates gates ({});\n", conns.join(", "));
    s += &format!("  wire [{}:0] we = gates.we;\n", shape.registers - 1);
    s += &format!(
        "  wire [{}:0] y [0:{}];\n",
        shape.width - 1,
        shape.registers - 1
    );
    for r in 0..shape.registers {
        s += &format!("  assign y[{r}] = gates.\\y[{r}] ;\n");
    }
    s + "endmodule\n"
}

/// osu018's models with a delay on each sequential UDP instance (see the module docs).
pub fn delayed_osu018(models: &str) -> String {
    let mut out = String::with_capacity(models.len() + 1024);
    for line in models.lines() {
        let t = line.trim_start();
        let udp = ["udp_dff", "udp_tlat", "udp_rslat"].into_iter().find(|u| {
            t.strip_prefix(u)
                .is_some_and(|r| r.trim_start().starts_with('('))
        });
        match udp {
            Some(u) => {
                let indent = &line[..line.len() - t.len()];
                out += &format!(
                    "{indent}{u} #{SEQUENTIAL_DELAY_NS} {}",
                    &t[u.len()..].trim_start()
                );
            }
            None => out += line,
        }
        out.push('\n');
    }
    out
}

fn plain_models(path: &Path, work: &Path) -> Result<PathBuf, CosimError> {
    if path.extension().is_none_or(|e| e != "gz") {
        return Ok(path.to_path_buf());
    }
    let out = work.join(path.file_stem().unwrap_or_default());
    let run = Command::new("gzip")
        .arg("-dc")
        .arg(path)
        .output()
        .map_err(|e| CosimError::io(path, e))?;
    if !run.status.success() {
        return Err(invalid(
            path,
            format!(
                "gzip -dc failed: {}",
                String::from_utf8_lossy(&run.stderr).trim()
            ),
        ));
    }
    std::fs::write(&out, &run.stdout).map_err(|e| CosimError::io(&out, e))?;
    Ok(out)
}

/// Compiles the netlist with its cell models, the RTL top and ROM and tb.v, runs it from
/// the RTL directory and parses the completion line.
pub fn run(g: &GateLevelRun<'_>) -> Result<RunOutcome, CosimError> {
    let iverilog = require("iverilog")?;
    let vvp = require("vvp")?;
    std::fs::create_dir_all(g.work).map_err(|e| CosimError::io(g.work, e))?;
    let text = read(g.netlist)?;
    let shape = netlist_shape(g.netlist, &text, g.pixel)?;
    let gates = g.work.join("netlist.v");
    write(
        &gates,
        &text.replacen(
            &format!("module {}(", g.pixel),
            &format!("module {}_gates(", g.pixel),
            1,
        ),
    )?;
    let wrap = g.work.join("pixel_wrapper.v");
    write(&wrap, &wrapper(g.pixel, &shape))?;
    let tb = g.work.join("tb.v");
    write(&tb, TB_V)?;

    // The RTL directory without the pixel's own file.
    let pixel_decl = format!("module {}", g.pixel);
    let mut rtl: Vec<PathBuf> = std::fs::read_dir(g.rtl_dir)
        .map_err(|e| CosimError::io(g.rtl_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .collect();
    rtl.sort();
    let mut kept = Vec::new();
    for p in rtl {
        let src = read(&p)?;
        let defines_pixel = src.lines().any(|l| {
            l.trim_start()
                .strip_prefix(&pixel_decl)
                .is_some_and(|r| r.starts_with([' ', '(', '#']))
        });
        if !defines_pixel {
            kept.push(p);
        }
    }

    let mut cmd = Command::new(&iverilog);
    cmd.args(["-g2005", "-o"])
        .arg(g.work.join("gl.vvp"))
        .arg(format!("-I{}", g.vec_dir.display()))
        .arg(format!("-DTB_TOP={}", g.top))
        .arg(format!("-DTB_VECTORS=\"{}/\"", g.vec_dir.display()));
    match g.cells {
        CellModels::Osu018 { models } => {
            let delayed = g.work.join("osu018_cells_delayed.v");
            write(&delayed, &delayed_osu018(&read(models)?))?;
            cmd.arg(&tb)
                .arg(&wrap)
                .arg(&gates)
                .args(&kept)
                .arg(&delayed);
        }
        CellModels::Sky130 { models, primitives } => {
            let models = plain_models(models, g.work)?;
            cmd.arg("-DFUNCTIONAL")
                .arg(format!("-DUNIT_DELAY=#{SEQUENTIAL_DELAY_NS}"))
                .arg(&tb)
                .arg(&wrap)
                .arg(&gates)
                .args(&kept)
                .arg(primitives)
                .arg(&models);
        }
    }
    let out = cmd.output().map_err(|e| CosimError::io(&iverilog, e))?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = err.lines().rev().take(20).collect();
        return Err(CosimError::ToolFailed {
            tool: "iverilog (gate level)",
            status: out.status.to_string(),
            output: tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
        });
    }
    let run = Command::new(&vvp)
        .current_dir(g.rtl_dir)
        .arg("-n")
        .arg(g.work.join("gl.vvp"))
        .output()
        .map_err(|e| CosimError::io(&vvp, e))?;
    parse_output(
        "icarus gate-level testbench",
        &format!(
            "{}{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const NET: &str = "module tofprobe_pixel(clk, rd_data);\n  wire [1:0] we;\n  wire [3:0] \\y[0] ;\n  wire [3:0] \\y[1] ;\n  input clk;\n  wire clk;\n  output [3:0] rd_data;\nendmodule\n";

    #[test]
    fn shape_and_wrapper_of_a_netlist() {
        let s = netlist_shape(Path::new("n.v"), NET, "tofprobe_pixel").unwrap();
        assert_eq!((s.registers, s.width), (2, 4));
        assert_eq!(s.port_names, ["clk", "rd_data"]);
        let w = wrapper("tofprobe_pixel", &s);
        assert!(
            w.contains("tofprobe_pixel_gates gates (.clk(clk), .rd_data(rd_data));"),
            "{w}"
        );
        assert!(w.contains("assign y[1] = gates.\\y[1] ;"), "{w}");
        assert!(w.contains("wire [1:0] we = gates.we;"), "{w}");
    }

    #[test]
    fn a_netlist_without_we_is_named_with_the_fix() {
        let msg = netlist_shape(
            Path::new("n.v"),
            &NET.replace(" we;", " wx;"),
            "tofprobe_pixel",
        )
        .unwrap_err()
        .to_string();
        assert!(
            msg.contains("n.v") && msg.contains("keep") && msg.contains("`we`"),
            "{msg}"
        );
        let msg = netlist_shape(Path::new("n.v"), NET, "other")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("module other("), "{msg}");
    }

    #[test]
    fn osu018_sequential_udps_get_a_delay() {
        let m = "   udp_dff (DS0000, D, CLK, 1'B0, 1'B0, NOTIFIER);\n   not (P0002, DS0000);\nprimitive udp_dff (out, in);\n";
        let d = delayed_osu018(m);
        assert!(d.contains("   udp_dff #0.01 (DS0000, D, CLK"), "{d}");
        assert!(d.contains("   not (P0002, DS0000);"), "{d}");
        assert!(
            d.contains("primitive udp_dff (out, in);"),
            "the primitive's definition stays: {d}"
        );
    }
}
