//! The FuseSoC (CAPI2) core rendered beside the generated RTL (`templates/tofprobe.core`),
//! so users run the pixel in their own tool: `lint` (Verilator lint-only), `synth` (yosys,
//! with the rendered `templates/yosys_synth.tcl`) and, when told where the golden vectors
//! and the testbench are ([`CoreSim`]), `sim` (Icarus replays the vectors through
//! testbench/tb.v, its macros from the rendered `templates/tb_defines.vh`). Every path in
//! the core is relative to the core file, so the directory can move with what it refers to.

use std::path::{Component, Path, PathBuf};

use askama::Template;
use tofprobe_pixel::PixelParams;

use crate::error::RtlError;
use crate::render::{RenderOptions, RtlFile, header};

/// The vector files testbench/tb.v reads (`$readmemh`), copied into the simulator's work
/// directory; `tb_params.vh` is included.
pub const VECTOR_FILES: &[&str] = &["stimulus.hex", "readout.hex", "trace.hex", "pins.hex"];

/// Where the core's `sim` target finds the golden vectors and the testbench: paths relative
/// to the core's directory (see [`relative_path`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoreSim {
    /// The vectors directory (`tofprobe vectors` of the same configuration and overrides).
    pub vectors_dir: String,
    /// The testbench file (the repository's testbench/tb.v).
    pub testbench: String,
}

#[derive(Template)]
#[template(path = "tofprobe.core", escape = "none")]
struct CoreT {
    header: String,
    vlnv_name: String,
    version: &'static str,
    description: String,
    rtl_files: Vec<String>,
    rom_hex: Option<String>,
    sim: Option<SimT>,
    yosys_script: String,
    top: String,
}

/// The `tb` fileset and the simulation targets: Verilog sources (the pixel's macro file and
/// testbench, or the array kit's testbench), the vectors' include, the vector data copied to
/// the tool's work directory (path, name there), the testbench's top and whether a Verilator
/// target (`sim_verilator`, `verilator --binary`) is rendered beside Icarus's `sim`.
struct SimT {
    sources: Vec<String>,
    include: String,
    data: Vec<(String, String)>,
    toplevel: &'static str,
    verilator: bool,
}

#[derive(Template)]
#[template(path = "yosys_synth.tcl", escape = "none")]
struct YosysT {
    header: String,
}

#[derive(Template)]
#[template(path = "tb_defines.vh", escape = "none")]
struct DefinesT {
    header: String,
    top: String,
}

fn render_err(template: &'static str) -> impl Fn(askama::Error) -> RtlError {
    move |e| RtlError::Render {
        template,
        message: e.to_string(),
    }
}

/// The rendered header as `#` comment lines (YAML, Tcl).
fn hash_header(p: &PixelParams, template: &str, o: &RenderOptions) -> String {
    header(p, template, o)
        .lines()
        .map(|l| format!("#{}", l.strip_prefix("//").unwrap_or(l)))
        .collect::<Vec<_>>()
        .join("\n")
}

/// File name of the core for a module prefix.
pub fn core_file_name(module_prefix: &str) -> String {
    format!("{module_prefix}.core")
}

/// Renders the core and its helper files for the already rendered `rtl` (the output of
/// [`crate::render()`] for the same `p` and `o`): the core, the yosys script and, with `sim`,
/// the testbench's macro file. Names derive from `o.module_prefix` (a validated
/// identifier); the paths in `sim` must pass [`check_core_path`].
pub fn render_core(
    p: &PixelParams,
    rtl: &[RtlFile],
    o: &RenderOptions,
    sim: Option<&CoreSim>,
) -> Result<Vec<RtlFile>, RtlError> {
    crate::naming::validate_identifier("module_prefix", &o.module_prefix)?;
    if let Some(s) = sim {
        check_core_path("core vectors directory", &s.vectors_dir)?;
        check_core_path("core testbench", &s.testbench)?;
    }
    let prefix = &o.module_prefix;
    let (_, _, top) = crate::naming::module_names(prefix);
    let sim = sim.map(|s| SimT {
        sources: vec![defines_name(prefix), s.testbench.clone()],
        include: format!("{}/tb_params.vh", s.vectors_dir),
        data: VECTOR_FILES
            .iter()
            .map(|v| (format!("{}/{v}", s.vectors_dir), v.to_string()))
            .collect(),
        toplevel: "tb",
        verilator: false,
    });
    core_files(
        p,
        rtl,
        o,
        sim,
        top,
        format!("{prefix}_pixel"),
        String::new(),
    )
}

