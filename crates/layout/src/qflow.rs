//! One qflow project: the synthesised netlist converted to qflow's BLIF (no re-synthesis:
//! a yosys script that only reads the project's netlist and writes it out; qflow's
//! blifFanout then only buffers nets of fanout > 16, i.e. builds the clock's buffer tree,
//! and resizes nothing), then qflow's stages (`place`, `route`,
//! `migrate`, `drc`, `lvs`, `gdsii`), each timed, its log checked for qflow's error
//! condition.

use crate::error::{LayoutError, Result};
use crate::tech::TechFiles;
use crate::tools::{Tool, tail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A qflow project directory.
#[derive(Debug, Clone)]
pub struct Project {
    /// The directory (`source/`, `synthesis/`, `layout/`, `log/`).
    pub dir: PathBuf,
    /// The top module.
    pub top: String,
    /// The technology.
    pub tech: TechFiles,
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| LayoutError::io("reading", path, e))
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| LayoutError::io("writing", path, e))
}

impl Project {
    /// A fresh project in `dir` (removed first if present) holding `netlist`.
    /// `dir` and the technology's paths must be absolute: qflow's scripts run in the
    /// project's subdirectories (the flow resolves them once, at its entry).
    pub fn create(dir: &Path, top: &str, tech: &TechFiles, netlist: &Path) -> Result<Project> {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|e| LayoutError::io("removing", dir, e))?;
        }
        for sub in ["source", "synthesis", "layout", "log"] {
            let d = dir.join(sub);
            std::fs::create_dir_all(&d).map_err(|e| LayoutError::io("creating", &d, e))?;
        }
        let src = dir.join("source").join(format!("{top}.v"));
        std::fs::copy(netlist, &src).map_err(|e| LayoutError::io("copying", netlist, e))?;
        // qflow finds a technology outside its own directory as PROJECT/tech/NAME.
        if !tech.dir.starts_with(crate::tech::QFLOW_TECH) {
            let link = dir.join("tech");
            std::fs::create_dir_all(&link).map_err(|e| LayoutError::io("creating", &link, e))?;
            let link = link.join(&tech.name);
            std::os::unix::fs::symlink(&tech.dir, &link)
                .map_err(|e| LayoutError::io("linking", &link, e))?;
        }
        let qbin = PathBuf::from("/usr/lib/qflow");
        write(
            &dir.join("qflow_vars.sh"),
            &format!(
                "#!/usr/bin/tcsh -f\nset projectpath={p}\nset techdir={t}\nset sourcedir={p}/source\n\
                 set synthdir={p}/synthesis\nset layoutdir={p}/layout\nset techname={n}\n\
                 set scriptdir={q}/scripts\nset bindir={q}/bin\nset logdir={p}/log\n",
                p = dir.display(),
                t = tech.dir.display(),
                n = tech.name,
                q = qbin.display()
            ),
        )?;
        let (buf, a, y) = tech.buffer;
        let ties = match tech.tech {
            crate::tech::Tech::Sky130 => {
                "hilomap -singleton -hicell sky130_fd_sc_hd__conb_1 HI -locell sky130_fd_sc_hd__conb_1 LO\n"
            }
            crate::tech::Tech::Osu018 => "",
        };
        write(
            &dir.join("source/convert.ys"),
            &format!(
                "# The project's synthesised netlist as qflow's BLIF: no synthesis here.\n\
                 read_liberty -lib {lib}\nread_verilog {src}\nhierarchy -top {top}\n{ties}opt_clean -purge\n\
                 write_blif -buf {buf} {a} {y} {top}_mapped.blif\n",
                lib = tech.liberty.display(),
                src = src.display(),
            ),
        )?;
        let p = Project {
            dir: dir.to_path_buf(),
            top: top.to_string(),
            tech: tech.clone(),
        };
        p.set_density(0.6)?;
        Ok(p)
    }

    /// Sets the placement's target density (qflow's `initial_density`: fill cells are
    /// added until the cells cover that fraction of the core). blifFanout runs as
    /// buffering only (`-f`, no gate resizing) with fanout ≤ 16: the synthesised nets have
    /// fanout ≤ 8 already (ABC's buffering), so what it buffers is the clock, whose tree of
    /// buffers this is.
    pub fn set_density(&self, density: f64) -> Result<()> {
        write(
            &self.dir.join("project_vars.sh"),
            &format!(
                "#!/usr/bin/tcsh -f\nset yosys_options = \"-s {}\"\nset fanout_options = \"-f -F 16\"\nset initial_density = {density}\n",
                self.dir.join("source/convert.ys").display()
            ),
        )
    }

    /// Whether qrouter runs its stage 3 (cleanup). Off, the placement step finds
    /// `layout/TOP.cfg2` and appends it to the router's script instead of qflow's
    /// `qrouter::standard_route TOP_route.def false`: the same procedure with its
    /// `nocleanup` argument (stages 1 and 2, the DEF and RC files, no stage 3).
    pub fn set_route_cleanup(&self, cleanup: bool) -> Result<()> {
        let cfg2 = self.layout_file("cfg2");
        if cleanup {
            match std::fs::remove_file(&cfg2) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    Err(LayoutError::io("removing", &cfg2, e))
                }
                _ => Ok(()),
            }
        } else {
            write(
                &cfg2,
                &format!(
                    "qrouter::standard_route {}_route.def false true\nquit\n",
                    self.top
                ),
            )
        }
    }

    /// After placement: qrouter kept on the die's tracks, the keep-out of
    /// [`crate::die::keep_out`] inserted into the router configuration before its
    /// `read_def` (the placed DEF, `layout/TOP.def`, gives the die and tracks).
    pub fn keep_routes_inside(&self) -> Result<()> {
        let (def, cfg) = (self.layout_file("def"), self.layout_file("cfg"));
        let text = read(&def)?;
        let lines = crate::die::keep_out(&crate::die::frame(&text, &def)?);
        let with =
            crate::die::with_keep_out(&read(&cfg)?, &lines).ok_or_else(|| LayoutError::Parse {
                tool: "qflow (router configuration)",
                what: "`read_def`".into(),
                path: cfg.clone(),
            })?;
        write(&cfg, &with)
    }

    /// After routing: the routed DEF's die grown to hold the wires on its edge tracks,
    /// the pins extended to it ([`crate::die::grow_die`]).
    pub fn grow_die(&self) -> Result<crate::die::Growth> {
        let def = self.layout_file("def");
        let (grown, growth) = crate::die::grow_die(&read(&def)?, &def)?;
        write(&def, &grown)?;
        Ok(growth)
    }

    /// magic's reasons for the DRC errors of the routed macro: each rule broken and how
    /// many boxes break it, and every error box (`drc listall why` on the layout database
    /// the DRC stage checked; the boxes are what the ECO re-route maps to nets).
    pub fn drc_reasons(&self) -> Result<(Vec<DrcRule>, Vec<DrcBox>)> {
        let magic = Tool::Magic.locate()?;
        let script = self
            .dir
            .join("layout")
            .join(format!("why_drc_{}.tcl", self.top));
        write(
            &script,
            &format!(
                "lef read {lef}\nload {top}\ndrc on\nselect top cell\nexpand\ndrc check\ndrc catchup\n\
                 puts stdout \"TOFPROBE-SCALE [cif scale out]\"\n\
                 foreach {{rule boxes}} [drc listall why] {{\n  puts stdout \"TOFPROBE-DRC [llength $boxes] $rule\"\n  \
                 foreach b $boxes {{ puts stdout \"TOFPROBE-BOX [join $b] $rule\" }}\n}}\nquit\n",
                lef = self.tech.cell_lef.display(),
                top = self.top
            ),
        )?;
        let out = Command::new(&magic)
            .args(["-dnull", "-noconsole"])
            .arg(&script)
            .current_dir(self.dir.join("layout"))
            .output()
            .map_err(|e| LayoutError::io("running", &magic, e))?;
        let text = String::from_utf8_lossy(&out.stdout);
        // Kept beside qflow's DRC log: the boxes the ECO re-route worked from.
        write(&self.dir.join("log").join("drc_why.log"), &text)?;
        Ok((parse_drc_reasons(&text), parse_drc_boxes(&text)))
    }

    /// The checks of the routed DEF (`layout/TOP.def`, its section counts set to its
    /// entries first, [`crate::def::fix_counts`]): magic reads it (qflow's `migrate`:
    /// layout database, extraction, LEF), counts the DRC errors (with their rules and
    /// boxes when there are any), and netgen compares the extraction with the netlist.
    pub fn checks(&self) -> Result<Checks> {
        let start = std::time::Instant::now();
        // Every DEF magic reads has its sections' counts right (qrouter's SPECIALNETS
        // count is not; the ECO's splice changes the entries).
        let def = self.layout_file("def");
        write(&def, &crate::def::fix_counts(&read(&def)?))?;
        self.stage("layout database", "migrate", "migrate.log")?;
        let (drc_log, _) = self.stage("DRC", "drc", "drc.log")?;
        let drc_errors = drc_log
            .lines()
            .rev()
            .find_map(|l| l.trim().strip_prefix("drc = "))
            .and_then(|v| v.trim().parse::<u64>().ok())
            .ok_or_else(|| LayoutError::Parse {
                tool: "magic",
                what: "`drc = N`".into(),
                path: self.dir.join("log/drc.log"),
            })?;
        let (drc_rules, drc_boxes) = if drc_errors > 0 {
            self.continue_after_drc()?;
            self.drc_reasons()?
        } else {
            (vec![], vec![])
        };
        let drc_seconds = start.elapsed().as_secs_f64();
        let (lvs_log, lvs_seconds) = self.stage("LVS", "lvs", "lvs.log")?;
        let lvs_result = lvs_log
            .lines()
            .find(|l| l.starts_with("Result:"))
            .map(|l| l.trim_start_matches("Result:").trim().to_string())
            .unwrap_or_else(|| "no result line".into());
        let lvs_match =
            lvs_log.contains("Total errors = 0") && lvs_result.contains("match uniquely");
        Ok(Checks {
            drc_errors,
            drc_rules,
            drc_boxes,
            lvs_match,
            lvs_result,
            lvs_errors: lvs_counts(&lvs_log),
            lvs_total: lvs_total(&lvs_log).unwrap_or(u64::from(!lvs_match)),
            drc_seconds,
            lvs_seconds,
        })
    }

    /// Lets qflow's later stages run after a DRC failure: its GDS stage refuses to run
    /// after a DRC log ending in "error condition", so a line saying where the errors went
    /// (the report) ends the log instead.
    pub fn continue_after_drc(&self) -> Result<()> {
        let log = self.dir.join("log").join("drc.log");
        let mut text = std::fs::read_to_string(&log).unwrap_or_default();
        text.push_str("tofprobe: the DRC errors are in the layout report; LVS and GDS continue.\n");
        write(&log, &text)
    }

    /// A file of the layout directory: `layout/TOP.EXT`.
    pub fn layout_file(&self, ext: &str) -> PathBuf {
        self.dir.join("layout").join(format!("{}.{ext}", self.top))
    }

    /// A file of the synthesis directory: `synthesis/TOP.EXT`.
    pub fn synthesis_file(&self, ext: &str) -> PathBuf {
        self.dir
            .join("synthesis")
            .join(format!("{}.{ext}", self.top))
    }

    /// Runs qflow's `stage` (its qflow name) and returns its log's text and the seconds
    /// it took; an error names the stage and the log's tail. A routing, DRC or LVS stage
    /// that stopped on its own verdict (unrouted nets, DRC errors, a mismatch) returns its
    /// log: the verdict is the report's, not an error.
    pub fn stage(&self, step: &'static str, stage: &str, log: &str) -> Result<(String, f64)> {
        let qflow = Tool::Qflow.locate()?;
        let start = std::time::Instant::now();
        let out = Command::new(&qflow)
            .arg(stage)
            .arg(&self.top)
            .current_dir(&self.dir)
            .output()
            .map_err(|e| LayoutError::io("running", &qflow, e))?;
        let seconds = start.elapsed().as_secs_f64();
        let console = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        let console_path = self.dir.join("log").join(format!("qflow-{stage}.txt"));
        write(&console_path, &console)?;
        let log_path = self.dir.join("log").join(log);
        let text = std::fs::read_to_string(&log_path).unwrap_or_default();
        let failed = !out.status.success()
            || text.contains("error condition")
            || text.contains("Premature exit")
            || text.is_empty();
        // The route, DRC and LVS stages fail qflow's way when their verdict is bad
        // (unrouted nets; `drc = N` with N > 0; netgen's "Netlists do not match"): the
        // caller reads that verdict from the log and reports it, so only a log without it
        // is a tool failure.
        let verdict_in_log = match stage {
            "route" => true,
            "drc" => text.lines().any(|l| l.trim().starts_with("drc = ")),
            "lvs" => text.lines().any(|l| l.starts_with("Result:")),
            _ => false,
        };
        if failed && !verdict_in_log {
            let both = format!("{text}\n{console}");
            return Err(LayoutError::ToolFailed {
                step,
                tool: "qflow",
                status: out
                    .status
                    .code()
                    .map_or("killed".into(), |c| format!("exit {c}")),
                log: log_path,
                tail: tail(both.trim_end(), 15),
            });
        }
        Ok((text, seconds))
    }
}

