//! Issue 31, items 3 and 4, through the binary: a refusal names the key the user wrote with
//! the type the schema gives it (string keys as strings or names, choices as an integer
//! or "auto"), a valid key is never blamed for a wrong one elsewhere, a frame longer than
//! the acquisition is refused, and a megabyte value is echoed clipped.

use std::time::Duration;

use crate::bounds::{clip, refused, run, s, scratch, write};
use crate::common::{default_text, edit};

/// A case: its name, the edits of the default, the message it must print.
type Case<'a> = (&'a str, &'a [(&'a str, &'a str)], &'a str);

/// Runs `config` on the default with `edits`; the refusal's stderr.
fn config_error(name: &str, edits: &[(&str, &str)]) -> String {
    let d = scratch(&format!("blame-{name}"));
    let cfg = write(&d, "c.toml", &edit(default_text(), edits));
    let r = run(&["config", s(&cfg)], Duration::from_secs(20));
    assert_eq!(r.code, Some(2), "{name}: {}", clip(&r.stderr));
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    r.stderr
}

/// `jitter_ps = "50"` beside a valid `adders = "auto"` blames `sensor.jitter_ps` (it blamed
/// `pixel.adders`, "expected an integer >= 0": 412 fuzz runs in 103 cases), and each string
/// key is reported with its real type.
#[test]
fn a_wrong_type_is_blamed_on_its_key_with_the_schemas_type() {
    let cases: [Case; 6] = [
        (
            "jitter",
            &[
                ("jitter_ps = 50.0 ", "jitter_ps = \"50\" "),
                ("adders = 2 ", "adders = \"auto\" "),
            ],
            "`sensor.jitter_ps` = \"50\" has the wrong type: expected a number",
        ),
        (
            "register-file",
            &[("adders = 2 ", "adders = 2\nregister_file = 3 ")],
            "`pixel.register_file` = 3 has the wrong type: expected one of `flops`, `clock_gated`, `latch`",
        ),
        (
            "register-file-name",
            &[("adders = 2 ", "adders = 2\nregister_file = \"latches\" ")],
            "`pixel.register_file` = \"latches\" is not accepted: unknown variant `latches`, expected one of `flops`, `clock_gated`, `latch`",
        ),
        (
            "rounding",
            &[("adders = 2 ", "adders = 2\nprefilter_rounding = true ")],
            "`pixel.prefilter_rounding` = true has the wrong type: expected one of `floor` or `nearest`",
        ),
        (
            "liberty",
            &[("adders = 2 ", "adders = \"auto\"\ntiming_liberty = 130 ")],
            "`pixel.timing_liberty` = 130 has the wrong type: expected a string",
        ),
        (
            "adders",
            &[("adders = 2 ", "adders = \"AUTO\" ")],
            "`pixel.adders` = \"AUTO\" has the wrong type: expected an integer >= 0 or \"auto\"",
        ),
    ];
    for (name, edits, want) in cases {
        let e = config_error(name, edits);
        assert!(e.contains(want), "{name}: want {want}\n got {e}");
    }
    // The message keeps where the parser stopped: the line of `jitter_ps`.
    let line = default_text()
        .lines()
        .position(|l| l.starts_with("jitter_ps"))
        .expect("jitter_ps")
        + 1;
    let e = config_error(
        "jitter-line",
        &[("jitter_ps = 50.0 ", "jitter_ps = \"50\" ")],
    );
    assert!(
        e.contains(&format!(
            "(at line {line}, column 13: invalid type: string \"50\""
        )),
        "{e}"
    );
    // Several string keys right, one number wrong: only the number is named.
    let e = config_error(
        "mixed",
        &[
            (
                "adders = 2 ",
                "adders = \"auto\"\nregister_file = \"clock_gated\"\nprefilter_rounding = \"nearest\"\ntiming_liberty = \"sky130\" ",
            ),
            ("signal_rate = 1.0 ", "signal_rate = \"1\" "),
        ],
    );
    assert!(e.contains("`sensor.signal_rate` = \"1\""), "{e}");
    for k in [
        "adders",
        "register_file",
        "prefilter_rounding",
        "timing_liberty",
    ] {
        assert!(!e.contains(k), "{k} blamed: {e}");
    }
}

/// `pixel.frame_pulses` longer than the acquisition was accepted silently; it is refused
/// naming the key, the acquisition's N and the value that works, by `config` and
/// `simulate` alike. Equal to N it resolves.
#[test]
fn a_frame_longer_than_the_acquisition_is_refused() {
    let d = scratch("frame-longer");
    let text = |frame: u64| {
        edit(
            default_text(),
            &[
                ("duration_s = 1.0 ", "pulses = 20000 "),
                (
                    "adders = 2 ",
                    &format!("adders = 2\nframe_pulses = {frame} "),
                ),
            ],
        )
    };
    let cfg = write(&d, "long.toml", &text(40_000));
    for cmd in ["config", "simulate"] {
        let r = run(&[cmd, s(&cfg)], Duration::from_secs(20));
        refused(
            &r,
            &[
                "pixel.frame_pulses = 40000",
                "at most the acquisition's 20000 pulses",
                "nearest valid value: 20000",
            ],
        );
    }
    let cfg = write(&d, "equal.toml", &text(20_000));
    let r = run(&["config", s(&cfg)], Duration::from_secs(20));
    assert_eq!(r.code, Some(0), "{}", clip(&r.stderr));
}

/// A 1 MB `timing_liberty` value is echoed clipped (it came back twice, in a 2 MB
/// message): the refusal names the key and stays under 2 kB.
#[test]
fn a_megabyte_timing_liberty_is_echoed_clipped() {
    let d = scratch("liberty-long");
    let long = "x".repeat(1 << 20);
    let cfg = write(
        &d,
        "long.toml",
        &edit(
            default_text(),
            &[(
                "adders = 2 ",
                &format!("adders = \"auto\"\ntiming_liberty = \"{long}\" "),
            )],
        ),
    );
    let r = run(
        &["config", "--time-adders", s(&cfg)],
        Duration::from_secs(20),
    );
    refused(&r, &["pixel.timing_liberty = \"xxx", "...\""]);
    assert!(r.stderr.len() < 2000, "{} bytes", r.stderr.len());
}
