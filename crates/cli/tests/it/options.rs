//! Issue 16 through the binary: `tofprobe size --options` on a small pixel (B = 2, a
//! 20,000-pulse frame, 20 MHz clock) measures the architecture options, marks the Pareto
//! front and recommends the smallest pixel that meets its clock and the accuracy target;
//! `tofprobe flow --recommended` builds that pixel and co-simulates it bit-exact. Every
//! number is checked against an independent recomputation from the rows (the front, the
//! choice) or against the options' construction (G = 2 narrows W by F − G = 6 bits).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{default_text, edit, have_tools};
use serde_json::Value;

/// Options the tests measure (with the baseline, always kept).
const OPTIONS: [&str; 2] = ["G=2", "G=2+clock-gated"];

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-options-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The default scene on a 20,000-pulse frame (one ROM period, the 4.5 kHz tone on bin 9)
/// with B = 2 bins at C = 2 cycles per pulse: two-second syntheses.
fn small_config(dir: &Path) -> PathBuf {
    let text = edit(
        default_text(),
        &[
            ("duration_s = 1.0", "pulses = 20000"),
            ("bins = 16", "bins = 2"),
            ("cycles_per_pulse = 16", "cycles_per_pulse = 2"),
        ],
    );
    let p = dir.join("small.toml");
    std::fs::write(&p, text).expect("write config");
    p
}

fn run(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .arg("--cache")
        .arg(cache)
        .output()
        .expect("run tofprobe")
}

fn options_args<'a>(cfg: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["size", cfg, "--sweep-bins", "1,2", "--options"];
    for o in OPTIONS {
        v.extend(["--option", o]);
    }
    v.extend_from_slice(extra);
    v
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// One test, in order, so the syntheses of the first command are the cache of the others:
/// the refusals that come before any synthesis, the study on both libraries, an
/// unreachable target, then `flow --recommended`.
#[test]
fn options_study_recommendation_and_flow() {
    if !have_tools(&["yosys", "sta", "verilator"]) {
        return;
    }
    let dir = scratch("study");
    let cfg = small_config(&dir);
    let cfg_s = cfg.to_str().unwrap();
    // `--cache DIR` is the synthesis cache itself; $TOFPROBE_CACHE (flow has no --cache) is
    // its parent.
    let cache = dir.join("cache").join("synth");
    refusals(cfg_s, &cache, &dir);
    let rec = front_and_recommendation(cfg_s, &cache, &dir.join("set"));
    bins_from_a_layout_report(cfg_s, &cache, &dir);
    unreachable_target_names_the_closest_option(cfg_s, &cache);
    flow_recommended_builds_and_cosimulates_the_choice(cfg_s, &cache, &dir.join("out"), &rec);
}

