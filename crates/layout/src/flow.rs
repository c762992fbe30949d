//! The layout flow of one resolved design, step by step (see the crate's header).

use std::path::{Path, PathBuf};
use std::time::Instant;

use tofprobe_design::ResolvedDesign;
use tofprobe_eda::analysis::analyse_points;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::scaling::AreaModel;

use crate::error::{LayoutError, Result};
use crate::qflow::{Project, route_verdict};
use crate::report::{Attempt, LayoutReport, SCHEMA, Step, SynthFigures};
use crate::tech::{Tech, TechFiles};

/// Densities below this are not tried (the macro would be mostly fill).
pub const MIN_DENSITY: f64 = 0.2;
/// Placement attempts at most (the asked density, then 0.1 lower each time).
pub const MAX_ATTEMPTS: usize = 3;
/// Above this many cells `RouteCleanup::Auto` skips qrouter's stage 3: on the default
/// pixel (9,248 cells) it re-routed 40–60 nets a minute after stages 1 and 2 had routed
/// all 9,435 nets in ≈ 47 min, i.e. hours for wirelength alone; the 2-bin pixel (2,627
/// cells) keeps it (it takes a minute there).
pub const AUTO_CLEANUP_MAX_CELLS: u64 = 5_000;

/// Whether qrouter runs its stage 3, the cleanup that rips up and re-routes every routed
/// net. Stages 1 and 2 (route, then rip up and re-route the failures) leave every net
/// routed; stage 3 shortens the wires and removes defects stage 2 can leave (the default
/// pixel's stage-2 route had 3 DRC errors and one open net, which the ECO re-route,
/// `crate::repair`, clears by re-routing two nets; docs/layout.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RouteCleanup {
    /// On up to [`AUTO_CLEANUP_MAX_CELLS`] cells, off above.
    Auto,
    /// Always (qflow's own `qrouter::standard_route`).
    On,
    /// Never (`qrouter::standard_route` with its `nocleanup` argument).
    Off,
}

impl RouteCleanup {
    /// Parses `auto`, `on` or `off` (the CLI's `--route-cleanup`).
    pub fn parse(s: &str) -> Result<RouteCleanup> {
        match s {
            "auto" => Ok(RouteCleanup::Auto),
            "on" => Ok(RouteCleanup::On),
            "off" => Ok(RouteCleanup::Off),
            _ => Err(LayoutError::Option {
                option: "route-cleanup",
                value: s.into(),
                allowed: "auto, on or off".into(),
            }),
        }
    }

    /// Whether stage 3 runs for a netlist of `cells` cells.
    pub fn runs(self, cells: u64) -> bool {
        match self {
            RouteCleanup::Auto => cells <= AUTO_CLEANUP_MAX_CELLS,
            RouteCleanup::On => true,
            RouteCleanup::Off => false,
        }
    }
}

/// The density `Density::Auto` asks for up to [`AUTO_CLEANUP_MAX_CELLS`] cells (the 2-bin
/// pixel routes clean there, stage 3 included) and above ([`AUTO_DENSITY_LARGE`]).
pub const AUTO_DENSITY_SMALL: f64 = 0.6;
/// The density `Density::Auto` asks for above [`AUTO_CLEANUP_MAX_CELLS`] cells: the default
/// pixel (9,248 cells) routes every net at 0.5 with stages 1 and 2 and is clean after the
/// ECO re-route (docs/layout.md); at 0.6 stage 2 had not finished after 34 min.
pub const AUTO_DENSITY_LARGE: f64 = 0.5;

/// The target placement density asked for: a number, or `auto` (by the netlist's size).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Density {
    /// [`AUTO_DENSITY_SMALL`] up to [`AUTO_CLEANUP_MAX_CELLS`] cells, [`AUTO_DENSITY_LARGE`] above.
    Auto,
    /// This density (cells / core), [`MIN_DENSITY`] ..= 0.95.
    Fixed(f64),
}

impl Density {
    /// Parses `auto` or a number (the CLI's `--density`); the range is checked by
    /// [`check_options`].
    pub fn parse(s: &str) -> Result<Density> {
        if s == "auto" {
            return Ok(Density::Auto);
        }
        s.trim()
            .parse::<f64>()
            .map(Density::Fixed)
            .map_err(|_| LayoutError::Option {
                option: "density",
                value: s.into(),
                allowed: format!("auto or a number {MIN_DENSITY} ..= 0.95, e.g. 0.5"),
            })
    }

    /// The density to place a netlist of `cells` cells at.
    pub fn target(self, cells: u64) -> f64 {
        match self {
            Density::Auto if cells <= AUTO_CLEANUP_MAX_CELLS => AUTO_DENSITY_SMALL,
            Density::Auto => AUTO_DENSITY_LARGE,
            Density::Fixed(d) => d,
        }
    }
}

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

/// Checks the request's numbers before anything runs.
pub fn check_options(density: Density, node_nm: f64) -> Result<()> {
    if let Density::Fixed(density) = density
        && !(density.is_finite() && (MIN_DENSITY..=0.95).contains(&density))
    {
        return Err(LayoutError::Option {
            option: "density",
            value: density.to_string(),
            allowed: format!(
                "auto or {MIN_DENSITY} ..= 0.95 (0.5 routes the default pixel on osu018)"
            ),
        });
    }
    if !(node_nm.is_finite() && node_nm > 0.0 && node_nm <= 1000.0) {
        return Err(LayoutError::Option {
            option: "node-nm",
            value: node_nm.to_string(),
            allowed: "0 < node ≤ 1000 (nm), e.g. 40".into(),
        });
    }
    Ok(())
}

