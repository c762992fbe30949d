//! The steps of [`super::run`], one function each, over the run's state ([`Run`]): the
//! request with absolute paths, the technology, the progress callback and the timed steps
//! every step appends to. What a step produces for later ones is its return value, so the
//! order of the steps (and of their progress messages and timings) is [`super::run`]'s.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use tofprobe_design::ResolvedDesign;
use tofprobe_eda::analysis::{PointResult, analyse_points};
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::scaling::AreaModel;
use tofprobe_eda::synth::Synthesis;

use super::{LayoutRequest, LayoutRun, MIN_DENSITY, check_options, densities, notes};
use crate::error::{LayoutError, Result};
use crate::qflow::{Checks, Project, route_verdict};
use crate::report::{Attempt, LayoutReport, SCHEMA, Step, SynthFigures};
use crate::tech::{Tech, TechFiles};

/// The state every step shares.
pub(super) struct Run<'a> {
    design: &'a ResolvedDesign,
    /// The request, its paths made absolute.
    req: LayoutRequest,
    progress: &'a mut dyn FnMut(&str),
    /// The timed steps of the report, in order.
    steps: Vec<Step>,
    tech: TechFiles,
    /// sky130's PDK (its corners); none on osu018.
    sky130_pdk: Option<Sky130Pdk>,
}

/// Step 1's product: the synthesised points and the cells' layout sizes.
pub(super) struct Synthesised {
    provider: GeneratedPixel,
    period_ns: f64,
    lib: Liberty,
    /// The configured bins and width.
    b: u64,
    w: u32,
    /// The smaller B of the area model.
    other: u64,
    /// The configured pixel first, then `other`.
    points: Vec<PointResult>,
    lef_text: String,
    sizes: BTreeMap<String, (f64, f64)>,
}

impl Synthesised {
    fn main(&self) -> &Synthesis {
        &self.points[0].synthesis
    }

    /// The configured pixel's synthesis as the report gives it.
    fn figures(&self) -> SynthFigures {
        let (syn, timing) = (self.main(), self.points[0].timing.as_ref());
        SynthFigures {
            area_um2: syn.total_area_um2,
            cells: syn.cell_count,
            f_max_mhz: timing.map(|t| t.f_max_mhz),
            slack_ns: timing.map(|t| self.period_ns - t.critical_path_ns),
            key: syn.key.clone(),
        }
    }
}

/// Step 2's product: the qflow project, placed and routed.
pub(super) struct Routed {
    project: Project,
    dir: PathBuf,
    lock: std::fs::File,
    top: String,
    clock_buffers: u64,
    route_cleanup: bool,
    attempts: Vec<Attempt>,
}

/// Step 3's product: the verdicts after any repair.
pub(super) struct Checked {
    die_growth: crate::die::Growth,
    repair: Option<crate::repair::Repair>,
    checks: Checks,
}

/// Step 4's product: the routed DEF and what was read and proven from it.
pub(super) struct Inspected {
    def_path: PathBuf,
    def_text: String,
    def_boundary: crate::boundary::Outside,
    def_counts: Vec<crate::def::SectionCount>,
    gds: crate::gds::GdsFigures,
    equivalence: crate::netlist::LaidOutProof,
}

impl<'a> Run<'a> {
    /// Checks the options and the tools, makes the request's paths absolute and finds the
    /// technology's files.
    pub(super) fn prepare(
        design: &'a ResolvedDesign,
        req: &LayoutRequest,
        progress: &'a mut dyn FnMut(&str),
    ) -> Result<Self> {
        check_options(req.density, req.node_nm)?;
        crate::tools::require_all()?;
        // Absolute paths: qflow's scripts run in the project's subdirectories, and the
        // technology is linked into the project (a relative `--cache` or PDK broke both).
        let absolute =
            |p: &Path| std::path::absolute(p).map_err(|e| LayoutError::io("resolving", p, e));
        let req = LayoutRequest {
            cache: absolute(&req.cache)?,
            sky130_pdk: req.sky130_pdk.as_deref().map(absolute).transpose()?,
            ..req.clone()
        };
        let (tech, sky130_pdk) = match req.tech {
            Tech::Osu018 => (TechFiles::osu018()?, None),
            Tech::Sky130 => {
                let pdk = Sky130Pdk::discover(req.sky130_pdk.as_deref())?.ok_or_else(|| {
                    LayoutError::TechFile {
                        tech: "sky130",
                        what: "the PDK directory",
                        path: tofprobe_eda::pdk::search_path()[0].clone(),
                        hint: "--sky130-pdk DIR or $TOFPROBE_SKY130_PDK",
                    }
                })?;
                (TechFiles::sky130(&pdk.dir, &req.cache)?, Some(pdk))
            }
        };
        Ok(Run {
            design,
            req,
            progress,
            steps: Vec::new(),
            tech,
            sky130_pdk,
        })
    }

