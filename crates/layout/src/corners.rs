//! Timing after routing at every corner of the technology's liberties: qrouter's RC trees
//! written as SPEF, the routed netlist timed by OpenSTA on each corner with the same
//! wires (`crate::sta`), beside the synthesis netlist's timing on that corner (the size
//! report's figures, cached); and for a corner whose setup the routed pixel misses, the
//! option that meets it, found as `tofprobe size` finds it (`tofprobe_eda::corner_option`),
//! judged after routing.

use std::path::{Path, PathBuf};

use tofprobe_eda::analysis::RtlProvider;
use tofprobe_eda::corner_option::{CornerOption, Criterion, DEFAULT_TRIALS};
use tofprobe_eda::corners::CornerTiming;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::size_report::Design;
use tofprobe_eda::synth::Synthesis;

use crate::error::{LayoutError, Result};
use crate::qflow::Project;
use crate::report::CornerRow;
use crate::sta::PostRoute;

/// What the post-route timing needs to know.
pub struct TimingInputs<'a> {
    /// The qflow project (its RC file, placed netlist, layout directory).
    pub project: &'a Project,
    /// The synthesised netlist the layout came from.
    pub synthesis: &'a Synthesis,
    /// The liberty synthesis mapped on (the nominal corner).
    pub liberty: &'a Liberty,
    /// Every corner: (library, corner, liberty file); the nominal one among them.
    pub corners: Vec<(String, String, PathBuf)>,
    /// The configured pixel (adders, cycles per pulse, laser rate) for the options.
    pub design: Design,
    /// Its RTL for any number of adders.
    pub provider: &'a dyn RtlProvider,
    /// The synthesis cache.
    pub cache: &'a Path,
    /// The clock period (ns).
    pub period_ns: f64,
}

impl std::fmt::Debug for TimingInputs<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TimingInputs")
            .field("corners", &self.corners)
            .field("design", &self.design)
            .field("period_ns", &self.period_ns)
            .finish_non_exhaustive()
    }
}

/// The post-route timing: the nominal corner's, every corner's row, and the option that
/// meets each corner whose post-route setup fails.
#[derive(Debug, Clone)]
pub struct Timed {
    /// The nominal corner (the liberty synthesis mapped on).
    pub post_route: PostRoute,
    /// Every corner.
    pub corners: Vec<CornerRow>,
    /// The options for the corners missed after routing.
    pub corner_options: Vec<CornerOption>,
}

/// Writes the SPEF (`layout/TOP.spef`) and times the routed netlist at every corner.
pub fn time(i: &TimingInputs<'_>) -> Result<Timed> {
    let project = i.project;
    let top = &project.top;
    let rc_path = project.layout_file("rc");
    let rc =
        std::fs::read_to_string(&rc_path).map_err(|e| LayoutError::io("reading", &rc_path, e))?;
    let mut nets = crate::spef::parse_rc(&rc, &rc_path)?;
    let netlist = project.synthesis_file("rtlnopwr.v");
    let verilog =
        std::fs::read_to_string(&netlist).map_err(|e| LayoutError::io("reading", &netlist, e))?;
    crate::spef::rename_to_netlist(&mut nets, &verilog);
    let spef_path = project.layout_file("spef");
    std::fs::write(&spef_path, crate::spef::write_spef(top, &nets))
        .map_err(|e| LayoutError::io("writing", &spef_path, e))?;
    let spef_nets = nets.iter().filter(|n| !n.points.is_empty()).count();
    let work = project.dir.join("layout");
    let post = |lib: &Path, corner: &str| {
        crate::sta::run(
            lib,
            &netlist,
            &spef_path,
            top,
            i.period_ns,
            spef_nets,
            &work,
            corner,
        )
    };
    let post_route = post(&i.liberty.path, "typical")?;
    let mut corners = Vec::new();
    let mut corner_options = Vec::new();
    let clock_mhz = 1e3 / i.period_ns;
    for (library, corner, path) in &i.corners {
        let synth_t = tofprobe_eda::corners::time_cached(i.synthesis, path, corner, "clk")?;
        let post_route = if *path == i.liberty.path {
            post_route.clone()
        } else {
            post(path, corner)?
        };
        if post_route.setup_slack_ns < 0.0 {
            // The search starts from the routed f_max and judges each candidate's
            // synthesis f_max scaled by what routing cost this pixel at this corner.
            let row = CornerTiming::new(
                library,
                corner,
                path,
                &tofprobe_eda::sta::Timing {
                    critical_path_ns: 1e3 / post_route.f_max_mhz,
                    f_max_mhz: post_route.f_max_mhz,
                    startpoint: post_route.setup_path.0.clone(),
                    endpoint: post_route.setup_path.1.clone(),
                    path_cells: 0,
                },
                clock_mhz,
                i.design.laser_rate_hz,
            );
            corner_options.push(tofprobe_eda::corner_option::find(
                i.provider,
                &i.design,
                &row,
                i.liberty,
                "clk",
                i.cache,
                DEFAULT_TRIALS,
                Criterion::post_route(post_route.f_max_mhz / synth_t.f_max_mhz),
                i.synthesis.total_area_um2,
            )?);
        }
        corners.push(CornerRow {
            library: library.clone(),
            corner: corner.clone(),
            synthesis_f_max_mhz: synth_t.f_max_mhz,
            synthesis_slack_ns: i.period_ns - synth_t.critical_path_ns,
            post_route,
        });
    }
    Ok(Timed {
        post_route,
        corners,
        corner_options,
    })
}
