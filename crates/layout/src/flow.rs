//! The layout flow of one resolved design, step by step (see the crate's header).

mod steps;

use std::path::{Path, PathBuf};

use tofprobe_design::ResolvedDesign;
use tofprobe_eda::generated::GeneratedPixel;

use crate::error::{LayoutError, Result};
pub use crate::options::{
    AUTO_CLEANUP_MAX_CELLS, AUTO_DENSITY_LARGE, AUTO_DENSITY_SMALL, Density, MAX_ATTEMPTS,
    MIN_DENSITY, RouteCleanup, check_options, densities,
};
use crate::qflow::Project;
use crate::report::LayoutReport;
use crate::tech::{Tech, TechFiles};
use steps::Run;

/// What to lay out and how.
#[derive(Debug, Clone, PartialEq)]
pub struct LayoutRequest {
    /// The technology.
    pub tech: Tech,
    /// Target placement density (cells / core), 0.2 ..= 0.95, or auto.
    pub density: Density,
    /// The synthesis cache (`tofprobe_eda::fsutil::synth_cache_dir`), shared with `size`.
    pub cache: PathBuf,
    /// The sky130 PDK directory (default: `tofprobe_eda::pdk` discovery).
    pub sky130_pdk: Option<PathBuf>,
    /// Node (nm) the bins-per-pitch answer is scaled to.
    pub node_nm: f64,
    /// Pixel pitches and the paper's bins for them.
    pub pitches: Vec<(f64, Option<u64>)>,
    /// qrouter's stage 3.
    pub route_cleanup: RouteCleanup,
}

/// A finished layout: the report and the files of its output set.
#[derive(Debug)]
pub struct LayoutRun {
    /// The report.
    pub report: LayoutReport,
    /// (name in the output set, file) pairs: DEF, GDS, LEF, SPEF, placed netlist, PNG.
    pub files: Vec<(String, PathBuf)>,
    /// The qflow project directory (logs of every tool).
    pub project: PathBuf,
    /// The project's lock (`layout/TECH-KEY.lock`), held until the run is dropped: another
    /// layout of the same netlist waits for it rather than wiping the project (and the
    /// files above) from under this one while they are read.
    _lock: std::fs::File,
}

/// Lays out `design`; `progress` hears each step's name as it starts.
pub fn run(
    design: &ResolvedDesign,
    req: &LayoutRequest,
    progress: &mut dyn FnMut(&str),
) -> Result<LayoutRun> {
    let mut run = Run::prepare(design, req, progress)?;
    let synthesised = run.synthesise()?;
    let routed = run.place_and_route(&synthesised)?;
    let checked = run.check(&routed)?;
    let inspected = run.inspect(&synthesised, &routed)?;
    let timed_corners = run.post_route_timing(&synthesised, &routed)?;
    let png = run.picture(&routed)?;
    run.finish(synthesised, routed, checked, inspected, timed_corners, png)
}

/// The routed DEF's netlist (`layout/TOP.laid-out.v`, [`crate::netlist::from_def`]) proven
/// equivalent to the pixel's RTL by the project's proof (`tofprobe_eda::equiv`, cached
/// beside the sign-off proofs); an unproven pair is the report's verdict, not an error.
#[allow(clippy::too_many_arguments)]
fn laid_out_proof(
    project: &Project,
    provider: &GeneratedPixel,
    def_text: &str,
    syn: &tofprobe_eda::synth::Synthesis,
    tech: &TechFiles,
    req: &LayoutRequest,
    b: u64,
    w: u32,
) -> Result<crate::netlist::LaidOutProof> {
    use tofprobe_eda::analysis::RtlProvider as _;
    let def_path = project.layout_file("def");
    let synthesised = std::fs::read_to_string(&syn.netlist_verilog)
        .map_err(|e| LayoutError::io("reading", &syn.netlist_verilog, e))?;
    let laid = crate::netlist::from_def(def_text, &synthesised, &project.top, &def_path)?;
    let path = project.layout_file("laid-out.v");
    std::fs::write(&path, &laid.verilog).map_err(|e| LayoutError::io("writing", &path, e))?;
    let work = project.dir.join("equiv");
    std::fs::create_dir_all(&work).map_err(|e| LayoutError::io("creating", &work, e))?;
    let rtl = provider.rtl(b, w, &work)?;
    let spec = tofprobe_eda::equiv::EquivSpec {
        rtl: rtl.sources,
        top: rtl.top,
        params: rtl.params,
        netlist: path.clone(),
        liberty: tech.liberty.clone(),
    };
    let proof = tofprobe_eda::equiv::check_equivalence_cached(
        &spec,
        &work,
        Some(&req.cache.join("equiv-proofs")),
    );
    let name = format!("{}.laid-out.v", project.top);
    let base = crate::netlist::LaidOutProof {
        netlist: name,
        cells: laid.cells,
        physical_only: laid.physical_only,
        points: 0,
        proven: 0,
        first_unproven: String::new(),
        seconds: 0.0,
        cached: false,
    };
    match proof {
        Ok(e) => Ok(crate::netlist::LaidOutProof {
            points: e.points,
            proven: e.proven,
            seconds: e.seconds,
            cached: e.cached,
            ..base
        }),
        Err(tofprobe_eda::EdaError::NotEquivalent(f)) => Ok(crate::netlist::LaidOutProof {
            points: f.total,
            proven: f.total - f.unproven,
            first_unproven: f.first,
            ..base
        }),
        Err(e) => Err(e.into()),
    }
}