    fn timed(&mut self, name: &str, t: Instant) {
        self.steps.push(Step {
            step: name.into(),
            seconds: t.elapsed().as_secs_f64(),
        })
    }

    /// Step 1, synthesis: the configured pixel and a smaller B for the area model; the
    /// netlist's cells must all have a layout view.
    pub(super) fn synthesise(&mut self) -> Result<Synthesised> {
        (self.progress)("synthesis");
        let t = Instant::now();
        let pixel = &self.design.pixel;
        let provider = GeneratedPixel {
            base: pixel.clone(),
        };
        let period_ns = 1e9 / (pixel.cycles_per_pulse as f64 * self.design.sensor().laser_rate_hz);
        let lib = Liberty::load(&self.tech.liberty)?;
        let (b, w) = (pixel.bins as u64, pixel.width);
        let other = if b > 1 { b / 2 } else { 2 };
        let points = analyse_points(
            &provider,
            &[(b, w), (other, w)],
            &lib,
            true,
            "clk",
            &self.req.cache,
            Some(period_ns * 1e3),
        )?;
        self.timed("synthesis (yosys, cached with `size`)", t);

        let tech = &self.tech;
        let lef_text = std::fs::read_to_string(&tech.cell_lef)
            .map_err(|e| LayoutError::io("reading", &tech.cell_lef, e))?;
        let sizes = crate::def::lef_sizes(&lef_text);
        let syn = &points[0].synthesis;
        if let Some(cell) = syn.cells_by_type.keys().find(|c| !sizes.contains_key(*c)) {
            return Err(LayoutError::CellMismatch {
                cell: cell.clone(),
                liberty: tech.liberty.clone(),
                lef: tech.cell_lef.clone(),
            });
        }
        Ok(Synthesised {
            provider,
            period_ns,
            lib,
            b,
            w,
            other,
            points,
            lef_text,
            sizes,
        })
    }

    /// Step 2, the qflow project: convert, then place and route, lower densities on failure.
    pub(super) fn place_and_route(&mut self, s: &Synthesised) -> Result<Routed> {
        let syn = s.main();
        let name = format!("{}-{}", self.tech.tech.name(), syn.key);
        let dir = self.req.cache.join("layout").join(&name);
        // One run per project at a time (across processes): a second layout of the same
        // netlist waits here instead of removing this one's project as it is being built.
        let lock = tofprobe_io::cache::lock_key(&self.req.cache.join("layout"), &name)
            .map_err(|e| LayoutError::io("locking", &dir, e))?;
        let top = s.provider.top();
        let project = Project::create(&dir, &top, &self.tech, &syn.netlist_verilog)?;
        (self.progress)("netlist to qflow");
        let t = Instant::now();
        let (synth_log, _) = project.stage("netlist conversion", "synthesize", "synth.log")?;
        let clock_buffers: u64 = synth_log
            .lines()
            .filter_map(|l| l.trim().strip_suffix(" buffers were added."))
            .filter_map(|n| n.trim().parse::<u64>().ok())
            .sum();
        self.timed("netlist to qflow (BLIF, SPICE)", t);
        let route_cleanup = self.req.route_cleanup.runs(syn.cell_count);
        project.set_route_cleanup(route_cleanup)?;
        let attempts = self.route(&project, syn.cell_count)?;
        Ok(Routed {
            project,
            dir,
            lock,
            top,
            clock_buffers,
            route_cleanup,
            attempts,
        })
    }

