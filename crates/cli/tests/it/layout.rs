//! `tofprobe layout` through the binary: a 2-bin pixel placed and routed on osu018 (qflow's
//! graywolf and qrouter), DRC-clean (magic) and LVS-matched (netgen) against its netlist,
//! its laid-out netlist proven equivalent to the RTL, every shape inside the die, timed
//! after routing with the routed wires (OpenSTA + SPEF, every path group), drawn
//! (klayout), and written as one output set that `check-set` accepts. Its cold cost is the place and route
//! (≈ 4 minutes on two shared cores, qrouter most of it). Bad options fail before any tool
//! runs, naming the option and a value that works.

use crate::common::{self, tofprobe};

#[test]
fn a_two_bin_pixel_routes_drc_and_lvs_clean_on_osu018() {
    if !common::have_tools(&[
        "yosys",
        "sta",
        "qflow",
        "graywolf",
        "qrouter",
        "magic",
        "netgen-lvs",
        "klayout",
        "/usr/share/qflow/tech/osu018/osu018_stdcells.lef",
    ]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("two.toml");
    let text = include_str!("../../../../scenes/default.toml").replacen("bins = 16", "bins = 2", 1);
    assert!(text.contains("bins = 2 "), "default changed");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("layout");
    let cache = dir.path().join("cache");
    // Relative spellings, run from the directory: qflow's scripts run in the project's
    // subdirectories, so the flow must hand them absolute paths (a relative `--cache`
    // once failed in the netlist conversion).
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .current_dir(dir.path())
        .args([
            "layout",
            "two.toml",
            "--out",
            "layout",
            "--cache",
            "cache",
            // Stage 3 skipped, as `auto` does for the default pixel (the path its full
            // layout takes); it also saves the CI a minute of re-routing for wirelength.
            "--route-cleanup",
            "off",
            "--json",
        ])
        .output()
        .expect("run tofprobe");
    assert!(
        run.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let r = common::last_json(&run);
    assert_eq!(r["schema"], "tofprobe-layout-1");
    assert_eq!(r["route_cleanup"], false, "{r}");
    // qrouter itself says it bypassed stage 3 (the script `--route-cleanup off` gave it).
    let key = r["synthesis"]["key"].as_str().unwrap();
    let route_log = std::fs::read_to_string(
        cache
            .join("layout")
            .join(format!("osu018-{key}"))
            .join("log/route.log"),
    )
    .unwrap();
    assert!(
        route_log.contains("Cleanup stage (stage3) bypassed"),
        "{route_log}"
    );
    assert_eq!(r["drc_errors"], 0, "{r}");
    assert_eq!(r["lvs_match"], true, "{r}");
    // Clean at once: the ECO re-route (for a dirty stage-2 route) did not run.
    assert!(r["repair"].is_null(), "{r}");
    assert!(
        r["lvs_result"].as_str().unwrap().contains("match uniquely"),
        "{r}"
    );
    let def = &r["def"];
    // The logic cells fill the core to about the density asked for (0.6), never beyond 1.
    let util = def["cell_area_um2"].as_f64().unwrap()
        / (def["core_width_um"].as_f64().unwrap() * def["core_height_um"].as_f64().unwrap());
    assert!((0.4..=0.75).contains(&util), "utilisation {util}");
    assert!(def["wirelength_um"].as_f64().unwrap() > 1e4, "{def}");
    // Every synthesised cell is placed, plus the clock buffers qflow adds and the buffers
    // `write_blif -buf` puts where the netlist wires a port straight to another net (one
    // on this pixel).
    let cells = def["cells"].as_u64().unwrap();
    let synth = r["synthesis"]["cells"].as_u64().unwrap();
    let extra = cells - synth - r["clock_buffers"].as_u64().unwrap();
    assert!(
        extra <= 3,
        "{extra} cells beyond the netlist and the clock buffers: {r}"
    );
    // Post-route timing: the wires slow the worst path against the ideal-clock synthesis
    // figure, and the SPEF annotated (nearly) every net.
    let p = &r["post_route"];
    let (post, pre) = (
        p["f_max_mhz"].as_f64().unwrap(),
        r["synthesis"]["f_max_mhz"].as_f64().unwrap(),
    );
    assert!(
        post > 50.0 && post < pre,
        "post-route {post} MHz, synthesis {pre} MHz"
    );
    assert!(p["spef_nets"].as_u64().unwrap() * 10 > synth * 9, "{p}");
    // The set is whole, with the macro's views and the picture.
    let check = tofprobe(&["check-set", out.to_str().unwrap()]);
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    for f in [
        "tofprobe_pixel.def",
        "tofprobe_pixel.gds",
        "tofprobe_pixel.lef",
        "tofprobe_pixel.spef",
        "tofprobe_pixel.laid-out.v",
    ] {
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 1000, "{f}");
    }
    let png = std::fs::read(out.join("layout.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000);
    let lef = std::fs::read_to_string(out.join("tofprobe_pixel.lef")).unwrap();
    assert!(
        lef.contains("MACRO tofprobe_pixel") && lef.contains("PIN clk"),
        "LEF"
    );
    let md = std::fs::read_to_string(out.join("layout-report.md")).unwrap();
    assert!(md.contains("| DRC errors (magic) | 0 |"), "{md}");
    assert!(md.contains("## Verdict\n\n**PASS**"), "{md}");
    assert_eq!(r["failures"], serde_json::json!([]), "{r}");
    // Timing: the worst of every path group, OpenSTA's own worst slack (the reader checks
    // that itself); hold judged between registers.
    let groups = p["hold_groups"].as_array().unwrap();
    let worst = groups
        .iter()
        .map(|g| g["slack_ns"].as_f64().unwrap())
        .fold(f64::MAX, f64::min);
    assert_eq!(worst, p["hold_slack_ns"].as_f64().unwrap(), "{p}");
    assert!(
        p["setup_slack_ns"].as_f64().unwrap() >= 0.0
            && p["hold_slack_registers_ns"].as_f64().unwrap() >= 0.0,
        "{p}"
    );

    // The laid-out netlist (the routed DEF's cells and nets, clock buffers included, fill
    // left out) proven equivalent to the RTL, and written into the set.
    let e = &r["equivalence"];
    assert!(
        e["points"].as_u64().unwrap() > 100 && e["proven"] == e["points"],
        "{e}"
    );
    assert_eq!(e["cells"], def["cells"], "{e}");
    let laid = std::fs::read_to_string(out.join("tofprobe_pixel.laid-out.v")).unwrap();
    assert!(
        laid.matches("  CLKBUF1 ").count() > 40,
        "the clock tree's buffers are in it"
    );

    // Every shape inside the die, in the DEF and the GDS; the macro's LEF is the die; the
    // DEF's sections list what they declare. Checked here again, naively: every route
    // point and pin placement of the DEF lies in its DIEAREA, and every section's `- `
    // entries number what its header says.
    assert_eq!(r["def_boundary"]["outside"], 0, "{r}");
    assert_eq!(r["gds"]["outside"], 0, "{r}");
    // osu018 has no cell GDS: the stream's cells are empty and the report says so.
    assert_eq!(r["gds"]["empty_cells"], r["gds"]["cells"], "{r}");
    assert!(md.contains("| GDS holds | routing and pins only"), "{md}");
    let def_text = std::fs::read_to_string(out.join("tofprobe_pixel.def")).unwrap();
    let die: Vec<f64> = def_text
        .lines()
        .find_map(|l| l.strip_prefix("DIEAREA"))
        .unwrap()
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    let mut section: Option<(String, u64, u64)> = None;
    let mut last = (0.0, 0.0);
    for line in def_text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if let [name, n, ";"] = t.as_slice()
            && let Ok(n) = n.parse::<u64>()
            && name.chars().all(|c| c.is_ascii_uppercase())
        {
            section = Some((name.to_string(), n, 0));
        } else if let Some((name, declared, listed)) = section.as_mut() {
            if t.as_slice() == ["END", name.as_str()] {
                assert_eq!(*declared, *listed, "{name}");
                section = None;
            } else if t.first() == Some(&"-") {
                *listed += 1;
            }
        }
        for w in t.windows(4).filter(|w| w[0] == "(" && w[3] == ")") {
            let x = if w[1] == "*" {
                last.0
            } else {
                w[1].parse().unwrap_or(last.0)
            };
            let y = if w[2] == "*" {
                last.1
            } else {
                w[2].parse().unwrap_or(last.1)
            };
            last = (x, y);
            let placed = t.contains(&"PLACED")
                || t.contains(&"ROUTED")
                || t.contains(&"NEW")
                || t.contains(&"FIXED");
            if placed && !t.contains(&"RECT") && !t.contains(&"LAYER") {
                assert!(
                    x >= die[0] && x <= die[2] && y >= die[1] && y <= die[3],
                    "({x}, {y}) outside {die:?}: {line}"
                );
            }
        }
    }
    let size = format!(
        "SIZE {:.3} BY {:.3} ;",
        def["die_width_um"].as_f64().unwrap(),
        def["die_height_um"].as_f64().unwrap()
    );
    assert!(lef.contains(&size), "{size} in the LEF");

    // `size --layout-report`: the macro's post-route corners beside the size report's
    // synthesis corners (the same pixel: one osu018 synthesis, cached by the layout run).
    let report = out.join("layout-report.json");
    let size = tofprobe(&[
        "size",
        cfg.to_str().unwrap(),
        "--no-sky130",
        "--sweep-bins",
        "2",
        "--sweep-widths",
        "39",
        "--cache",
        cache.to_str().unwrap(),
        "--layout-report",
        report.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        size.status.success(),
        "{}",
        String::from_utf8_lossy(&size.stderr)
    );
    let s = common::last_json(&size);
    let row = &s["post_route"]["corners"][0];
    assert_eq!(row["library"], "osu018_stdcells", "{s}");
    // The post-route f_max is the layout's own, and below the size report's synthesis
    // f_max of the same netlist (the wires only slow it).
    assert_eq!(row["post_route"]["f_max_mhz"], p["f_max_mhz"], "{row}");
    let synth_fmax = s["timing_corners"][0]["f_max_mhz"].as_f64().unwrap();
    assert!(
        post < synth_fmax,
        "post-route {post}, synthesis {synth_fmax}"
    );
    // A report of another pixel (the default, B = 16) is refused naming the option.
    let other = tofprobe(&[
        "size",
        "--no-sky130",
        "--layout-report",
        report.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&other.stderr);
    assert_eq!(other.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--layout-report") && err.contains("B = 16"),
        "{err}"
    );
}

#[test]
fn bad_layout_options_are_refused_naming_a_value_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for (args, want) in [
        (vec!["--density", "1.5"], "--density = 1.5"),
        (vec!["--density", "NaN"], "0.5 routes"),
        (vec!["--density", "dense"], "auto or a number"),
        (vec!["--tech", "gf180"], "osu018 or sky130"),
        (vec!["--node-nm", "0"], "--node-nm = 0"),
        (vec!["--route-cleanup", "sometimes"], "auto, on or off"),
    ] {
        let mut a = vec!["layout", "--out", out.to_str().unwrap()];
        a.extend(args);
        let run = tofprobe(&a);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{a:?}: {err}");
        assert!(err.contains(want), "{a:?}: {err}");
        assert!(!out.exists(), "{a:?} left {out:?}");
    }
}