/// The verdicts of [`Project::checks`].
#[derive(Debug, Clone, PartialEq)]
pub struct Checks {
    /// magic's DRC error count.
    pub drc_errors: u64,
    /// The rules broken (empty when clean).
    pub drc_rules: Vec<DrcRule>,
    /// The error boxes (empty when clean).
    pub drc_boxes: Vec<DrcBox>,
    /// netgen's verdict.
    pub lvs_match: bool,
    /// netgen's result line.
    pub lvs_result: String,
    /// The nonzero counts of the LVS summary.
    pub lvs_errors: Vec<String>,
    /// netgen's total error count.
    pub lvs_total: u64,
    /// Wall time of the layout database, extraction and DRC (s).
    pub drc_seconds: f64,
    /// Wall time of LVS (s).
    pub lvs_seconds: f64,
}

impl Checks {
    /// DRC 0 and LVS match.
    pub fn clean(&self) -> bool {
        self.drc_errors == 0 && self.lvs_match
    }
}

/// A DRC rule the layout breaks and how many error boxes break it.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DrcRule {
    /// magic's text of the rule (e.g. `Metal2 spacing < 3 (Mosis #9.2)`).
    pub rule: String,
    /// Error boxes.
    pub boxes: u64,
}

/// netgen's total error count in qflow's LVS log (`Total errors = N`).
pub fn lvs_total(log: &str) -> Option<u64> {
    log.lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix("Total errors = "))
        .and_then(|n| n.trim().parse().ok())
}