    /// Placement and routing at each density of [`densities`] until the route is whole;
    /// the last one unrouted is the error.
    fn route(&mut self, project: &Project, cells: u64) -> Result<Vec<Attempt>> {
        let mut attempts = Vec::new();
        let tries = densities(self.req.density.target(cells));
        for (i, &d) in tries.iter().enumerate() {
            project.set_density(d)?;
            (self.progress)(&format!("placement at density {d}"));
            let t = Instant::now();
            project.stage("placement", "place", "place.log")?;
            project.keep_routes_inside()?;
            self.timed(&format!("placement (graywolf, density {d})"), t);
            (self.progress)("routing");
            let t = Instant::now();
            let (log, _) = project.stage("routing", "route", "route.log")?;
            self.timed(&format!("routing (qrouter, density {d})"), t);
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
        Ok(attempts)
    }

    /// Step 3, checks and views; a dirty route is repaired by re-routing the nets at its errors.
    pub(super) fn check(&mut self, r: &Routed) -> Result<Checked> {
        let project = &r.project;
        let die_growth = project.grow_die()?;
        (self.progress)("DRC, extraction, LEF, LVS");
        let first = project.checks()?;
        self.steps.push(Step {
            step: "DRC and extraction (magic)".into(),
            seconds: first.drc_seconds,
        });
        self.steps.push(Step {
            step: "LVS (netgen)".into(),
            seconds: first.lvs_seconds,
        });
        let (repair, checks) = if first.clean() {
            (None, first)
        } else {
            let (r, c) =
                crate::repair::repair(project, first, &mut self.steps, &mut *self.progress)?;
            (Some(r), c)
        };
        (self.progress)("GDS");
        let t = Instant::now();
        project.stage("GDS", "gdsii", "gdsii.log")?;
        self.timed("GDS (magic)", t);
        Ok(Checked {
            die_growth,
            repair,
            checks,
        })
    }

    /// Step 4, the routed DEF's boundary and counts, the GDS read back, the laid-out netlist
    /// proven equivalent to the RTL.
    pub(super) fn inspect(&mut self, s: &Synthesised, r: &Routed) -> Result<Inspected> {
        (self.progress)("boundary, GDS, equivalence");
        let t = Instant::now();
        let (project, tech) = (&r.project, &self.tech);
        let def_path = project.layout_file("def");
        let def_text = std::fs::read_to_string(&def_path)
            .map_err(|e| LayoutError::io("reading", &def_path, e))?;
        let geometry = crate::boundary::Geometry::from_lef(&[
            &std::fs::read_to_string(&tech.tech_lef)
                .map_err(|e| LayoutError::io("reading", &tech.tech_lef, e))?,
            &s.lef_text,
        ]);
        let def_boundary = crate::boundary::outside_die(&def_text, &geometry, &s.sizes, &def_path)?;
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
            &r.dir.join("layout"),
        )?;
        let equivalence = super::laid_out_proof(
            project,
            &s.provider,
            &def_text,
            s.main(),
            tech,
            &self.req,
            s.b,
            s.w,
        )?;
        self.timed("boundary, GDS (klayout), equivalence (yosys)", t);
        Ok(Inspected {
            def_path,
            def_text,
            def_boundary,
            def_counts,
            gds,
            equivalence,
        })
    }

    /// Step 5, post-route timing at every corner, the option for a corner missed.
    pub(super) fn post_route_timing(
        &mut self,
        s: &Synthesised,
        r: &Routed,
    ) -> Result<crate::corners::Timed> {
        (self.progress)("post-route timing");
        let t = Instant::now();
        let cache = &self.req.cache;
        let corner_libs: Vec<(String, String, PathBuf)> = match &self.sky130_pdk {
            Some(pdk) => pdk
                .corners
                .iter()
                .map(|c| {
                    Ok((
                        format!("sky130_fd_sc_hd__{}", c.name),
                        c.name.clone(),
                        tofprobe_eda::pdk::plain_copy(&c.source, cache)?,
                    ))
                })
                .collect::<Result<_>>()?,
            None => vec![(
                s.lib.name.clone(),
                "typical".into(),
                self.tech.liberty.clone(),
            )],
        };
        let pixel = &self.design.pixel;
        let timed_corners = crate::corners::time(&crate::corners::TimingInputs {
            project: &r.project,
            synthesis: s.main(),
            liberty: &s.lib,
            corners: corner_libs,
            design: tofprobe_eda::size_report::Design {
                bins: s.b,
                width: s.w,
                registers: pixel.registers() as u64,
                ops_per_pulse: pixel.ops_per_pulse() as u64,
                adders: pixel.adders as u64,
                cycles_per_pulse: pixel.cycles_per_pulse as u64,
                laser_rate_hz: self.design.sensor().laser_rate_hz,
            },
            provider: &s.provider,
            cache,
            period_ns: s.period_ns,
        })?;
        self.timed("post-route timing (OpenSTA + SPEF)", t);
        Ok(timed_corners)
    }

