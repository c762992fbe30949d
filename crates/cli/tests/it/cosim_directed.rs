//! `tofprobe cosim --directed` as users run it: the contract's directed sequencer
//! (docs/pixel-contract.md, "The directed sequencer") co-simulates the default with a short
//! frame in Verilator and in Icarus, three frames per loop, for the closed-form number of
//! cycles; the committed (reference-sequencer) RTL is refused under `--directed`, naming
//! the sequencer; `--long-frame` needs `--directed`.

use crate::common;
use common::tofprobe;
use std::path::{Path, PathBuf};

fn tools() -> bool {
    common::have_tools(&["verilator", "iverilog", "vvp"])
}

fn out_dir(name: &str) -> String {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cosim-directed-out")
        .join(name)
        .display()
        .to_string()
}

fn json(o: &std::process::Output) -> serde_json::Value {
    common::last_json(o)
}

/// Cycles of one directed loop of the default (R = 32, A = 2, so K = 16; C = 16; W = 39, so
/// the saturation burst is capped at 2·4096) with N = 16 and a long frame of M·N: the
/// program's table summed by hand.
fn loop_cycles(m: u64) -> u64 {
    let (n, c, k, r) = (16, 16, 16, 32);
    (n / 2 - 1) * c + 1 + (c - 1) // half a frame, its last pulse, the mid-frame reset
        + n * c + 1 + (r + 2) // frame 0, readout with a pulse, pulses during the readout
        + 2 * k + n * c + 2 * 4096 + k + (k + 1) + (r + 2) // frame 1
        + (m * n - 1) * c + 1 + (k + 1) + (r + 2) // frame 2
}

#[test]
fn directed_cosim_passes_in_both_simulators() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    for sim in ["verilator", "icarus"] {
        let o = tofprobe(&[
            "cosim",
            "--directed",
            "--long-frame",
            "2",
            "--frame-pulses",
            "16",
            "--rom-depth",
            "16",
            "--json",
            "--simulator",
            sim,
            "--out",
            &out_dir(sim),
        ]);
        assert!(
            o.status.success(),
            "{sim}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let j = json(&o);
        assert_eq!(j["pass"], true, "{sim}: {j}");
        assert_eq!(j["frames"], 3, "three frames per loop: {j}");
        assert_eq!(j["cycles"], 2 + loop_cycles(2) + 1, "{sim}: {j}");
    }
}

#[test]
fn reference_rtl_is_refused_under_directed() {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl");
    let o = tofprobe(&[
        "cosim",
        "--directed",
        "--rtl",
        from.to_str().expect("utf-8"),
        "--frame-pulses",
        "64",
        "--out",
        &out_dir("refused"),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("sequencer") && err.contains("reference") && err.contains("directed"),
        "{err}"
    );
    let o = tofprobe(&["cosim", "--long-frame", "2"]);
    assert!(!o.status.success(), "--long-frame without --directed");
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--directed"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
