//! `tofprobe layout` through the binary: a 2-bin pixel placed and routed on osu018 (qflow's
//! graywolf and qrouter), DRC-clean (magic) and LVS-matched (netgen) against its netlist,
//! timed after routing with the routed wires (OpenSTA + SPEF), drawn (klayout), and written
//! as one output set that `check-set` accepts. Its cold cost is the place and route
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