    /// Step 6, the picture (klayout), drawn into the project's layout directory.
    pub(super) fn picture(&mut self, r: &Routed) -> Result<PathBuf> {
        (self.progress)("picture");
        let t = Instant::now();
        let png = r.project.layout_file("png");
        crate::picture::draw(
            &r.project.layout_file("gds"),
            &png,
            1600,
            &r.dir.join("layout"),
        )?;
        self.timed("picture (klayout)", t);
        Ok(png)
    }

    /// The routed figures and the bins per pitch, then the report and its files.
    pub(super) fn finish(
        self,
        s: Synthesised,
        r: Routed,
        checked: Checked,
        inspected: Inspected,
        timed_corners: crate::corners::Timed,
        png: PathBuf,
    ) -> Result<LayoutRun> {
        let Inspected {
            def_path,
            def_text,
            def_boundary,
            def_counts,
            gds,
            equivalence,
        } = inspected;
        let def = crate::def::parse_def(&def_text, &s.sizes, &self.tech.fill, &def_path)?;
        let bins_per_pitch = self.bins_per_pitch(&s, &def)?;
        let synthesis = s.figures();
        let Checks {
            drc_errors,
            drc_rules,
            lvs_match,
            lvs_result,
            lvs_errors,
            ..
        } = checked.checks;
        let mut report = LayoutReport {
            schema: SCHEMA.into(),
            tech: self.tech.tech.name().into(),
            config: self.design.origin.clone(),
            top: r.top.clone(),
            bins: s.b,
            width: s.w,
            attempts: r.attempts,
            route_cleanup: r.route_cleanup,
            def,
            synthesis,
            drc_errors,
            drc_rules,
            lvs_match,
            lvs_result,
            lvs_errors,
            repair: checked.repair,
            post_route: timed_corners.post_route,
            bins_per_pitch,
            steps: self.steps,
            clock_buffers: r.clock_buffers,
            corners: timed_corners.corners,
            die_growth: Some(checked.die_growth),
            def_boundary: Some(def_boundary),
            def_counts,
            gds: Some(gds),
            equivalence: Some(equivalence),
            corner_options: timed_corners.corner_options,
            failures: vec![],
            notes: notes(&self.tech, s.other, r.route_cleanup),
        };
        report.failures = crate::verdict::failures(&report);
        Ok(LayoutRun {
            report,
            files: super::files(&r.project, &r.top, png),
            project: r.dir,
            _lock: r.lock,
        })
    }

    /// The bins that fit each pitch: the area model A(B) of the two synthesised points
    /// times the routed factor (none when the model cannot be fitted).
    fn bins_per_pitch(
        &self,
        s: &Synthesised,
        def: &crate::def::DefFigures,
    ) -> Result<Option<crate::pitch_bins::BinsPerPitch>> {
        let model = AreaModel::fit(
            &s.points
                .iter()
                .map(|p| (p.bins as f64, p.synthesis.total_area_um2))
                .collect::<Vec<_>>(),
        )
        .ok();
        let routed_factor = def.die_area_um2() / s.main().total_area_um2;
        Ok(match model {
            Some(m) => Some(crate::pitch_bins::bins_per_pitch(
                m,
                routed_factor,
                def.die_area_um2(),
                self.tech.tech.node_nm(),
                self.req.node_nm,
                &self.req.pitches,
            )?),
            None => None,
        })
    }
}
