//! The flow through the library, as `tofprobe flow` calls it (`command::choose`,
//! `command::run_any`; the CLI keeps one smoke test): the embedded default renders its ΣΔ
//! ROM (periodic, L = 20,000: the 4.5 kHz tone on bin 9), co-simulates clean on a
//! 60,000-pulse frame (three ROM periods) and reports the normalised spectrum; sign-off on
//! a two-bin pixel's short frame replays the flow's own vectors at gate level on osu018
//! and sky130 and proves equivalence, and a frame too long for gate level is refused before
//! any simulation; a frame count out of range and `recommended` on an array are refused
//! before any study runs, naming the option.

use tofprobe_design::{DEFAULT_TOML, Document};
use tofprobe_flow::FlowError;
use tofprobe_flow::adders::resolve;
use tofprobe_flow::command::{Recommend, choose, run_any};
use tofprobe_flow::flow::{FlowOptions, FlowOutcome, check_frames};

fn design(text: &str) -> tofprobe_design::ResolvedDesign {
    let doc = Document::from_toml_str(text, "test.toml").expect("parses");
    resolve(doc, "test.toml", &mut Default::default()).expect("resolves")
}

fn options(out: &std::path::Path) -> FlowOptions {
    FlowOptions {
        out: out.to_path_buf(),
        frame_pulses: None,
        full_frame: false,
        frames: 1,
        no_size: true,
        sky130: false,
        signoff: false,
        options: None,
    }
}

fn run(d: &tofprobe_design::ResolvedDesign, o: &FlowOptions) -> FlowOutcome {
    let (d, study) = choose(d.clone(), o.frames, None).expect("no study asked");
    assert!(study.is_none());
    run_any(&d, o).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_default_uses_the_sigma_delta_rom_and_passes() {
    if !tofprobe_testkit::tools::have(&["verilator"], "flow::command") {
        return;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let o = run(&design(DEFAULT_TOML), &options(dir.path()));
    assert!(o.pass, "{o:?}");
    // 60000 = the largest N ≤ 65536 with 4500 Hz · N / 10 MHz an integer (27).
    assert_eq!(o.frame_pulses, 60_000);
    assert_eq!(o.mismatches, 0);
    assert!(
        o.size_line.contains("sizing skipped (--no-size)"),
        "{}",
        o.size_line
    );
    let md = std::fs::read_to_string(&o.report).expect("report");
    assert!(md.contains("ΣΔ probe ROM (periodic rectangular"), "{md}");
    assert!(md.contains("wrap clean"), "{md}");
    assert!(md.contains("| 0 | 9 | 4500.0 |"), "{md}");
    // The rendered ROM image is L = 20,000 entries deep (one `$readmemh` line each).
    let hex = std::fs::read_to_string(dir.path().join("rtl/tofprobe_probe_rom.hex")).expect("rom");
    let lines = hex
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .count();
    assert_eq!(lines, 20_000);
}

/// A 20,000-pulse frame (one ROM period), not the default's 10^7: registers 9 bits
/// narrower, so the two syntheses and equivalence proofs take 23 CPU-s, not 34. (A broken
/// netlist failing both checks is crates/eda/tests/it/signoff.rs.)
#[test]
fn signoff_on_a_short_frame_replays_and_proves_on_both_libraries() {
    if !tofprobe_testkit::tools::have(&["verilator", "iverilog", "yosys"], "flow::command") {
        return;
    }
    let text = DEFAULT_TOML.replacen("bins = 16", "bins = 2", 1).replacen(
        "duration_s = 1.0",
        "pulses = 20000",
        1,
    );
    assert!(
        text.contains("bins = 2 ") && text.contains("pulses = 20000"),
        "default changed"
    );
    let d = design(&text);
    let dir = tempfile::tempdir().expect("temp dir");
    let o = FlowOptions {
        frame_pulses: Some(64),
        frames: 2,
        signoff: true,
        ..options(dir.path())
    };
    let out = run(&d, &o);
    assert!(out.pass, "{out:?}");
    let libs: Vec<&str> = out.signoff.iter().map(|l| l.library.as_str()).collect();
    assert_eq!(
        libs,
        ["osu018", "sky130_fd_sc_hd tt_025C_1v80"],
        "{:?}",
        out.signoff
    );
    for l in &out.signoff {
        assert!(l.pass(), "{}", l.text);
        // 2 + 2·(64·16 + 4 + 2) + 1 = 2063 cycles (4 registers: 2 bins × I, Q).
        assert!(
            l.text
                .contains("gate-level replay 2063 cycles, 2 frame(s) bit-exact"),
            "{}",
            l.text
        );
    }
    let md = std::fs::read_to_string(&out.report).expect("report");
    assert!(
        md.contains("## Sign-off") && md.contains("equivalence proven"),
        "{md}"
    );

    let long = FlowOptions {
        frame_pulses: Some(60_000),
        frames: 1,
        ..o
    };
    let e = run_any(&d, &long).expect_err("too long for gate level");
    let msg = e.to_string();
    assert!(
        msg.contains("--signoff") && msg.contains("960009-cycle trace"),
        "{msg}"
    );
}

#[test]
fn frames_out_of_range_and_recommended_arrays_are_refused_before_any_study() {
    for bad in [0, 101] {
        let e = check_frames(bad).expect_err("out of range");
        assert!(
            e.to_string().contains("--frames = ") && e.to_string().contains("1..=100"),
            "{e}"
        );
    }
    check_frames(1).expect("1 frame");
    check_frames(100).expect("100 frames");
    let recommend = Recommend {
        only: vec![],
        target_error_um: 1.0,
    };
    // Both refusals come back at once: the options study takes minutes.
    let started = std::time::Instant::now();
    let pixel = design(DEFAULT_TOML);
    let e = choose(pixel, 0, Some(&recommend)).expect_err("frames = 0");
    assert!(e.to_string().contains("--frames = 0"), "{e}");
    let array = design(&format!(
        "{DEFAULT_TOML}\n[array]\nrows = 2\ncols = 2\npitch_um = 40.0\nmm_per_pixel = 1.0\n"
    ));
    let e = choose(array, 1, Some(&recommend)).expect_err("an array");
    assert!(
        matches!(&e, FlowError::Experiment(x) if x.to_string().contains("--recommended")),
        "{e}"
    );
    assert!(started.elapsed().as_secs() < 30, "{:?}", started.elapsed());
}
