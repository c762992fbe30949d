//! Reliability through the binary (docs/reliability.md): user text never reaches a
//! generated file raw, path spellings do not change outputs, a killed `vectors` leaves the
//! old set or the new set whole, a full disk or a full stdout is an error (exit 2, no
//! panic, no leftovers), long file names work, and extreme configurations print only finite
//! numbers.

use crate::common;

use std::collections::BTreeMap;
use std::process::{Command, Stdio};
use std::time::Duration;

use common::{default_text, edit, listing, tofprobe, whole_set_seed};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
}

const EVIL: &str =
    "o\nmodule evil; initial $display(\"pwned\"); endmodule\n*/ `x` \u{7}\r# [x]\nk = 1";

#[test]
fn command_line_text_never_reaches_a_generated_file_raw() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = tmp.path().join("c\nmodule m; endmodule\n.toml");
    std::fs::write(&cfg, default_text()).unwrap();
    let out = tmp.path().join(EVIL);
    let o = bin()
        .args(["rtl"])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .args(["--frame-pulses", "64"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let vout = tmp.path().join(format!("{EVIL}v"));
    let o = bin()
        .args(["vectors", "--frame-pulses", "64", "--frames", "1", "--out"])
        .arg(&vout)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for dir in [&out, &vout] {
        for name in listing(dir) {
            let text = std::fs::read_to_string(dir.join(&name)).unwrap();
            assert!(
                !text.contains("$display(\"pwned\")") && !text.contains("\nk = 1"),
                "{name}"
            );
            if name.ends_with(".v") {
                let modules = text.lines().filter(|l| l.starts_with("module ")).count();
                assert_eq!(modules, 1, "{name}: one module per file");
            }
            if name.ends_with(".hex") {
                // $readmemh: comments and hex words only.
                for l in text.lines() {
                    assert!(
                        l.starts_with("//") || l.chars().all(|c| c.is_ascii_hexdigit()),
                        "{name}: `{l}`"
                    );
                }
            }
            if name.ends_with(".toml") {
                toml::from_str::<toml::Table>(&text)
                    .unwrap_or_else(|e| panic!("{name} is not TOML: {e}"));
            }
        }
    }
    // A deliberately raw header would fail the module count: the check can fail.
    let raw = format!("// regenerate with `tofprobe rtl --out {EVIL}`\nmodule tofprobe_top;\n");
    assert_eq!(raw.lines().filter(|l| l.starts_with("module ")).count(), 2);
}

#[test]
fn the_spelling_of_out_does_not_change_a_byte() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    for (cwd, spelling) in [(a.path(), "X"), (b.path(), "./X//")] {
        let o = bin()
            .current_dir(cwd)
            .args(["rtl", "--frame-pulses", "64", "--out", spelling])
            .output()
            .unwrap();
        assert!(o.status.success());
    }
    let (x, y) = (a.path().join("X"), b.path().join("X"));
    assert_eq!(listing(&x), listing(&y));
    for n in listing(&x) {
        assert_eq!(
            std::fs::read(x.join(&n)).unwrap(),
            std::fs::read(y.join(&n)).unwrap(),
            "{n}"
        );
    }
}

#[test]
fn a_killed_vectors_run_leaves_the_old_or_the_new_set_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("v");
    let args = |seed: &str| {
        let mut c = bin();
        c.args([
            "vectors",
            "--frame-pulses",
            "4096",
            "--frames",
            "2",
            "--seed",
            seed,
        ])
        .arg("--out")
        .arg(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        c
    };
    assert!(args("1").status().unwrap().success());
    assert_eq!(whole_set_seed(&dir), Some(1));
    // Kill points spread over a run (≈ 1.8 s here, most of it staging and fsync), the last after it ends; fixed, so the test is deterministic.
    let (mut old, mut new, mut recovered) = (0, 0, 0);
    for (i, ms) in [20u64, 300, 600, 900, 1200, 1400, 1600, 1800, 4000]
        .iter()
        .enumerate()
    {
        let seed = (i + 2).to_string();
        let mut child = args(&seed).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(*ms));
        let _ = child.kill();
        let _ = child.wait();
        // Before any recovery: a visible set is whole, or it lacks its manifest (an
        // interrupted commit, which readers refuse).
        let before = whole_set_seed(&dir);
        if before.is_none() {
            assert!(
                !dir.join("manifest.toml").exists(),
                "torn set with a manifest"
            );
        }
        tofprobe_io::recover(&dir).unwrap();
        recovered += usize::from(before.is_none());
        let seed_now = whole_set_seed(&dir).expect("after recovery the set is whole");
        assert!(
            listing(&dir).iter().all(|n| !n.starts_with('.')),
            "{:?}",
            listing(&dir)
        );
        if seed_now.to_string() == seed {
            new += 1;
        } else {
            old += 1;
        }
        // The next kill starts from whatever set is there now.
    }
    eprintln!("kill test: {old} old set, {new} new set, {recovered} completed by recovery");
    assert!(new >= 1, "the run left to finish must install its set");
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full");
    let Ok(full) = full else {
        eprintln!("skipped: no /dev/full");
        return;
    };
    let o = bin()
        .args(["config", "--print-default"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("error: cannot write to standard output") && !err.contains("panicked"),
        "{err}"
    );
}

