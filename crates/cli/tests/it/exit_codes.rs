//! The documented exit codes (README.md, "Exit codes"), through the binary: for every
//! command an ok case (0) and an error case (2: usage, input or I/O), FAIL = 1 for a
//! co-simulation of a hand-broken pixel, and a quiet 141 on a closed stdout pipe.
//!
//! Cheap cases only: the ok runs of `reproduce --quick` (≈ 25 s) and `size` (yosys, ≈ 11 s)
//! are not repeated here; reproduce.rs (`quick_json_rows_carry_seeds_bands_and_z_scores`)
//! and size.rs (`tiny_pixel_json_report`) assert their status 0, and reproduce's FAIL = 1
//! (a missed paper row) has no cheap trigger.

use crate::common;
use common::{default_text, edit, short_tone_frame, tofprobe};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("exit-codes")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("mkdir");
    d
}

fn eda() -> bool {
    common::have_tools(&["verilator", "iverilog", "vvp"])
}

/// Runs `tofprobe args` and asserts the exit status (and, for 2, an `error:` line).
fn expect(code: i32, args: &[&str]) {
    let o = tofprobe(args);
    assert_eq!(
        o.status.code(),
        Some(code),
        "tofprobe {args:?}\nstdout: {}\nstderr: {}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    if code == 2 {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.starts_with("error:") || err.contains("\nerror:"),
            "{args:?}: {err}"
        );
    }
    if code != 101 {
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("panicked"),
            "{args:?} panicked"
        );
    }
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn every_command_exits_with_its_documented_code() {
    let d = scratch("commands");
    let tiny = d.join("tiny.toml");
    std::fs::write(&tiny, short_tone_frame(4096)).expect("config");
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        edit(
            default_text(),
            &[("bins = 16", "bins = 16\nno_such_key = 1")],
        ),
    )
    .expect("config");
    let missing = s(&d.join("missing.toml")).to_string();

    expect(0, &["--help"]);
    expect(0, &["--version"]);
    // No command: clap's usage text (no `error:` line), status 2.
    assert_eq!(tofprobe(&[]).status.code(), Some(2));
    expect(2, &["no-such-command"]);

    expect(0, &["config", "--print-default"]);
    expect(0, &["config", s(&tiny)]);
    expect(2, &["config", s(&bad)]);

    expect(0, &["simulate", s(&tiny)]);
    expect(2, &["simulate", &missing]);

    expect(0, &["bench", "scene", "--pulses", "65536"]);
    expect(2, &["bench", "scene", "--pulses", "0"]);

    // reproduce: ok in reproduce.rs (see the header); a usage error here.
    expect(2, &["reproduce", "--no-such-option"]);

    // The vendored record: always there, so the ok case always runs.
    let ptu = tofprobe_testkit::data::tttr_record("hydraharp_v20_t3.ptu");
    expect(0, &["replay", s(&ptu)]);
    let truncated = d.join("truncated.ptu");
    std::fs::write(&truncated, b"PQTTTR\0\0").expect("write");
    expect(2, &["replay", s(&truncated)]);

    // size: ok in size.rs (see the header); an unreadable liberty here.
    expect(
        2,
        &["size", s(&tiny), "--liberty", s(&d.join("missing.lib"))],
    );

    let rtl = d.join("rtl");
    expect(0, &["rtl", "--out", s(&rtl), "--frame-pulses", "64"]);
    std::fs::write(rtl.join("tofprobe_top.v"), "// mine\n").expect("write");
    expect(2, &["rtl", "--out", s(&rtl), "--frame-pulses", "64"]);

    let vec = d.join("vectors");
    expect(0, &["vectors", "--out", s(&vec), "--frame-pulses", "64"]);
    expect(2, &["vectors", "--out", s(&vec), "--frames", "0"]);

    let t = d.join("tradeoff");
    let t = s(&t);
    let tiny_s = s(&tiny);
    expect(
        0,
        &[
            "tradeoff",
            tiny_s,
            "--sweep-pulses",
            "4096",
            "--reps",
            "1",
            "--out",
            t,
        ],
    );
    expect(2, &["tradeoff", &missing]);

    expect(2, &["flow", "--frames", "0"]);
    expect(
        2,
        &[
            "cosim",
            "--x-seed",
            "0",
            "--frame-pulses",
            "64",
            "--out",
            s(&d.join("c")),
        ],
    );
    if !eda() {
        eprintln!("*** SKIPPED flow/cosim ok and FAIL cases: EDA tools missing ***");
        return;
    }
    let f = d.join("flow");
    expect(
        0,
        &["flow", "--frame-pulses", "64", "--no-size", "--out", s(&f)],
    );
}

/// A hand-broken pixel (adder 0 subtracts where it should add) in a copy of the committed
/// short RTL: the verdict FAIL is exit status 1; the clean copy passes with 0.
#[test]
fn cosim_fail_is_exit_status_1() {
    if !eda() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("cosim");
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl");
    for (name, broken) in [("clean", false), ("broken", true)] {
        let rtl = d.join(name);
        std::fs::create_dir_all(&rtl).expect("mkdir");
        for e in std::fs::read_dir(&from).expect("dir") {
            let e = e.expect("entry");
            std::fs::copy(e.path(), rtl.join(e.file_name())).expect("copy");
        }
        if broken {
            let pixel = rtl.join("tofprobe_pixel.v");
            let text = std::fs::read_to_string(&pixel).expect("pixel");
            let good = "add_0 ? (yin_0 + opx) : (yin_0 - opx)";
            assert!(text.contains(good));
            std::fs::write(
                &pixel,
                text.replace(good, "add_0 ? (yin_0 - opx) : (yin_0 + opx)"),
            )
            .expect("write");
        }
        let out = d.join(format!("{name}-out"));
        expect(
            if broken { 1 } else { 0 },
            &[
                "cosim",
                "--rtl",
                s(&rtl),
                "--frame-pulses",
                "64",
                "--simulator",
                "icarus",
                // The verdict only: no traced Verilator build for a VCD of the mismatch.
                "--no-vcd",
                "--out",
                s(&out),
            ],
        );
    }
}

/// Standard output closed before anything is written (a reader that went away): quiet,
/// status 141 (128 + SIGPIPE), no panic report, no `error:`.
#[test]
fn closed_stdout_pipe_exits_quietly_with_141() {
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["config", "--print-default"])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(141));
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
