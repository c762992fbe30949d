//! Issue 45 items 9–12 through the binary: refusals blame the option, key or set at
//! fault (item 9); numbers out of range are refused, printed readably (item 10); output
//! that cannot be written is refused before any work (item 11); a set's bytes do not
//! depend on where the configuration lies, and a full standard output is an error that
//! says which set was written (item 12). Every run is bounded (time, 4 GiB).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::array_sets::plate;
use crate::bounds::{refused, run};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const T: Duration = Duration::from_secs(30);

/// No number in `text` is printed as a long decimal (a 1e-300 once printed 300 digits).
#[track_caller]
fn readable(text: &str) {
    assert!(!text.contains("0000000000"), "a long decimal in: {text}");
}

#[test]
fn refusals_name_the_option_the_key_and_the_set() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let out = tmp.path().join("out");
    // More shards than pixels: the option, not a non-existent --array.
    let r = run(
        &["simulate", s(&cfg), "--out", s(&out), "--shard", "0/20"],
        T,
    );
    refused(&r, &["--shard = 0/20", "n ≤ 12", "4 × 3 array"]);
    assert!(!r.stderr.contains("--array"), "{}", r.stderr);
    // A directory that is no tile set: named.
    let r = run(&["merge", s(tmp.path()), "--out", s(&out)], T);
    refused(&r, &["merge: tile set", s(tmp.path())]);
    // A type error inside a rate map's table names the key inside it.
    let bad = plate(
        tmp.path(),
        "bad.toml",
        &[(
            "mm_per_pixel = 80.0",
            "mm_per_pixel = 80.0\nsignal_map = { kind = \"constant\", value = \"x\" }",
        )],
    );
    let r = run(&["config", s(&bad)], T);
    refused(
        &r,
        &["`array.signal_map.value` = \"x\" has the wrong type: expected a number"],
    );
    // A 10-byte version-2 .npy map is cut short, not of an unknown version.
    std::fs::write(tmp.path().join("m.npy"), b"\x93NUMPY\x02\x00\x10\x00").unwrap();
    let npy = plate(
        tmp.path(),
        "npy.toml",
        &[(
            "mm_per_pixel = 80.0",
            "mm_per_pixel = 80.0\nsignal_map = { kind = \"image\", path = \"m.npy\" }",
        )],
    );
    let r = run(&["config", s(&npy)], T);
    refused(
        &r,
        &[
            "array.signal_map.path = \"m.npy\"",
            "version 2",
            "cut short",
        ],
    );
    assert!(!r.stderr.contains("is not one of 1, 2, 3"), "{}", r.stderr);
}

#[test]
fn numbers_out_of_range_are_refused_and_printed_readably() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: Vec<(&str, (&str, String), Vec<&str>)> = vec![
        (
            "a 5e-324 bits/s link",
            (
                "mm_per_pixel = 80.0",
                "mm_per_pixel = 80.0\nreadout_bits_per_s = 5e-324".into(),
            ),
            vec!["array.readout_bits_per_s = 5e-324", "2^40 cycles"],
        ),
        (
            "a field of view giving 7.6e13 mm per pixel",
            (
                "mm_per_pixel = 80.0",
                "field_of_view_deg = 179.99999\ndistance_mm = 1e7".into(),
            ),
            vec![
                "array.field_of_view_deg = 179.99999",
                "mm per pixel",
                "narrower",
            ],
        ),
        (
            "a field of view giving 0 mm per pixel",
            (
                "mm_per_pixel = 80.0",
                "field_of_view_deg = 1e-300\ndistance_mm = 1.0".into(),
            ),
            vec!["array.field_of_view_deg = 1e-300", "mm per pixel", "wider"],
        ),
        (
            "a pitch of 1e-300 µm",
            ("pitch_um = 30.0", "pitch_um = 1e-300".into()),
            vec!["array.pitch_um = 1e-300", "0.001 <= pitch_um"],
        ),
        (
            "a map path of 4 kB",
            (
                "mm_per_pixel = 80.0",
                format!(
                    "mm_per_pixel = 80.0\nsignal_map = {{ kind = \"image\", path = \"{}\" }}",
                    "d/".repeat(2048)
                ),
            ),
            vec!["array.signal_map.path", "..."],
        ),
    ];
    for (what, (from, to), needles) in cases {
        let cfg = plate(tmp.path(), "c.toml", &[(from, to.as_str())]);
        let r = run(&["config", s(&cfg)], T);
        refused(&r, &needles);
        readable(&r.stderr);
        assert!(
            r.stderr.len() < 1200,
            "{what}: {} bytes of message",
            r.stderr.len()
        );
    }
    // size --utilisation: bounded, readable, and refused (not ignored) on a single pixel;
    // no tool runs before the refusal (an empty PATH).
    let cfg = plate(tmp.path(), "p.toml", &[]);
    for (args, needles) in [
        (
            vec!["size", s(&cfg), "--utilisation", "1e-300"],
            vec!["--utilisation = 1e-300", "0.05 ≤ utilisation ≤ 1"],
        ),
        (
            vec!["size", "--utilisation", "0.5"],
            vec!["--utilisation = 0.5", "[array] configuration only"],
        ),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(&args)
            .env("PATH", "")
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        for n in needles {
            assert!(e.contains(n), "{args:?}: `{n}` not in {e}");
        }
        readable(&e);
    }
}