/// The densities tried for a request of `d`.
pub fn densities(d: f64) -> Vec<f64> {
    (0..MAX_ATTEMPTS)
        .map(|i| ((d - 0.1 * i as f64) * 100.0).round() / 100.0)
        .filter(|&x| x >= MIN_DENSITY - 1e-9)
        .collect()
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

    // 4. Post-route timing.
    progress("post-route timing");
    let t = Instant::now();
    let rc_path = project.layout_file("rc");
    let rc =
        std::fs::read_to_string(&rc_path).map_err(|e| LayoutError::io("reading", &rc_path, e))?;
    let mut nets = crate::spef::parse_rc(&rc, &rc_path)?;
    let netlist = project.synthesis_file("rtlnopwr.v");
    let verilog =
        std::fs::read_to_string(&netlist).map_err(|e| LayoutError::io("reading", &netlist, e))?;
    crate::spef::rename_to_netlist(&mut nets, &verilog);
    let spef_path = project.layout_file("spef");
    std::fs::write(&spef_path, crate::spef::write_spef(&top, &nets))
        .map_err(|e| LayoutError::io("writing", &spef_path, e))?;
    let spef_nets = nets.iter().filter(|n| !n.points.is_empty()).count();
    let post = |lib: &Path, corner: &str| {
        crate::sta::run(
            lib,
            &netlist,
            &spef_path,
            &top,
            period_ns,
            spef_nets,
            &dir.join("layout"),
            corner,
        )
    };
    let post_route = post(&tech.liberty, "typical")?;
    // Every corner: the synthesis netlist timed on each liberty (the size report's
    // figures, cached), the routed one with the same wires.
    let mut corners = Vec::new();
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
    for (library, corner, path) in corner_libs {
        let synth_t = tofprobe_eda::corners::time_cached(syn, &path, &corner, "clk")?;
        let post_route = if path == tech.liberty {
            post_route.clone()
        } else {
            post(&path, &corner)?
        };
        corners.push(crate::report::CornerRow {
            library,
            corner,
            synthesis_f_max_mhz: synth_t.f_max_mhz,
            synthesis_slack_ns: period_ns - synth_t.critical_path_ns,
            post_route,
        });
    }
    timed(&mut steps, "post-route timing (OpenSTA + SPEF)", t);

    // 5. Picture, figures, bins per pitch.
    progress("picture");
    let t = Instant::now();
    let png = project.layout_file("png");
    crate::picture::draw(&project.layout_file("gds"), &png, 1600, &dir.join("layout"))?;
    timed(&mut steps, "picture (klayout)", t);
    let def_path = project.layout_file("def");
    let def_text =
        std::fs::read_to_string(&def_path).map_err(|e| LayoutError::io("reading", &def_path, e))?;
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
    let report = LayoutReport {
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
        post_route,
        bins_per_pitch,
        steps,
        clock_buffers,
        corners,
        notes: notes(&tech, other, route_cleanup),
    };
    let ext = |e: &str| project.layout_file(e);
    let files = vec![
        (format!("{top}.def"), ext("def")),
        (format!("{top}.gds"), ext("gds")),
        (format!("{top}.lef"), ext("lef")),
        (format!("{top}.spef"), ext("spef")),
        (format!("{top}.v"), netlist),
        ("layout.png".to_string(), png),
    ];
    Ok(LayoutRun {
        report,
        files,
        project: dir,
        _lock: lock,
    })
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
        n.push("osu018: Debian's qflow-tech-osu018 has no cell GDS, so the GDS and the picture hold the cells' LEF abstracts (pins and obstructions) with the routing, and magic's DRC checks the routing and the abstracts, not the cells' transistors.".into());
    }
    n
}

/// The directory a design's layout project uses (for tests that look at the logs).
pub fn project_dir(cache: &Path, tech: Tech, synthesis_key: &str) -> PathBuf {
    cache
        .join("layout")
        .join(format!("{}-{synthesis_key}", tech.name()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn route_cleanup_auto_keeps_stage_3_for_small_pixels_only() {
        // The 2-bin pixel (2,627 cells) keeps it, the default (9,248 cells) skips it.
        assert!(RouteCleanup::Auto.runs(2_627));
        assert!(RouteCleanup::Auto.runs(AUTO_CLEANUP_MAX_CELLS));
        assert!(!RouteCleanup::Auto.runs(9_248));
        assert!(RouteCleanup::On.runs(9_248));
        assert!(!RouteCleanup::Off.runs(10));
        assert_eq!(RouteCleanup::parse("off").unwrap(), RouteCleanup::Off);
        let e = RouteCleanup::parse("never").unwrap_err().to_string();
        assert!(
            e.contains("route-cleanup") && e.contains("auto, on or off"),
            "{e}"
        );
    }

    #[test]
    fn density_auto_follows_the_netlist_size() {
        // The 2-bin pixel (2,627 cells) at 0.6, where it routes clean with stage 3; the
        // default (9,248 cells) at 0.5, where it routes clean after the ECO re-route.
        assert_eq!(Density::Auto.target(2_627), 0.6);
        assert_eq!(Density::Auto.target(AUTO_CLEANUP_MAX_CELLS), 0.6);
        assert_eq!(Density::Auto.target(9_248), 0.5);
        assert_eq!(Density::Fixed(0.45).target(9_248), 0.45);
        assert_eq!(Density::parse("auto").unwrap(), Density::Auto);
        assert_eq!(Density::parse("0.55").unwrap(), Density::Fixed(0.55));
        let e = Density::parse("dense").unwrap_err().to_string();
        assert!(
            e.contains("--density = dense") && e.contains("auto or a number"),
            "{e}"
        );
        assert!(check_options(Density::Auto, 40.0).is_ok());
        let e = check_options(Density::Fixed(0.99), 40.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("0.5 routes the default pixel"), "{e}");
    }
}
