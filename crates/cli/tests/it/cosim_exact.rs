//! `tofprobe cosim --rtl DIR` as users run it (issue 17): the committed short-frame default
//! RTL co-simulates clean in Verilator and in Icarus; a frame-length mismatch, a Haar/Fourier
//! mismatch and a one-bit ROM edit are errors naming what differs, before any simulation;
//! a hand-edited (broken) pixel fails in both simulators with the same first mismatch,
//! exit status 1 and the mismatch's expected/actual in the JSON.

use crate::common;
use common::tofprobe;
use std::path::{Path, PathBuf};

fn tools() -> bool {
    common::have_tools(&["verilator", "iverilog", "vvp"])
}

/// A copy of testbench/default-short/rtl (the default with N = 64) under the target dir.
fn copy_short(name: &str) -> PathBuf {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl");
    let to = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cosim-exact")
        .join(name);
    let _ = std::fs::remove_dir_all(&to);
    std::fs::create_dir_all(&to).expect("mkdir");
    for e in std::fs::read_dir(&from).expect("dir") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), to.join(e.file_name())).expect("copy");
    }
    to
}

fn out_dir(name: &str) -> String {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cosim-exact-out")
        .join(name)
        .display()
        .to_string()
}

fn json(o: &std::process::Output) -> serde_json::Value {
    common::last_json(o)
}

#[test]
fn committed_rtl_copy_passes_in_both_simulators() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let rtl = copy_short("clean");
    let rtl = rtl.to_str().expect("utf-8");
    for sim in ["verilator", "icarus"] {
        let o = tofprobe(&[
            "cosim",
            "--rtl",
            rtl,
            "--frame-pulses",
            "64",
            "--frames",
            "2",
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
        assert_eq!(j["simulator"], sim);
        assert_eq!(j["cycles"], 2 + 2 * (64 * 16 + 32 + 2) + 1);
        assert!(j["rom"].as_str().unwrap_or("").contains("L = 20000"), "{j}");
    }
}

#[test]
fn mismatched_rtl_is_refused_naming_the_parameter() {
    let rtl = copy_short("mismatch");
    let rtl = rtl.to_str().expect("utf-8");
    // Frame length: the RTL is N = 64, the run asks for 128.
    let o = tofprobe(&[
        "cosim",
        "--rtl",
        rtl,
        "--frame-pulses",
        "128",
        "--out",
        &out_dir("n"),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("N (pulses per frame) = 64") && err.contains("N (pulses per frame) = 128"),
        "{err}"
    );
    // The full default frame against the short RTL: named too, not a FAIL after minutes.
    let o = tofprobe(&["cosim", "--rtl", rtl, "--out", &out_dir("n-full")]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("= 10000000"));
    // A one-bit ROM edit (manifest removed, so only the comparison can catch it).
    std::fs::remove_file(Path::new(rtl).join("tofprobe_probe_rom.toml")).expect("rm");
    // The set's marker lists the manifest: without that line the set is still whole (a
    // listed file missing is an interrupted set, refused before anything runs).
    let marker = Path::new(rtl).join("tofprobe-set.toml");
    let listed = std::fs::read_to_string(&marker).expect("marker");
    let kept: Vec<&str> = listed
        .lines()
        .filter(|l| !l.starts_with("\"tofprobe_probe_rom.toml\""))
        .collect();
    std::fs::write(&marker, kept.join("\n") + "\n").expect("marker");
    let hex = Path::new(rtl).join("tofprobe_probe_rom.hex");
    let text = std::fs::read_to_string(&hex).expect("hex");
    let first_data = text
        .lines()
        .position(|l| !l.starts_with("//"))
        .expect("data");
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == first_data + 3 {
                let mut c: Vec<char> = l.chars().collect();
                let last = c.len() - 1;
                let v = c[last].to_digit(16).expect("hex") ^ 1;
                c[last] = std::char::from_digit(v, 16).expect("digit");
                c.into_iter().collect()
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&hex, edited.join("\n") + "\n").expect("write");
    let o = tofprobe(&[
        "cosim",
        "--rtl",
        rtl,
        "--frame-pulses",
        "64",
        "--no-vcd",
        "--out",
        &out_dir("rom"),
    ]);
    assert!(!o.status.success());
    // `--no-vcd`: the mismatch is reported, no VCD is written (and no traced build made).
    assert!(!Path::new(&out_dir("rom")).join("cosim.vcd").exists());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("at entry 3: register bit(s) [0] differ"),
        "{err}"
    );
}

#[test]
fn a_broken_pixel_fails_alike_in_both_simulators() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    // A hand edit (an ECO gone wrong): adder 0 subtracts where it should add.
    let rtl = copy_short("broken");
    let pixel = rtl.join("tofprobe_pixel.v");
    let text = std::fs::read_to_string(&pixel).expect("pixel");
    let bad = "add_0 ? (yin_0 - opx) : (yin_0 + opx)";
    let text = text.replace("add_0 ? (yin_0 + opx) : (yin_0 - opx)", bad);
    assert!(text.contains(bad));
    std::fs::write(&pixel, text).expect("write");
    let rtl = rtl.to_str().expect("utf-8");
    let mut firsts = Vec::new();
    for sim in ["verilator", "icarus"] {
        let o = tofprobe(&[
            "cosim",
            "--rtl",
            rtl,
            "--frame-pulses",
            "64",
            "--json",
            "--simulator",
            sim,
            "--out",
            &out_dir(&format!("broken-{sim}")),
        ]);
        assert_eq!(o.status.code(), Some(1), "{sim}: exit status");
        let j = json(&o);
        assert_eq!(j["pass"], false);
        // By default a Verilator mismatch gets a VCD around it (a traced build): the
        // signals a designer opens first.
        if sim == "verilator" {
            let path = j["vcd"].as_str().unwrap_or_else(|| panic!("no VCD: {j}"));
            let vcd = std::fs::read_to_string(path).expect("the VCD exists");
            assert!(vcd.contains("$enddefinitions") && vcd.contains("$var"));
        }
        for k in ["cycle", "pulse", "signal", "expected", "actual"] {
            assert!(
                !j[format!("first_mismatch_{k}")].is_null(),
                "{sim}: {k} missing: {j}"
            );
        }
        firsts.push((
            j["first_mismatch_cycle"].clone(),
            j["first_mismatch_pulse"].clone(),
            j["first_mismatch_signal"].clone(),
        ));
    }
    assert_eq!(
        firsts[0], firsts[1],
        "both simulators report the same first mismatch"
    );
}
