//! The layout flow of one resolved design, step by step (see the crate's header).

use std::path::{Path, PathBuf};
use std::time::Instant;

use tofprobe_design::ResolvedDesign;
use tofprobe_eda::analysis::analyse_points;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::scaling::AreaModel;

use crate::error::{LayoutError, Result};
pub use crate::options::{
    AUTO_CLEANUP_MAX_CELLS, AUTO_DENSITY_LARGE, AUTO_DENSITY_SMALL, Density, MAX_ATTEMPTS,
    MIN_DENSITY, RouteCleanup, check_options, densities,
};
use crate::qflow::{Project, route_verdict};
use crate::report::{Attempt, LayoutReport, SCHEMA, Step, SynthFigures};
use crate::tech::{Tech, TechFiles};

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
    check_options(req.density, req.node_nm)?;
    crate::tools::require_all()?;
    // Absolute paths: qflow's scripts run in the project's subdirectories, and the
    // technology is linked into the project (a relative `--cache` or PDK broke both).
    let absolute =
        |p: &Path| std::path::absolute(p).map_err(|e| LayoutError::io("resolving", p, e));
    let req = &LayoutRequest {
        cache: absolute(&req.cache)?,
        sky130_pdk: req.sky130_pdk.as_deref().map(absolute).transpose()?,
        ..req.clone()
    };
    let mut steps = Vec::new();
    let timed = |steps: &mut Vec<Step>, name: &str, t: Instant| {
        steps.push(Step {
            step: name.into(),
            seconds: t.elapsed().as_secs_f64(),
        })
    };
    let (tech, sky130_pdk) = match req.tech {
        Tech::Osu018 => (TechFiles::osu018()?, None),
        Tech::Sky130 => {
            let pdk = tofprobe_eda::pdk::Sky130Pdk::discover(req.sky130_pdk.as_deref())?
                .ok_or_else(|| LayoutError::TechFile {
                    tech: "sky130",
                    what: "the PDK directory",
                    path: tofprobe_eda::pdk::search_path()[0].clone(),
                    hint: "--sky130-pdk DIR or $TOFPROBE_SKY130_PDK",
                })?;
            (TechFiles::sky130(&pdk.dir, &req.cache)?, Some(pdk))
        }
    };

    // 1. Synthesis: the configured pixel and a smaller B for the area model.
    progress("synthesis");
    let t = Instant::now();
    let pixel = &design.pixel;
    let provider = GeneratedPixel {
        base: pixel.clone(),
    };
    let period_ns = 1e9 / (pixel.cycles_per_pulse as f64 * design.sensor().laser_rate_hz);
    let lib = Liberty::load(&tech.liberty)?;
    let (b, w) = (pixel.bins as u64, pixel.width);
    let other = if b > 1 { b / 2 } else { 2 };
    let points = analyse_points(
        &provider,
        &[(b, w), (other, w)],
        &lib,
        true,
        "clk",
        &req.cache,
        Some(period_ns * 1e3),
    )?;
    let main = &points[0];
    let syn = &main.synthesis;
    timed(&mut steps, "synthesis (yosys, cached with `size`)", t);

    // The netlist's cells must all have a layout view.
    let lef_text = std::fs::read_to_string(&tech.cell_lef)
        .map_err(|e| LayoutError::io("reading", &tech.cell_lef, e))?;
    let sizes = crate::def::lef_sizes(&lef_text);
    if let Some(cell) = syn.cells_by_type.keys().find(|c| !sizes.contains_key(*c)) {
        return Err(LayoutError::CellMismatch {
            cell: cell.clone(),
            liberty: tech.liberty.clone(),
            lef: tech.cell_lef.clone(),
        });
    }

    // 2. The qflow project: convert, then place and route, lower densities on failure.
    let name = format!("{}-{}", tech.tech.name(), syn.key);
    let dir = req.cache.join("layout").join(&name);
    // One run per project at a time (across processes): a second layout of the same
    // netlist waits here instead of removing this one's project as it is being built.
    let lock = tofprobe_io::cache::lock_key(&req.cache.join("layout"), &name)
        .map_err(|e| LayoutError::io("locking", &dir, e))?;
    let top = provider.top();
    let project = Project::create(&dir, &top, &tech, &syn.netlist_verilog)?;
    progress("netlist to qflow");
    let t = Instant::now();
    let (synth_log, _) = project.stage("netlist conversion", "synthesize", "synth.log")?;
    let clock_buffers: u64 = synth_log
        .lines()
        .filter_map(|l| l.trim().strip_suffix(" buffers were added."))
        .filter_map(|n| n.trim().parse::<u64>().ok())
        .sum();
    timed(&mut steps, "netlist to qflow (BLIF, SPICE)", t);
    let route_cleanup = req.route_cleanup.runs(syn.cell_count);
    project.set_route_cleanup(route_cleanup)?;
    let mut attempts = Vec::new();
    let tries = densities(req.density.target(syn.cell_count));
    for (i, &d) in tries.iter().enumerate() {
        project.set_density(d)?;
        progress(&format!("placement at density {d}"));
        let t = Instant::now();
        project.stage("placement", "place", "place.log")?;
        project.keep_routes_inside()?;
        timed(&mut steps, &format!("placement (graywolf, density {d})"), t);
        progress("routing");
        let t = Instant::now();
        let (log, _) = project.stage("routing", "route", "route.log")?;
        timed(&mut steps, &format!("routing (qrouter, density {d})"), t);
        match route_verdict(&log) {
            Ok(()) => {
                attempts.push(Attempt {
                    density: d,
                    unrouted: 0,
                    unrouted_nets: vec![],
                });
                break;
            }
            Err((count, mut nets)) => {
                nets.truncate(20);
                attempts.push(Attempt {
                    density: d,
                    unrouted: count,
                    unrouted_nets: nets.clone(),
                });
                if i + 1 == tries.len() {
                    return Err(LayoutError::Unrouted {
                        tried: tries
                            .iter()
                            .map(|d| d.to_string())
                            .collect::<Vec<_>>()
                            .join(", "),
                        last: d,
                        nets: format!("{count} ({})", nets.join(", ")),
                        suggest: ((d - 0.1).max(MIN_DENSITY) * 100.0).round() / 100.0,
                    });
                }
            }
        }
    }

    // 3. Checks and views; a dirty route is repaired by re-routing the nets at its errors.
    let die_growth = project.grow_die()?;
    progress("DRC, extraction, LEF, LVS");
    let first = project.checks()?;
    steps.push(Step {
        step: "DRC and extraction (magic)".into(),
        seconds: first.drc_seconds,
    });
    steps.push(Step {
        step: "LVS (netgen)".into(),
        seconds: first.lvs_seconds,
    });
    let (repair, checks) = if first.clean() {
        (None, first)
    } else {
        let (r, c) = crate::repair::repair(&project, first, &mut steps, progress)?;
        (Some(r), c)
    };
    let crate::qflow::Checks {
        drc_errors,
        drc_rules,
        lvs_match,
        lvs_result,
        lvs_errors,
        ..
    } = checks;
    progress("GDS");
    let t = Instant::now();
    project.stage("GDS", "gdsii", "gdsii.log")?;
    timed(&mut steps, "GDS (magic)", t);

    // 4. The routed DEF's boundary and counts, the GDS read back, the laid-out netlist
    // proven equivalent to the RTL.
    progress("boundary, GDS, equivalence");
    let t = Instant::now();
    let def_path = project.layout_file("def");
    let def_text =
        std::fs::read_to_string(&def_path).map_err(|e| LayoutError::io("reading", &def_path, e))?;
    let geometry = crate::boundary::Geometry::from_lef(&[
        &std::fs::read_to_string(&tech.tech_lef)
            .map_err(|e| LayoutError::io("reading", &tech.tech_lef, e))?,
        &lef_text,
    ]);
    let def_boundary = crate::boundary::outside_die(&def_text, &geometry, &sizes, &def_path)?;
    let def_counts = crate::def::section_counts(&def_text);
    let frame = crate::die::frame(&def_text, &def_path)?;
    let u = frame.units;
    let gds = crate::gds::inspect(
        &project.layout_file("gds"),
        (
            frame.die.0 / u,
            frame.die.1 / u,
            frame.die.2 / u,
            frame.die.3 / u,
        ),
        &dir.join("layout"),
    )?;
    let equivalence = laid_out_proof(&project, &provider, &def_text, syn, &tech, req, b, w)?;
    timed(
        &mut steps,
        "boundary, GDS (klayout), equivalence (yosys)",
        t,
    );

    // 5. Post-route timing at every corner, the option for a corner missed.
    progress("post-route timing");
    let t = Instant::now();
    let corner_libs: Vec<(String, String, PathBuf)> = match &sky130_pdk {
        Some(pdk) => pdk
            .corners
            .iter()
            .map(|c| {
                Ok((
                    format!("sky130_fd_sc_hd__{}", c.name),
                    c.name.clone(),
                    tofprobe_eda::pdk::plain_copy(&c.source, &req.cache)?,
                ))
            })
            .collect::<Result<_>>()?,
        None => vec![(lib.name.clone(), "typical".into(), tech.liberty.clone())],
    };
    let timed_corners = crate::corners::time(&crate::corners::TimingInputs {
        project: &project,
        synthesis: syn,
        liberty: &lib,
        corners: corner_libs,
        design: tofprobe_eda::size_report::Design {
            bins: b,
            width: w,
            registers: pixel.registers() as u64,
            ops_per_pulse: pixel.ops_per_pulse() as u64,
            adders: pixel.adders as u64,
            cycles_per_pulse: pixel.cycles_per_pulse as u64,
            laser_rate_hz: design.sensor().laser_rate_hz,
        },
        provider: &provider,
        cache: &req.cache,
        period_ns,
    })?;
    let netlist = project.synthesis_file("rtlnopwr.v");
    timed(&mut steps, "post-route timing (OpenSTA + SPEF)", t);

    // 6. Picture, figures, bins per pitch.
    progress("picture");
    let t = Instant::now();
    let png = project.layout_file("png");
    crate::picture::draw(&project.layout_file("gds"), &png, 1600, &dir.join("layout"))?;
    timed(&mut steps, "picture (klayout)", t);
    let def = crate::def::parse_def(&def_text, &sizes, &tech.fill, &def_path)?;
    let model = AreaModel::fit(
        &points
            .iter()
            .map(|p| (p.bins as f64, p.synthesis.total_area_um2))
            .collect::<Vec<_>>(),
    )
    .ok();
    let routed_factor = def.die_area_um2() / syn.total_area_um2;
    let bins_per_pitch = match model {
        Some(m) => Some(crate::bins::bins_per_pitch(
            m,
            routed_factor,
            def.die_area_um2(),
            tech.tech.node_nm(),
            req.node_nm,
            &req.pitches,
        )?),
        None => None,
    };
    let synthesis = SynthFigures {
        area_um2: syn.total_area_um2,
        cells: syn.cell_count,
        f_max_mhz: main.timing.as_ref().map(|t| t.f_max_mhz),
        slack_ns: main.timing.as_ref().map(|t| period_ns - t.critical_path_ns),
        key: syn.key.clone(),
    };
    let mut report = LayoutReport {
        schema: SCHEMA.into(),
        tech: tech.tech.name().into(),
        config: design.origin.clone(),
        top: top.clone(),
        bins: b,
        width: w,
        attempts,
        route_cleanup,
        def,
        synthesis,
        drc_errors,
        drc_rules,
        lvs_match,
        lvs_result,
        lvs_errors,
        repair,
        post_route: timed_corners.post_route,
        bins_per_pitch,
        steps,
        clock_buffers,
        corners: timed_corners.corners,
        die_growth: Some(die_growth),
        def_boundary: Some(def_boundary),
        def_counts,
        gds: Some(gds),
        equivalence: Some(equivalence),
        corner_options: timed_corners.corner_options,
        failures: vec![],
        notes: notes(&tech, other, route_cleanup),
    };
    report.failures = crate::verdict::failures(&report);
    let ext = |e: &str| project.layout_file(e);
    let files = vec![
        (format!("{top}.def"), ext("def")),
        (format!("{top}.gds"), ext("gds")),
        (format!("{top}.lef"), ext("lef")),
        (format!("{top}.spef"), ext("spef")),
        (format!("{top}.v"), netlist),
        (
            format!("{top}.laid-out.v"),
            project.layout_file("laid-out.v"),
        ),
        ("layout.png".to_string(), png),
    ];
    Ok(LayoutRun {
        report,
        files,
        project: dir,
        _lock: lock,
    })
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
