//! Runs the checks and, when they are dirty, the ECO re-route (`tofprobe_layout::repair`)
//! on a finished qflow project of the layout flow (`CACHE/layout/TECH-KEY`, osu018):
//! `cargo run --release -p tofprobe-layout --example eco_repair -- PROJECT_DIR [TOP]`;
//! `… -- PROJECT_DIR TOP --round NET…` runs one ECO round on the named nets, no checks.
//! It rewrites the project's `layout/TOP.def` and `.rc` (the stage-2 ones are kept as
//! `TOP_stage2.def`/`.rc`): run it on a copy.

use std::path::PathBuf;
use std::time::Instant;
use tofprobe_layout::qflow::Project;
use tofprobe_layout::tech::TechFiles;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().ok_or("usage: eco_repair PROJECT_DIR [TOP]")?);
    let top = args.next().unwrap_or_else(|| "tofprobe_pixel".into());
    let project = Project {
        dir: std::path::absolute(dir)?,
        top,
        tech: TechFiles::osu018()?,
    };
    let rest: Vec<String> = args.collect();
    if rest.first().map(String::as_str) == Some("--round") {
        let nets = rest[1..].iter().cloned().collect();
        let eco = tofprobe_layout::repair::eco_round(&project, &nets, 1)?;
        eprintln!("{eco:?}");
        return Ok(());
    }
    let t = Instant::now();
    let first = project.checks()?;
    eprintln!(
        "checks: DRC {} ({:.0} s), LVS total errors {} ({:.0} s)",
        first.drc_errors, first.drc_seconds, first.lvs_total, first.lvs_seconds
    );
    if first.clean() {
        return Ok(());
    }
    let mut steps = Vec::new();
    let (rep, last) =
        tofprobe_layout::repair::repair(&project, first, &mut steps, &mut |s| eprintln!("{s}"))?;
    for s in &steps {
        eprintln!("{:>8.1} s  {}", s.seconds, s.step);
    }
    println!("{}", serde_json::to_string_pretty(&rep)?);
    eprintln!(
        "after: DRC {}, LVS {} ({}), {:.0} s in all",
        last.drc_errors,
        if last.lvs_match { "match" } else { "MISMATCH" },
        last.lvs_result,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