/// The core of an array's rendered files (`crate::render_array`): its toplevel the
/// `<prefix>_array` module of `rows` × `cols` pixels, targets `lint` and `synth`; with
/// `kit` (the set carries its verification kit, [`crate::kit`]: the testbench and the
/// vectors beside the RTL) also `sim` (Icarus) and `sim_verilator` (`verilator --binary`),
/// both running the kit's testbench against the set's RTL.
pub fn render_array_core(
    p: &PixelParams,
    rtl: &[RtlFile],
    o: &RenderOptions,
    rows: usize,
    cols: usize,
    kit: bool,
) -> Result<Vec<RtlFile>, RtlError> {
    crate::naming::validate_identifier("module_prefix", &o.module_prefix)?;
    let prefix = &o.module_prefix;
    let top = crate::array::array_module_name(prefix);
    let sim = kit.then(|| SimT {
        sources: vec![crate::kit::KIT_TESTBENCH.to_string()],
        include: crate::kit::KIT_PARAMS.to_string(),
        data: crate::kit::KIT_DATA
            .iter()
            .map(|d| (d.to_string(), d.to_string()))
            .collect(),
        toplevel: crate::kit::KIT_TOP,
        verilator: true,
    });
    core_files(
        p,
        rtl,
        o,
        sim,
        top.clone(),
        top,
        format!("{rows} x {cols} array of the "),
    )
}

/// The pixel's macro file for testbench/tb.v (`TB_TOP`, `TB_VECTORS`).
fn defines_name(prefix: &str) -> String {
    format!("{prefix}_tb_defines.vh")
}

fn core_files(
    p: &PixelParams,
    rtl: &[RtlFile],
    o: &RenderOptions,
    sim: Option<SimT>,
    top: String,
    vlnv: String,
    what: String,
) -> Result<Vec<RtlFile>, RtlError> {
    let prefix = &o.module_prefix;
    let yosys_script = format!("{prefix}_yosys_synth.tcl");
    let defines = defines_name(prefix);
    let pixel_sim = sim.as_ref().is_some_and(|s| s.sources.contains(&defines));
    let mut files = Vec::new();
    let core = CoreT {
        header: hash_header(p, "tofprobe.core", o),
        vlnv_name: format!("tofprobe:tofprobe:{vlnv}"),
        version: env!("CARGO_PKG_VERSION"),
        description: format!(
            "tofprobe {what}one-bit frequency-probing dToF pixel ({:?}, B={}, U={}, A={}, C={}, W={}, N={}, L={}, hash {})",
            p.mode,
            p.bins,
            p.haar_scales,
            p.adders,
            p.cycles_per_pulse,
            p.width,
            p.frame_pulses,
            p.rom_depth,
            crate::naming::config_hash_with_prefix(p, prefix)
        ),
        rtl_files: rtl
            .iter()
            .filter(|f| f.name.ends_with(".v"))
            .map(|f| f.name.clone())
            .collect(),
        rom_hex: rtl
            .iter()
            .find(|f| f.name.ends_with(".hex"))
            .map(|f| f.name.clone()),
        sim,
        yosys_script: yosys_script.clone(),
        top: top.clone(),
    };
    files.push(RtlFile {
        name: core_file_name(prefix),
        template: "tofprobe.core",
        contents: core.render().map_err(render_err("tofprobe.core"))? + "\n",
    });
    let y = YosysT {
        header: hash_header(p, "yosys_synth.tcl", o),
    };
    files.push(RtlFile {
        name: yosys_script,
        template: "yosys_synth.tcl",
        contents: y.render().map_err(render_err("yosys_synth.tcl"))? + "\n",
    });
    if pixel_sim {
        let d = DefinesT {
            header: header(p, "tb_defines.vh", o),
            top,
        };
        files.push(RtlFile {
            name: defines,
            template: "tb_defines.vh",
            contents: d.render().map_err(render_err("tb_defines.vh"))? + "\n",
        });
    }
    Ok(files)
}