/// A short windowed Fourier frame (fast through `simulate`).
fn short(extra: &[(&str, &str)]) -> String {
    let mut e = vec![
        ("duration_s = 1.0 ", "pulses = 4096 #"),
        ("rom_mode = \"periodic\"", "rom_mode = \"windowed\""),
        ("bins = 16 ", "bins = 4 "),
        ("cycles_per_pulse = 16 ", "cycles_per_pulse = 4 "),
    ];
    e.extend_from_slice(extra);
    edit(default_text(), &e)
}

#[test]
fn a_250_byte_svg_name_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = tmp.path().join("c.toml");
    std::fs::write(&cfg, short(&[])).unwrap();
    let svg = tmp.path().join("s".repeat(246) + ".svg");
    let o = bin()
        .arg("simulate")
        .arg(&cfg)
        .arg("--svg")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    assert_eq!(listing(tmp.path()).len(), 2, "no temporary left");
}

#[test]
fn extreme_configurations_print_only_finite_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: BTreeMap<&str, Vec<(&str, &str)>> = BTreeMap::from([
        (
            "no detections",
            vec![("signal_rate = 1.0", "signal_rate = 0.0")],
        ),
        (
            "smallest amplitude",
            vec![("amplitude = 0.5 ", "amplitude = 0.01 ")],
        ),
        (
            "tiny signal",
            vec![("signal_rate = 1.0", "signal_rate = 1e-300")],
        ),
        (
            "all background",
            vec![("background_rate = 0.0", "background_rate = 50.0")],
        ),
    ]);
    for (what, edits) in cases {
        let cfg = tmp.path().join("x.toml");
        std::fs::write(&cfg, short(&edits)).unwrap();
        let o = bin()
            .arg("simulate")
            .arg(&cfg)
            .arg("--json")
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{what}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        common::finite::assert_finite(what, &v);
        let t = bin().arg("simulate").arg(&cfg).output().unwrap();
        let text = String::from_utf8_lossy(&t.stdout).to_lowercase();
        assert!(
            !text.contains("nan") && !text.contains("inf"),
            "{what}: {text}"
        );
    }
    let o = tofprobe(&["config", "--print-default"]);
    assert!(o.status.success());
}

#[test]
fn a_full_disk_leaves_no_partial_set() {
    let tmp = tempfile::tempdir().unwrap();
    let mnt = tmp.path().join("small");
    std::fs::create_dir(&mnt).unwrap();
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs"])
        .arg(&mnt)
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        eprintln!(
            "skipped: cannot mount a small tmpfs (needs root); the full-disk test did not run"
        );
        return;
    }
    let o = bin()
        .args(["rtl", "--out"])
        .arg(mnt.join("rtl"))
        .output()
        .unwrap();
    let left = listing(&mnt);
    let _ = Command::new("umount").arg(&mnt).status();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(left.is_empty(), "a full disk left {left:?}");
}

/// `--svg FILE` never replaces a user's file that is not an SVG (issue 31): `simulate`
/// refuses with exit 2 naming why and leaves the file as it was; an SVG at the path (its
/// own earlier plot) is replaced.
#[test]
fn an_svg_path_holding_a_foreign_file_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let notes = tmp.path().join("notes.svg");
    std::fs::write(&notes, "my lab notes\n").unwrap();
    let cfg = tmp.path().join("short.toml");
    std::fs::write(
        &cfg,
        tofprobe_design::DEFAULT_TOML.replacen("duration_s = 1.0", "pulses = 40000", 1),
    )
    .unwrap();
    let run = |svg: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .arg("simulate")
            .arg(&cfg)
            .arg("--svg")
            .arg(svg)
            .output()
            .unwrap()
    };
    let o = run(&notes);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not an SVG"), "{err}");
    assert_eq!(std::fs::read_to_string(&notes).unwrap(), "my lab notes\n");
    let plot = tmp.path().join("plot.svg");
    std::fs::write(&plot, "<svg xmlns=\"http://www.w3.org/2000/svg\"></svg>\n").unwrap();
    let o = run(&plot);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read_to_string(&plot)
            .unwrap()
            .contains("bit-true spectrum")
    );
}