/// A DRC error box (µm) and the rule it breaks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DrcBox {
    /// magic's text of the rule.
    pub rule: String,
    /// Lower left x (µm).
    pub x0: f64,
    /// Lower left y (µm).
    pub y0: f64,
    /// Upper right x (µm).
    pub x1: f64,
    /// Upper right y (µm).
    pub y1: f64,
}

/// The error boxes printed by the DRC script of [`Project::drc_reasons`]:
/// `TOFPROBE-SCALE S` (µm per magic unit, `cif scale out`) and one
/// `TOFPROBE-BOX X0 Y0 X1 Y1 RULE` per box in magic units.
pub fn parse_drc_boxes(text: &str) -> Vec<DrcBox> {
    let scale = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("TOFPROBE-SCALE "))
        .and_then(|s| s.trim().parse::<f64>().ok());
    let Some(s) = scale else {
        return vec![];
    };
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("TOFPROBE-BOX "))
        .filter_map(|l| {
            let mut it = l.splitn(5, ' ');
            let mut c = [0.0; 4];
            for v in &mut c {
                *v = it.next()?.parse::<f64>().ok()? * s;
            }
            Some(DrcBox {
                rule: it.next()?.trim().to_string(),
                x0: c[0],
                y0: c[1],
                x1: c[2],
                y1: c[3],
            })
        })
        .collect()
}