/// The recommended option's name.
fn front_and_recommendation(cfg: &str, cache: &Path, out_dir: &Path) -> String {
    // A 20,000-pulse frame leaves ~3–12 µm of ΣΔ and photon noise in the tone (measured:
    // baseline 6.8 µm mean over the five seeds, worst 11.4): a 30 µm target every option
    // meets, so the choice is the area's.
    let mut args = options_args(cfg, &["--target-error-um", "30", "--json", "--out"]);
    args.push(out_dir.to_str().unwrap());
    let o = run(&args, cache);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    common::finite::assert_finite_output("size --options --json", &o.stdout);
    let j = common::last_json(&o);
    let opts = &j["options"];
    let rows = opts["rows"].as_array().expect("rows");
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["option"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["baseline", OPTIONS[0], OPTIONS[1]]);
    // osu018, then sky130 tt (the vendored PDK, third_party/sky130_fd_sc_hd): the front is read on sky130.
    let libs: Vec<&str> = rows[0]["libraries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["library"].as_str().unwrap())
        .collect();
    assert_eq!(libs, ["osu018_stdcells", "sky130_fd_sc_hd__tt_025C_1v80"]);
    let lib = 1;
    assert_eq!(opts["front_library"], libs[1]);
    // The baseline's bins per pitch on sky130 are the size report's own.
    assert_eq!(rows[0]["libraries"][lib]["fits"], j["sky130"]["fits"]);

    // Every row: five seeds, a spread that contains its mean, a timing verdict.
    for r in rows {
        let e = &r["tone_error_um"];
        assert_eq!(e["per_seed"].as_array().unwrap().len(), 5, "{r}");
        assert!(
            f(&e["min"]) <= f(&e["mean"]) && f(&e["mean"]) <= f(&e["max"]),
            "{e}"
        );
        let t = &r["libraries"][lib]["timing"];
        assert!(t["slack_percent"].is_number(), "untimed: {r}");
    }

    // G = 2 keeps 2 of the F = 8 fraction bits: every register 6 bits narrower, and the
    // pixel smaller; the register file shrinks most.
    let (base, g2) = (&rows[0], &rows[1]);
    assert_eq!(g2["register_frac_bits"], 2);
    assert_eq!(
        g2["width_bits"].as_u64().unwrap() + 6,
        base["width_bits"].as_u64().unwrap(),
        "G = 2 must narrow W by F − G"
    );
    let area = |r: &Value| f(&r["libraries"][lib]["total_area_um2"]);
    let regs = |r: &Value| f(&r["libraries"][lib]["register_file_um2"]);
    assert!(area(g2) < area(base), "{} vs {}", area(g2), area(base));
    assert!(regs(g2) < regs(base));
    // The clock-gated file drops the per-bit write multiplexer: smaller again.
    assert!(
        regs(&rows[2]) < regs(g2),
        "clock gates {} vs enables {}",
        regs(&rows[2]),
        regs(g2)
    );

    // The front, recomputed naively: not dominated in (area per bin, mean error).
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            (
                f(&r["libraries"][lib]["model"]["per_bin_um2"]),
                f(&r["tone_error_um"]["mean"]),
            )
        })
        .collect();
    for (i, r) in rows.iter().enumerate() {
        let dominated = pts.iter().enumerate().any(|(j, q)| {
            j != i && q.0 <= pts[i].0 && q.1 <= pts[i].1 && (q.0 < pts[i].0 || q.1 < pts[i].1)
        });
        assert_eq!(r["on_front"], !dominated, "{}", r["option"]["name"]);
    }
    // The choice, recomputed: least area among rows meeting the clock and the target.
    let best = rows
        .iter()
        .filter(|r| r["meets_clock"] == true && f(&r["tone_error_um"]["max"]) <= 30.0)
        .min_by(|a, b| area(a).total_cmp(&area(b)))
        .expect("a row meets the target");
    assert_eq!(opts["recommendation"]["option"], best["option"]["name"]);

    // The set: the front's SVG beside the report, the Markdown tables.
    let svg = std::fs::read_to_string(out_dir.join("size-options.svg")).expect("front SVG");
    assert!(
        svg.contains("Pareto front") && svg.contains(OPTIONS[0]),
        "svg"
    );
    let md = std::fs::read_to_string(out_dir.join("size-report.md")).expect("report");
    for part in [
        "Architecture options",
        "Bins per pixel pitch",
        "paper (40 nm estimate) | 6 | 13",
        "**Recommended:**",
    ] {
        assert!(md.contains(part), "`{part}` missing from the report");
    }
    opts["recommendation"]["option"]
        .as_str()
        .unwrap()
        .to_string()
}

