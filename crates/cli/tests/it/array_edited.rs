//! An array set a designer owns (issue 42, point 3): `tofprobe rtl` writes a 4 × 4 array set,
//! `tofprobe cosim --rtl DIR` re-verifies it as it stands — unedited it passes; with one ROM
//! word changed, or one readout bit inverted, it fails naming the frame, pixel (r, c) and
//! cycle; a renamed port, a missing file and an option the array cannot honour are refused
//! by name; `--junit` writes its report on an array too.
//!
//! Cold cost: three Verilator builds of a 4 × 4 small-pixel array (≈ 20 s each on two cores).

use std::path::Path;

use crate::common::{default_text, edit, have_tools, tofprobe};

/// A 4 × 4 array of small pixels (B = 2: R = 4 registers, C = 4), 20,000 pulses.
fn config() -> String {
    let t = edit(
        default_text(),
        &[
            ("duration_s = 1.0", "pulses = 20000"),
            ("bins = 16", "bins = 2"),
            ("cycles_per_pulse = 16", "cycles_per_pulse = 4"),
        ],
    );
    format!("{t}\n[array]\nrows = 4\ncols = 4\npitch_um = 30.0\nmm_per_pixel = 1.0\n")
}

const SHORT: [&str; 4] = ["--frame-pulses", "16", "--rom-depth", "16"];

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `tofprobe cosim CFG --rtl RTL --json` (+ extra), its JSON and output.
fn cosim_rtl(cfg: &str, rtl: &Path, out: &Path, extra: &[&str]) -> (serde_json::Value, String) {
    let mut args = vec!["cosim", cfg, "--rtl", rtl.to_str().unwrap()];
    args.extend(SHORT);
    args.extend(["--frames", "2", "--json", "--out", out.to_str().unwrap()]);
    args.extend(extra);
    let o = tofprobe(&args);
    let t = text(&o);
    let out = String::from_utf8_lossy(&o.stdout);
    let j = serde_json::from_str(out.lines().last().unwrap_or("")).unwrap_or_default();
    (j, t)
}

/// A copy of the rendered set with `edit` applied to `file` (which must change).
fn edited(set: &Path, to: &Path, file: &str, edit: impl Fn(&str) -> String) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(set).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    let path = to.join(file);
    let before = std::fs::read_to_string(&path).unwrap();
    let after = edit(&before);
    assert_ne!(before, after, "the edit of {file} changed nothing");
    std::fs::write(&path, after).unwrap();
}

#[test]
fn an_edited_array_set_is_reverified_and_its_edits_are_caught() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("a44.toml");
    std::fs::write(&cfg, config()).unwrap();
    let cfg = cfg.to_str().unwrap();
    let set = dir.path().join("set");
    let mut args = vec!["rtl", cfg, "--out", set.to_str().unwrap()];
    args.extend(SHORT);
    let o = tofprobe(&args);
    assert!(o.status.success(), "{}", text(&o));

    // As written: bit-exact, under Verilator's three power-up seeds; the JUnit report has
    // one passing case per frame.
    let junit = dir.path().join("array.xml");
    let (j, t) = cosim_rtl(
        cfg,
        &set,
        &dir.path().join("w0"),
        &["--junit", junit.to_str().unwrap()],
    );
    assert_eq!(j["pass"].as_bool(), Some(true), "{t}");
    assert_eq!(j["edited_rtl"].as_bool(), Some(true), "{t}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains("tests=\"2\"") && xml.contains("failures=\"0\"") && xml.contains("frame 1"),
        "{xml}"
    );

    // One ROM word changed: entry 3's case line flips its lowest bit.
    let rom = dir.path().join("rom-edit");
    edited(&set, &rom, "tofprobe_probe_rom.v", |v| {
        let line = v.lines().find(|l| l.contains("4'd3: word = ")).unwrap();
        let (head, hex) = line.rsplit_once('h').unwrap();
        let digits = hex.trim_end_matches(';');
        let last = u32::from_str_radix(&digits[digits.len() - 1..], 16).unwrap() ^ 1;
        let flipped = format!("{head}h{}{:x};", &digits[..digits.len() - 1], last);
        v.replacen(line, &flipped, 1)
    });
    let (j, t) = cosim_rtl(
        cfg,
        &rom,
        &dir.path().join("w1"),
        &["--junit", junit.to_str().unwrap()],
    );
    assert_eq!(j["pass"].as_bool(), Some(false), "{t}");
    let first = j["first_mismatch"].as_str().unwrap_or_default();
    assert!(
        first.contains("pixel (") && first.contains("cycle ") && first.contains("frame "),
        "{first}"
    );
    assert!(
        t.contains("changed since it was written: tofprobe_probe_rom.v"),
        "{t}"
    );
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains("failures=\"1\"") && xml.contains("first mismatch"),
        "{xml}"
    );

    // One readout bit inverted at the port: the first beat of the first pixel shows it.
    let port = dir.path().join("port-edit");
    edited(&set, &port, "tofprobe_array.v", |v| {
        v.replace(
            "if (beat) ro_data <= dx[dm * READOUT_BITS +: READOUT_BITS];",
            "if (beat) ro_data <= dx[dm * READOUT_BITS +: READOUT_BITS] ^ { {(READOUT_BITS - 1){1'b0}}, 1'b1 };",
        )
    });
    let (j, t) = cosim_rtl(cfg, &port, &dir.path().join("w2"), &[]);
    assert_eq!(j["pass"].as_bool(), Some(false), "{t}");
    let first = j["first_mismatch"].as_str().unwrap_or_default();
    assert!(
        first.starts_with("ro_data") && first.contains("pixel (0, 0)") && first.contains("frame 0"),
        "{first}"
    );
    assert_eq!(j["first_frame"].as_u64(), Some(0), "{t}");

    // A renamed port: refused naming it, before any build.
    let renamed = dir.path().join("port-renamed");
    edited(&set, &renamed, "tofprobe_array.v", |v| {
        v.replace("output wire ready,", "output wire all_ready,")
            .replace(
                "assign ready = &row_ready;",
                "assign all_ready = &row_ready;",
            )
    });
    let (_, t) = cosim_rtl(cfg, &renamed, &dir.path().join("w3"), &[]);
    assert!(t.contains("port `ready` is missing"), "{t}");

    // A missing file: the set is not whole, the file named.
    let torn = dir.path().join("torn");
    edited(&set, &torn, "tofprobe_sequencer.v", |v| format!("{v}\n"));
    std::fs::remove_file(torn.join("tofprobe_sequencer.v")).unwrap();
    let (_, t) = cosim_rtl(cfg, &torn, &dir.path().join("w4"), &[]);
    assert!(
        t.contains("tofprobe_sequencer.v") && t.contains("not a whole output set"),
        "{t}"
    );

    // An option the array cannot honour is refused by name, never ignored.
    let (_, t) = cosim_rtl(cfg, &set, &dir.path().join("w5"), &["--seed", "7"]);
    assert!(
        t.contains("--seed") && t.contains("[acquisition] seed"),
        "{t}"
    );
}