/// The output set's (name, file) pairs: DEF, GDS, LEF, SPEF, placed and laid-out
/// netlists, PNG.
fn files(project: &Project, top: &str, png: PathBuf) -> Vec<(String, PathBuf)> {
    let ext = |e: &str| project.layout_file(e);
    vec![
        (format!("{top}.def"), ext("def")),
        (format!("{top}.gds"), ext("gds")),
        (format!("{top}.lef"), ext("lef")),
        (format!("{top}.spef"), ext("spef")),
        (format!("{top}.v"), project.synthesis_file("rtlnopwr.v")),
        (
            format!("{top}.laid-out.v"),
            project.layout_file("laid-out.v"),
        ),
        ("layout.png".to_string(), png),
    ]
}

fn notes(tech: &TechFiles, other_b: u64, route_cleanup: bool) -> Vec<String> {
    let mut n = vec![
        "Synthesis: the project's delay-driven yosys script (tofprobe_eda::synth), mapped for the configuration's clock; qflow only converts that netlist (BLIF, SPICE); its blifFanout buffers nets of fanout > 16 and resizes nothing (`-f -F 16`): the synthesised nets have fanout ≤ 8, so that is the clock's buffer tree. LVS compares the layout with this netlist: the synthesised one plus the clock buffers.".to_string(),
        "Placement: graywolf at the stated target density (qflow's initial_density: fill cells are added until the logic covers that fraction); a routing failure retries 0.1 lower, at most 3 attempts. Power: qflow's addspacers stripes (2 µm every 50 µm on osu018).".into(),
        "Post-route timing: OpenSTA on the placed netlist with qrouter's RC trees written as SPEF (lumped at each route point), the clock propagated through its buffer tree and routed wires (their delays are the skew the hold check sees), inputs at the clock edge, outputs due at the next.".into(),
        format!("Bins per pitch: the synthesis model A(B) fitted to B and {other_b} on this technology's liberty, times the routed factor die / cell area of the configured pixel (assumed to hold for other B), scaled by (target node / technology node)²."),
    ];
    n.push(if route_cleanup {
        "Routing: qrouter's stages 1 and 2 (route every net, rip up and re-route the failures) and stage 3 (every net re-routed shorter), qflow's own `qrouter::standard_route`.".into()
    } else {
        format!("Routing: qrouter's stages 1 and 2 only (every net routed); stage 3, the cleanup that re-routes each net, was skipped (`--route-cleanup`, auto above {AUTO_CLEANUP_MAX_CELLS} cells): the wirelength and the post-route wires are those of stage 2, a little longer than a cleaned-up route; defects stage 3 would remove are repaired by the ECO re-route (the nets at the DRC boxes and netgen's unmatched nets re-routed, DRC and LVS run again) or show in the verdicts.")
    });
    if tech.tech == Tech::Osu018 {
        n.push("osu018: Debian's qflow-tech-osu018 has no cell GDS, so the GDS holds the routing and pins only: its cell masters are empty references (see \"GDS holds\"), it is not a standalone stream, and the picture shows the routing. magic's DRC checks the routing against the cells' LEF abstracts (pins, obstructions), not the cells' transistors.".into());
    }
    n
}

/// The directory a design's layout project uses (for tests that look at the logs).
pub fn project_dir(cache: &Path, tech: Tech, synthesis_key: &str) -> PathBuf {
    cache
        .join("layout")
        .join(format!("{}-{synthesis_key}", tech.name()))
}
