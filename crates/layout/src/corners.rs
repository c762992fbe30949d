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
    for (library, corner, path) in &i.corners {
        let synth_t = tofprobe_eda::corners::time_cached(i.synthesis, path, corner, "clk")?;
        let post_route = if *path == i.liberty.path {
            post_route.clone()
        } else {
            post(path, corner)?
        };
        if let Some((row, criterion)) = missed_corner(
            (library, corner, path),
            &post_route,
            synth_t.f_max_mhz,
            i.design.laser_rate_hz,
        ) {
            corner_options.push(tofprobe_eda::corner_option::find(
                i.provider,
                &i.design,
                &row,
                i.liberty,
                "clk",
                i.cache,
                DEFAULT_TRIALS,
                criterion,
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

/// For a corner whose post-route setup fails: the row the option search starts from (the
/// routed f_max at the corner) and its criterion (each candidate's synthesis f_max scaled
/// by what routing cost this pixel there, `post-route / synthesis f_max`, slack ≥ 0).
pub fn missed_corner(
    (library, corner, liberty): (&str, &str, &Path),
    post: &PostRoute,
    synthesis_f_max_mhz: f64,
    laser_rate_hz: f64,
) -> Option<(CornerTiming, Criterion)> {
    if post.setup_slack_ns >= 0.0 {
        return None;
    }
    let row = CornerTiming::new(
        library,
        corner,
        liberty,
        &tofprobe_eda::sta::Timing {
            critical_path_ns: 1e3 / post.f_max_mhz,
            f_max_mhz: post.f_max_mhz,
            startpoint: post.setup_path.0.clone(),
            endpoint: post.setup_path.1.clone(),
            path_cells: 0,
        },
        1e3 / post.period_ns,
        laser_rate_hz,
    );
    Some((
        row,
        Criterion::post_route(post.f_max_mhz / synthesis_f_max_mhz),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_missed_after_routing_starts_the_search_at_its_routed_f_max() {
        // The 2-bin pixel's recorded post-route timing (osu018, 6.25 ns: met) moved to a
        // corner that misses: post-route 40 MHz where synthesis gave 44.4 MHz.
        let clean: crate::report::LayoutReport =
            serde_json::from_str(include_str!("../testdata/layout-report-2bin-osu018.json"))
                .unwrap();
        let met = &clean.post_route;
        assert!(
            missed_corner(
                ("osu018_stdcells", "typical", Path::new("l")),
                met,
                316.8,
                10e6
            )
            .is_none()
        );
        let mut slow = met.clone();
        slow.f_max_mhz = 40.0;
        slow.setup_slack_ns = 6.25 - 25.0;
        let (row, c) =
            missed_corner(("lib", "ss", Path::new("ss.lib")), &slow, 44.4, 10e6).unwrap();
        assert_eq!(
            (row.f_max_mhz, row.clock_mhz, row.meets_clock),
            (40.0, 160.0, false)
        );
        assert!((c.derate - 40.0 / 44.4).abs() < 1e-12 && c.margin_percent == 0.0);
        // The 2-bin pixel: P = 2B = 4 operations a pulse, configured C = 16 (160 MHz). At
        // 40 MHz with no margin the search starts at K = 4 (A = 1, 40 MHz), then A = 2 (K =
        // 2) and A = 4 (K = 1).
        assert_eq!(
            tofprobe_eda::corner_option::candidates_with(
                4,
                16,
                10e6,
                row.f_max_mhz,
                c.margin_percent
            ),
            vec![(1, 4), (2, 2), (4, 1)]
        );
    }
}