fn unreachable_target_names_the_closest_option(cfg: &str, cache: &Path) {
    let o = run(
        &[
            "size",
            cfg,
            "--sweep-bins",
            "1,2",
            "--options",
            "--option",
            "G=2",
            "--target-error-um",
            "0.001",
        ],
        cache,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for part in [
        "target-error-um",
        "0.001",
        "the closest is",
        "above the target",
        "try --target-error-um",
    ] {
        assert!(err.contains(part), "`{part}` missing from: {err}");
    }
}

/// A layout report as `tofprobe layout` writes it, with the fields `--layout-report` reads
/// (the rest of a real report is ignored).
fn layout_report(dir: &Path, name: &str, tech: &str, k: f64, drc: u64) -> PathBuf {
    let v = serde_json::json!({
        "schema": tofprobe_layout::report::SCHEMA,
        "tech": tech,
        "config": "small.toml",
        "drc_errors": drc,
        "lvs_match": true,
        "attempts": [{"density": 0.6}],
        "bins_per_pitch": {"routed_factor": k},
    });
    let p = dir.join(name);
    std::fs::write(&p, v.to_string()).expect("write layout report");
    p
}

/// `--layout-report`: every option's bins per pitch from layout on the report's technology
/// (osu018 here, not sky130), recomputed naively from the row's area model times k; the
/// recommendation's count in the Markdown. At 7 nm so that the counts are not all zero
/// (the osu018 model's fixed part fills a 40 µm pitch at 40 nm).
fn bins_from_a_layout_report(cfg: &str, cache: &Path, dir: &Path) {
    let k = 2.0;
    let report = layout_report(dir, "osu018-layout.json", "osu018", k, 0);
    let out_dir = dir.join("set-layout");
    let args = options_args(
        cfg,
        &[
            "--target-error-um",
            "30",
            "--node-nm",
            "7",
            "--layout-report",
            report.to_str().unwrap(),
            "--json",
            "--out",
            out_dir.to_str().unwrap(),
        ],
    );
    let o = run(&args, cache);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = common::last_json(&o);
    let opts = &j["options"];
    assert_eq!(opts["layout"]["factor"], k);
    assert_eq!(opts["layout"]["technology"], "osu018");
    let mut nonzero = 0;
    for r in opts["rows"].as_array().unwrap() {
        let (osu, sky) = (&r["libraries"][0], &r["libraries"][1]);
        assert!(
            sky.get("layout_fits").is_none(),
            "sky130 has no osu018 layout"
        );
        let model = &osu["model"];
        let (fixed, per_bin) = (f(&model["fixed_um2"]), f(&model["per_bin_um2"]));
        let synth = osu["fits"].as_array().unwrap();
        for (i, lf) in osu["layout_fits"].as_array().unwrap().iter().enumerate() {
            // side² = k·(F + n·b)·(7/180)²: n = ⌊(side²/(k·s) − F)/b⌋, at least 0.
            let side = f(&lf["pixel_side_um"]);
            let s = (7.0f64 / 180.0).powi(2);
            let naive = ((side * side / (k * s) - fixed) / per_bin).floor().max(0.0) as u64;
            let got = lf["bins"].as_u64().unwrap();
            // ±1: the naive line and the library's may round the boundary differently.
            assert!(
                got.abs_diff(naive) <= 1,
                "{}: {got} vs {naive}",
                r["option"]["name"]
            );
            let synth_bins = synth[i]["bins"].as_u64().unwrap();
            assert!(
                got < synth_bins,
                "k = 2 must leave fewer bins: {got} vs {synth_bins}"
            );
            nonzero += usize::from(got > 0);
        }
    }
    assert!(
        nonzero > 0,
        "every layout count is 0: the check would not see a wrong k"
    );
    let md = std::fs::read_to_string(out_dir.join("size-report.md")).expect("report");
    for part in [
        "Bins per pixel pitch from layout (k = 2.000, the osu018 macro of small.toml",
        "**The recommended option from layout** (k = 2.000, osu018 at 7 nm)",
        "Bins per pitch from layout: each option's area model times the routed factor",
    ] {
        assert!(md.contains(part), "`{part}` missing from the report");
    }
}

/// Refused before any synthesis: an unknown option, a target that is no tone error, a
/// layout report of a dirty macro or of a technology none of the liberties is.
fn refusals(cfg: &str, cache: &Path, dir: &Path) {
    // Each refused with exit code 2 and an error holding every part.
    let refused = |extra: &[&str], parts: &[&str]| {
        let mut args = vec!["size", cfg, "--no-sky130", "--options"];
        args.extend_from_slice(extra);
        let o = run(&args, cache);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        for p in parts {
            assert!(err.contains(p), "`{p}` missing: {err}");
        }
    };
    let dirty = layout_report(dir, "dirty.json", "osu018", 1.9, 4);
    refused(
        &["--layout-report", dirty.to_str().unwrap()],
        &["`drc_errors` = 4", "dirty.json"],
    );
    let sky = layout_report(dir, "sky.json", "sky130", 1.9, 0);
    refused(
        &["--layout-report", sky.to_str().unwrap()],
        &["layout-report", "sky130"],
    );
    // An unknown option lists the catalogue.
    refused(&["--option", "G=3"], &["\"G=3\"", "G=2+clock-gated"]);
    // So does a target that is no number of µm.
    refused(&["--target-error-um=-1"], &["target-error-um", "> 0"]);
}

fn flow_recommended_builds_and_cosimulates_the_choice(
    cfg: &str,
    cache: &Path,
    out: &Path,
    recommended: &str,
) {
    let mut args = vec!["flow", cfg, "--out", out.to_str().unwrap(), "--recommended"];
    for o in OPTIONS {
        args.extend(["--option", o]);
    }
    args.extend([
        "--target-error-um",
        "30",
        "--frame-pulses",
        "64",
        "--no-size",
    ]);
    let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    // flow has no --cache: the environment points it at the study's synthesis cache.
    c.args(&args).env("TOFPROBE_CACHE", cache.parent().unwrap());
    let o = c.output().expect("run tofprobe");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("flow PASS"), "{stdout}");
    let chosen = stdout
        .lines()
        .find_map(|l| l.strip_prefix("recommended: "))
        .and_then(|l| l.split(' ').next())
        .expect("the recommendation line")
        .to_string();
    // The same study on the same cache: the same choice as `size --options`.
    assert_eq!(chosen, recommended);
    let report = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(report.contains("## Recommended architecture"), "{report}");
    assert!(report.contains(&format!("option `{chosen}`")), "{report}");
    // On this pixel the smallest option is G = 2 with clock gates (both areas shrink, and
    // every row meets the 30 µm target): its RTL has the operand slice and the gates, so
    // the checks below cannot pass vacuously on another choice.
    assert_eq!(chosen, OPTIONS[1]);
    let rtl = std::fs::read_to_string(out.join("rtl").join("tofprobe_pixel.v")).expect("rtl");
    assert!(rtl.contains("x_new["), "the G = 2 operand slice is missing");
    assert!(rtl.contains("gclk_"), "the clock gates are missing");
}