/// The `TOFPROBE-DRC N RULE` lines of [`Project::drc_reasons`]'s magic script.
pub fn parse_drc_reasons(text: &str) -> Vec<DrcRule> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("TOFPROBE-DRC "))
        .filter_map(|l| {
            let (n, rule) = l.split_once(' ')?;
            Some(DrcRule {
                rule: rule.trim().to_string(),
                boxes: n.parse().ok()?,
            })
        })
        .collect()
}

/// The nonzero counts of qflow's LVS summary (`count_lvs.py`: "net count difference = 1",
/// "unmatched nets = 1", …), empty when the netlists match.
pub fn lvs_counts(log: &str) -> Vec<String> {
    log.lines()
        .skip_while(|l| !l.starts_with("LVS reports:"))
        .skip(1)
        .take_while(|l| !l.starts_with("Total errors"))
        .filter_map(|l| {
            let (what, n) = l.trim().rsplit_once(" = ")?;
            (n.trim().parse::<u64>().ok()? > 0).then(|| format!("{what} = {}", n.trim()))
        })
        .collect()
}

/// qrouter's verdict in a route log: `Ok(())` when every net routed, else the unrouted
/// nets' count and the names qrouter reported as failing in its last pass.
pub fn route_verdict(log: &str) -> std::result::Result<(), (usize, Vec<String>)> {
    let last = log
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with("Final:"));
    if last.is_some_and(|l| l.contains("No failed routes")) {
        return Ok(());
    }
    // The nets failing after the last stage marker (earlier passes rip them up again).
    let from = log.rfind("Progress: Stage").map_or(0, |i| i);
    let window = if log[from..].contains("Failed to route net") {
        &log[from..]
    } else {
        log
    };
    let mut nets: Vec<String> = window
        .lines()
        .filter_map(|l| l.trim().strip_prefix("Failed to route net "))
        .map(|n| n.trim().to_string())
        .collect();
    nets.sort();
    nets.dedup();
    let count = last
        .and_then(|l| l.split_whitespace().find_map(|w| w.parse::<usize>().ok()))
        .unwrap_or(nets.len().max(1));
    Err((count, nets))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lvs_counts_keep_the_nonzero_lines() {
        // The default pixel's LVS with one net open (2026-11-28).
        let log = "Result: Netlists do not match.\nLVS reports:\n    net count difference = 1\n    device count difference = 0\n    unmatched nets = 1\n\nTotal errors = 2\n";
        assert_eq!(
            lvs_counts(log),
            vec!["net count difference = 1", "unmatched nets = 1"]
        );
        assert!(lvs_counts("LVS reports:\n    unmatched nets = 0\nTotal errors = 0\n").is_empty());
    }

    #[test]
    fn drc_reasons_are_read_per_rule() {
        // What the magic script prints for the default pixel's routed macro (2026-11-28).
        let text = "Loading\nTOFPROBE-DRC 1 Metal2 spacing < 3 (Mosis #9.2)\nTOFPROBE-DRC 2 Metal2 area < 20 (Mosis #+++)\nTOFPROBE-DRC x bad\n";
        let r = parse_drc_reasons(text);
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].rule, "Metal2 spacing < 3 (Mosis #9.2)");
        assert_eq!(r[1].boxes, 2);
    }

    #[test]
    fn the_route_verdict_reads_the_final_line() {
        assert_eq!(
            route_verdict("Failed to route net a\nProgress: Stage 3\nFinal: No failed routes!\n"),
            Ok(())
        );
        let v = route_verdict(
            "Failed to route net a\nProgress: Stage 3 total routes\nFailed to route net b\nFailed to route net c\nFailed to route net b\nFinal: 2 unrouted nets\n",
        );
        assert_eq!(v, Err((2, vec!["b".into(), "c".into()])));
        // No verdict at all (the router died): a failure.
        assert!(route_verdict("").is_err());
    }
}
