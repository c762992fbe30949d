//! Every command resolves a configuration through the one resolution
//! (`tofprobe_design::resolve`): the same random documents — edits of the default that
//! land on both sides of the checks (`width = "auto"`, `rom_depth = 1`, frames that are
//! not whole ROM periods, too many bins for the band) — are given to `config`, `simulate`,
//! `rtl` and `vectors` (and, where the document is refused, to `size`, `cosim` and `flow`,
//! whose accepted runs need EDA tools). They must all accept it or all refuse it with the
//! same message, and where accepted, `simulate` and `rtl` must report the same register
//! width.

use crate::common;

use common::{default_text, edit, tofprobe};
use proptest::prelude::*;

/// The first line of stderr (the `error: …` line), or "" on success.
fn verdict(out: &std::process::Output) -> (bool, String) {
    let err = String::from_utf8_lossy(&out.stderr);
    (
        out.status.success(),
        err.lines().next().unwrap_or("").to_string(),
    )
}

/// A document from the drawn knobs.
fn document(pulses: u64, rom_depth: Option<u32>, width: &str, bins: &str) -> String {
    let mut text = edit(
        default_text(),
        &[
            ("duration_s = 1.0", &format!("pulses = {pulses}")),
            ("bins = 16", &format!("bins = {bins}")),
            ("cycles_per_pulse = 16", "cycles_per_pulse = 32"),
        ],
    );
    let mut extra = String::new();
    if let Some(l) = rom_depth {
        extra.push_str(&format!("rom_depth = {l}\n"));
    }
    if !width.is_empty() {
        extra.push_str(&format!("width = {width}\n"));
    }
    text = text.replacen("[pixel]\n", &format!("[pixel]\n{extra}"), 1);
    text
}

/// The `W = n bits` of `simulate`'s text output, or the `x n bits` of `rtl`'s.
fn width_in(stdout: &str, before: &str, after: &str) -> Option<u32> {
    let i = stdout.find(before)? + before.len();
    stdout[i..].split(after).next()?.trim().parse().ok()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10, .. ProptestConfig::default() })]

    #[test]
    fn every_command_accepts_and_refuses_alike(
        pulses in prop::sample::select(vec![20_000u64, 40_000, 30_000]),
        rom_depth in prop::sample::select(vec![None, Some(1u32), Some(1000), Some(2048), Some(20_000)]),
        width in prop::sample::select(vec!["", "\"auto\"", "30", "39", "50"]),
        bins in prop::sample::select(vec!["8", "16", "\"auto\""]),
    ) {
        let dir = tempfile_dir();
        let path = dir.join("doc.toml");
        std::fs::write(&path, document(pulses, rom_depth, width, bins)).expect("write");
        let p = path.to_str().expect("utf-8 path");
        let rtl_out = dir.join("rtl");
        let vec_out = dir.join("vectors");
        let config = verdict(&tofprobe(&["config", p]));
        let simulate_out = tofprobe(&["simulate", p]);
        let rtl_run = tofprobe(&["rtl", p, "--out", rtl_out.to_str().expect("utf-8")]);
        let runs = [
            ("simulate", verdict(&simulate_out)),
            ("rtl", verdict(&rtl_run)),
            ("vectors", verdict(&tofprobe(&[
                "vectors", p, "--out", vec_out.to_str().expect("utf-8"),
                "--frame-pulses", "64", "--frames", "1",
            ]))),
        ];
        for (name, v) in &runs {
            prop_assert_eq!(v, &config, "{} disagrees with config", name);
        }
        if config.0 {
            let s = String::from_utf8_lossy(&simulate_out.stdout);
            let r = String::from_utf8_lossy(&rtl_run.stdout);
            let ws = width_in(&s, "W = ", " bits");
            let wr = width_in(&r, "registers x ", " bits");
            prop_assert!(ws.is_some() && ws == wr, "W: simulate {:?}, rtl {:?}", ws, wr);
        } else {
            // Refused before any tool runs: the same message from the tool commands.
            for args in [
                vec!["size", p, "--no-sky130"],
                vec!["cosim", p, "--out", dir.join("c").to_str().expect("utf-8")],
                vec!["flow", p, "--no-size", "--out", dir.join("f").to_str().expect("utf-8")],
            ] {
                prop_assert_eq!(verdict(&tofprobe(&args)), config.clone(), "{:?}", args);
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// A fresh directory under the test target's temporary directory.
fn tempfile_dir() -> std::path::PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "resolution-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).expect("tmp dir");
    d
}

/// The two disagreements of issue 14, fixed: `width = "auto"` is accepted by `rtl` as by
/// `config`, and `rom_depth = 1` is refused by `config` and `rtl` as by `simulate`, naming
/// the field, the value and the depth that works (the `[probe]` ROM's, 20,000).
#[test]
fn width_auto_and_rom_depth_one_agree() {
    let dir = tempfile_dir();
    let auto = dir.join("auto.toml");
    std::fs::write(&auto, document(20_000, None, "\"auto\"", "16")).expect("write");
    let a = auto.to_str().expect("utf-8");
    assert!(tofprobe(&["config", a]).status.success());
    let out = dir.join("rtl");
    let r = tofprobe(&["rtl", a, "--out", out.to_str().expect("utf-8")]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));

    let one = dir.join("one.toml");
    std::fs::write(&one, document(20_000, Some(1), "", "16")).expect("write");
    let o = one.to_str().expect("utf-8");
    for cmd in ["config", "simulate"] {
        let v = verdict(&tofprobe(&[cmd, o]));
        assert!(!v.0, "{cmd} accepted rom_depth = 1");
        assert!(
            v.1.contains("pixel.rom_depth = 1 is not possible")
                && v.1.contains("nearest valid value: 20000"),
            "{cmd}: {}",
            v.1
        );
    }
    let v = verdict(&tofprobe(&[
        "rtl",
        o,
        "--out",
        out.to_str().expect("utf-8"),
    ]));
    assert!(!v.0 && v.1.contains("pixel.rom_depth = 1"), "{}", v.1);
    let _ = std::fs::remove_dir_all(&dir);
}
