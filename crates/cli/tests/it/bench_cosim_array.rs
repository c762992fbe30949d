//! `tofprobe bench cosim-array` as users run it: the committed 2 × 2 example array
//! (testbench/array-2x2/array-2x2.toml, N = 16, a 16-entry sign probe) built cold in both
//! Verilator layouts — every pixel inlined, and the pixel one hierarchical block — each
//! co-simulated bit for bit against the model (the hierarchical build once missed the first
//! clock edge: `ready` differed at cycle 1); the JSON names both layouts with their build
//! and tool CPU figures and the ratio; an unknown layout is refused naming the option.
//! Cold cost: two Verilator builds of a tiny 2 × 2 array (≈ 25 CPU-s).

use std::path::Path;

use crate::common::{have_tools, last_json, tofprobe};

fn config() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testbench/array-2x2/array-2x2.toml")
        .display()
        .to_string()
}

#[test]
fn both_layouts_build_cold_and_cosimulate_bit_for_bit() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let cfg = config();
    let o = tofprobe(&[
        "bench",
        "cosim-array",
        &cfg,
        "--rows",
        "2",
        "--cols",
        "2",
        "--frame-pulses",
        "16",
        "--rom-depth",
        "16",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = last_json(&o);
    let layouts = j["layouts"].as_array().unwrap();
    let names: Vec<&str> = layouts
        .iter()
        .map(|l| l["layout"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["flat", "hierarchical"]);
    for l in layouts {
        assert_eq!(l["pass"], true, "{l}");
        assert_eq!(l["mismatches"], 0, "{l}");
        // 2 reset cycles, 16 pulses of C = 4, the walk of 4 pixels and the status cycle.
        assert!(l["cycles"].as_u64().unwrap() > 2 + 16 * 4, "{l}");
        assert!(l["build_seconds"].as_f64().unwrap() > 0.0, "{l}");
        // A cold build runs Verilator and a C++ compiler: seconds of CPU, not zero.
        assert!(l["tools_cpu_seconds"].as_f64().unwrap() > 1.0, "{l}");
    }
    assert_eq!(layouts[0]["cycles"], layouts[1]["cycles"]);
    assert!(j["flat_over_hierarchical_build_cpu"].as_f64().unwrap() > 0.0);
    assert_eq!(j["rows"], 2);
    assert_eq!(j["frame_pulses"], 16);
}

#[test]
fn an_unknown_layout_is_refused_naming_the_option() {
    let o = tofprobe(&[
        "bench",
        "cosim-array",
        &config(),
        "--layouts",
        "flat,inlined",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("layouts") && e.contains("inlined") && e.contains("hierarchical"),
        "{e}"
    );
}