/// Accepts a relative path that can stand unquoted in the core's YAML and in a FuseSoC file
/// list: `[A-Za-z0-9._+-]` components separated by `/`, not starting with `-`, at most 200
/// characters. Anything else (a newline, `:`, `#`, a space, quotes) could change the core's
/// meaning, so it is refused, not mangled.
pub fn check_core_path(field: &'static str, value: &str) -> Result<(), RtlError> {
    let ok = !value.is_empty()
        && value.len() <= 200
        && !value.starts_with('-')
        && !value.starts_with('/')
        && value
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._+-/".contains(c));
    if ok {
        Ok(())
    } else {
        Err(RtlError::CorePath {
            field,
            value: value.to_string(),
        })
    }
}

/// `path` made absolute (against `cwd` when relative) and lexically normalised.
fn absolute(cwd: &Path, path: &Path) -> Vec<String> {
    let mut parts: Vec<String> = Vec::new();
    let full: PathBuf = if path.is_absolute() {
        path.to_path_buf()
    } else {
        cwd.join(path)
    };
    for c in full.components() {
        match c {
            Component::Normal(n) => parts.push(n.to_string_lossy().into_owned()),
            Component::ParentDir => {
                parts.pop();
            }
            Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
        }
    }
    parts
}

/// The path of `target` relative to the directory `from` (both relative to `cwd` unless
/// absolute), lexically: `X`, `./X/` and `a/../X` give the same text, whatever `cwd` is
/// when both are relative.
pub fn relative_path(cwd: &Path, from: &Path, target: &Path) -> String {
    let a = absolute(cwd, from);
    let b = absolute(cwd, target);
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut rel: Vec<String> = vec!["..".to_string(); a.len() - common];
    rel.extend(b[common..].iter().cloned());
    if rel.is_empty() {
        ".".to_string()
    } else {
        rel.join("/")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_ignore_spelling() {
        let cwd = Path::new("/w");
        let want = "../vectors";
        for (from, to) in [
            ("tb/short/rtl", "tb/short/vectors"),
            ("./tb/short/rtl/", "tb//short/./vectors/"),
            ("/w/tb/short/rtl", "tb/x/../short/vectors"),
        ] {
            assert_eq!(
                relative_path(cwd, Path::new(from), Path::new(to)),
                want,
                "{from} -> {to}"
            );
        }
        assert_eq!(
            relative_path(cwd, Path::new("rtl"), Path::new("testbench/tb.v")),
            "../testbench/tb.v"
        );
        // The same relation from another working directory gives the same text.
        assert_eq!(
            relative_path(
                Path::new("/elsewhere/deep"),
                Path::new("a/rtl"),
                Path::new("a/v")
            ),
            "../v"
        );
    }

    #[test]
    fn core_paths_that_could_inject_are_refused() {
        for bad in [
            "",
            "a\nname: x",
            "a: b",
            "a #c",
            "-x",
            "/abs",
            "a b",
            "\"q\"",
            "a{b}",
        ] {
            assert!(check_core_path("core testbench", bad).is_err(), "{bad:?}");
        }
        for good in ["../vectors", "../../tb.v", "x/y_z-1.2+3"] {
            check_core_path("core testbench", good).expect(good);
        }
    }
}
