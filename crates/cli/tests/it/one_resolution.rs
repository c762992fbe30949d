//! Issue 31, item 4 through the binary: the commands agree on what they accept, and a
//! refusal names the key the user wrote.
//! - A Haar scene without detections was accepted by `config`, `rtl` and `vectors` and
//!   refused by `simulate` naming no key (so was one without jitter): now every command
//!   refuses both at resolution naming the `sensor` keys.
//! - A `[probe]` section in Haar mode was refused (checked against the frame) though the
//!   README says it is ignored: now every command accepts it, ignores it (the RTL is byte
//!   for byte the one without it) and warns on stderr naming `probe` and `pixel.mode`.
//! - `timing_liberty` beside an explicit `adders` was ignored silently: refused naming both.
//! - `size --options` / `flow --recommended` on a Haar design ran for minutes and blamed an
//!   `--option` never given: refused at once naming `pixel.mode`.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

use common::{default_text, edit};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-one-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn run(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run tofprobe")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The paper's Fig. 12 scene cut to a 4096-pulse Haar frame (U = 4), with `edits`.
fn haar(edits: &[(&str, &str)]) -> String {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/fig12-step.toml");
    let mut e = vec![
        ("pulses = 524288 ", "pulses = 4096 "),
        ("haar_scales = 6 ", "haar_scales = 4 "),
    ];
    e.extend_from_slice(edits);
    edit(std::fs::read_to_string(scene).expect("fig12 scene"), &e)
}

/// Every command, from `dir` on `c.toml`; rtl and vectors into `out-rtl`, `out-vectors`.
const COMMANDS: [&[&str]; 4] = [
    &["config", "c.toml"],
    &["simulate", "c.toml"],
    &["rtl", "c.toml", "--out", "out-rtl"],
    &["vectors", "c.toml", "--out", "out-vectors"],
];

#[test]
fn a_haar_scene_without_detections_is_refused_by_every_command_naming_the_key() {
    for (name, edits, key) in [
        (
            "no-rates",
            &[("signal_rate = 1.0", "signal_rate = 0.0")][..],
            "signal_rate + background_rate = 0",
        ),
        // No jitter: a static depth gives one code, no noise to judge against.
        (
            "no-jitter",
            &[("jitter_ps = 20.0", "jitter_ps = 0.0")][..],
            "sensor.jitter_ps = 0",
        ),
    ] {
        let d = scratch(name);
        std::fs::write(d.join("c.toml"), haar(edits)).unwrap();
        for args in COMMANDS {
            let o = run(&d, args);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{name} {args:?}: {e}");
            assert!(
                e.contains("Haar mode judges its coefficients against the noise")
                    && e.contains("sensor.signal_rate")
                    && e.contains(key),
                "{name} {args:?}: {e}"
            );
        }
        assert!(!d.join("out-rtl").exists() && !d.join("out-vectors").exists());
        let _ = std::fs::remove_dir_all(&d);
    }
}

#[test]
fn a_probe_section_in_haar_mode_is_ignored_with_a_warning_everywhere() {
    let with = scratch("probe-with");
    let without = scratch("probe-without");
    // A periodic ROM of 20,000 entries does not divide N = 4096: checked against the frame,
    // as it used to be, it was refused.
    let probe = "\n[probe]\nrom_mode = \"periodic\"\nrom_depth = 20000\nosr = 16.0\n";
    std::fs::write(with.join("c.toml"), haar(&[]) + probe).unwrap();
    std::fs::write(without.join("c.toml"), haar(&[])).unwrap();
    for args in COMMANDS {
        let o = run(&with, args);
        let e = stderr(&o);
        assert!(o.status.success(), "{args:?}: {e}");
        assert!(
            e.contains("warning: c.toml: [probe] is set but pixel.mode is Haar")
                && e.contains("the probe section is ignored"),
            "{args:?}: {e}"
        );
        let o = run(&without, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    }
    // Ignored means ignored: the same RTL and vectors, byte for byte.
    for set in ["out-rtl", "out-vectors"] {
        let names = common::listing(&with.join(set));
        assert_eq!(names, common::listing(&without.join(set)));
        for n in names {
            assert!(
                std::fs::read(with.join(set).join(&n)).unwrap()
                    == std::fs::read(without.join(set).join(&n)).unwrap(),
                "{set}/{n} differs with [probe]"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&with);
    let _ = std::fs::remove_dir_all(&without);
}

#[test]
fn timing_liberty_beside_an_explicit_adders_is_refused_naming_both() {
    let d = scratch("liberty");
    let text = edit(
        default_text(),
        &[("adders = 2 ", "adders = 2\ntiming_liberty = \"sky130\" ")],
    );
    std::fs::write(d.join("c.toml"), text).unwrap();
    for args in [&["config", "c.toml"][..], &["rtl", "c.toml", "--out", "r"]] {
        let o = run(&d, args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(
            e.contains("pixel.timing_liberty = \"sky130\"")
                && e.contains("pixel.adders = 2 is explicit")
                && e.contains("set pixel.adders = \"auto\""),
            "{e}"
        );
    }
    // With "auto" the key is read (config without --time-adders runs no tool).
    let auto = edit(
        default_text(),
        &[(
            "adders = 2 ",
            "adders = \"auto\"\ntiming_liberty = \"sky130\" ",
        )],
    );
    std::fs::write(d.join("c.toml"), auto).unwrap();
    let o = run(&d, &["config", "c.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_options_study_refuses_a_haar_design_naming_pixel_mode() {
    let d = scratch("options");
    std::fs::write(d.join("c.toml"), haar(&[])).unwrap();
    for args in [
        &["size", "c.toml", "--options"][..],
        &["flow", "c.toml", "--recommended", "--out", "f"],
    ] {
        let t0 = Instant::now();
        let o = run(&d, args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains("pixel.mode = \"haar\"") && e.contains("Fourier"),
            "{args:?}: {e}"
        );
        assert!(!e.contains("--option "), "{args:?} blames an option: {e}");
        assert!(
            t0.elapsed().as_secs_f64() < 5.0,
            "{args:?}: {:?}",
            t0.elapsed()
        );
    }
    assert!(!d.join("f").exists());
    let _ = std::fs::remove_dir_all(&d);
}