#[test]
fn output_that_cannot_be_written_is_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    std::fs::write(&file, b"not a directory").unwrap();
    let out = file.join("out");
    // ≈ 2 s of model: refused in well under that.
    let big = plate(
        tmp.path(),
        "big.toml",
        &[
            ("rows = 4", "rows = 96"),
            ("cols = 3", "cols = 96"),
            ("mm_per_pixel = 80.0", "mm_per_pixel = 4.0"),
        ],
    );
    let r = run(&["simulate", s(&big), "--out", s(&out)], T);
    refused(&r, &["cannot write", s(&out)]);
    assert!(
        r.seconds < 1.0,
        "simulate --out ran {} s before refusing",
        r.seconds
    );
    // merge: before any tile is read.
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let sets: Vec<String> = (0..2)
        .map(|i| {
            let d = tmp.path().join(format!("t{i}"));
            let r = run(
                &[
                    "simulate",
                    s(&cfg),
                    "--out",
                    s(&d),
                    "--shard",
                    &format!("{i}/2"),
                ],
                T,
            );
            assert_eq!(r.code, Some(0), "{}", r.stderr);
            s(&d).to_string()
        })
        .collect();
    let r = run(&["merge", &sets[0], &sets[1], "--out", s(&out)], T);
    refused(&r, &["cannot write", s(&out)]);
    // layout: before synthesis, placement and routing (no tool is on the PATH here: the
    // refusal must be the output's, not a missing tool's).
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["layout", "--out", s(&out)])
        .env("PATH", "")
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("cannot write") && e.contains(s(&out)), "{e}");
    // A manifest of 33 MiB is refused by its size, not read into memory.
    let t = Path::new(&sets[1]);
    std::fs::write(t.join("manifest.json"), vec![b' '; 33 << 20]).unwrap();
    let r = run(
        &[
            "merge",
            &sets[0],
            &sets[1],
            "--out",
            s(&tmp.path().join("m")),
        ],
        T,
    );
    refused(
        &r,
        &["tile set", "manifest.json has 34603008 bytes", "at most"],
    );
}

#[test]
fn sets_do_not_depend_on_the_configurations_place_and_stdout_is_checked() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let bin = || {
        let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
        c.current_dir(tmp.path());
        c
    };
    let o = bin()
        .args(["simulate", "p.toml", "--out", "rel"])
        .output()
        .unwrap();
    assert!(o.status.success());
    let o = bin()
        .args(["simulate", s(&cfg), "--out", "abs"])
        .output()
        .unwrap();
    assert!(o.status.success());
    for f in [
        "summary.json",
        "vibration.uff",
        "registers.npy",
        "deflection.svg",
    ] {
        let (a, b) = (
            std::fs::read(tmp.path().join("rel").join(f)).unwrap(),
            std::fs::read(tmp.path().join("abs").join(f)).unwrap(),
        );
        if f == "summary.json" {
            let strip = |b: &[u8]| {
                let mut v: serde_json::Value = serde_json::from_slice(b).unwrap();
                let o = v.as_object_mut().unwrap();
                o.remove("model_seconds");
                o.remove("pixel_pulses_per_s");
                v
            };
            assert_eq!(strip(&a), strip(&b));
        } else {
            assert!(a == b, "{f} depends on the configuration's path");
        }
        let machine = tmp.path().to_string_lossy().into_owned();
        assert!(
            !String::from_utf8_lossy(&b).contains(&machine),
            "{f} holds {machine}"
        );
    }
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("skipped: no /dev/full");
        return;
    };
    // --help and --version into a full disk: an error, not a silent 0.
    for flag in ["--help", "--version"] {
        let o = bin()
            .arg(flag)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag}: {e}");
        assert!(e.contains("cannot write to standard output"), "{e}");
    }
    // A set committed, then its summary fails to print: exit 2, naming the set written
    // whole (check-set passes it).
    let o = bin()
        .args(["simulate", "p.toml", "--out", "full-stdout"])
        .stdout(full)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("cannot write to standard output")
            && e.contains("full-stdout was written whole"),
        "{e}"
    );
    let o = bin().args(["check-set", "full-stdout"]).output().unwrap();
    assert!(o.status.success());
}
