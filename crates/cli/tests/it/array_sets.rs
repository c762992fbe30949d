//! Issue 45 through the binary: array and tile sets end with the project's completion
//! marker, so `check-set` passes them whole and names what a cut commit tore (item 5); a
//! set never replaces a file it did not write (item 6) and drops the files of the set it
//! replaces (item 7); `merge` refuses a tampered manifest before sizing anything (item 1),
//! and sets whose resolved designs (maps included) or files differ (item 4); a second
//! writer into a directory being written is refused naming the first (item 8). Tiny
//! arrays, 40,000 pulses: each run takes a few hundredths of a second.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use crate::bounds::{refused, run as bounded};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[track_caller]
fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Exit 2 with a message holding every one of `needles`; returns it.
#[track_caller]
fn fails(args: &[&str], needles: &[&str]) -> String {
    let o = run(args);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
    assert!(!t.contains("panicked"), "{t}");
    for n in needles {
        assert!(t.contains(n), "{args:?}: `{n}` not in: {t}");
    }
    t
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// scenes/plate-mode.toml at 4 × 3 pixels, 40,000 pulses, with `edits` applied.
pub(crate) fn plate(dir: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut t = include_str!("../../../../scenes/plate-mode.toml").to_string();
    for (a, b) in [
        ("pulses = 1000000", "pulses = 40000"),
        ("rows = 32", "rows = 4"),
        ("cols = 32", "cols = 3"),
        ("mm_per_pixel = 10.0", "mm_per_pixel = 80.0"),
    ]
    .iter()
    .chain(edits)
    {
        assert!(t.contains(a), "{a}");
        t = t.replacen(a, b, 1);
    }
    let p = dir.join(name);
    std::fs::write(&p, t).unwrap();
    p
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    v.sort();
    v
}

/// Item 5: whole array and tile sets pass `check-set`; a commit stopped after each of its
/// renames is either refused — naming the files the cut moved in beside the old set's —
/// or whole, never a torn set accepted.
#[test]
fn check_set_passes_whole_array_and_tile_sets_and_names_a_torn_one() {
    let tmp = tempfile::tempdir().unwrap();
    let a = plate(tmp.path(), "a.toml", &[]);
    let b = plate(tmp.path(), "b.toml", &[("seed = 1\n", "seed = 2\n")]);
    let out = tmp.path().join("out");
    ok(&["simulate", s(&a), "--out", s(&out)]);
    let line = ok(&["check-set", s(&out)]);
    assert!(line.contains("whole output set, 18 file(s)"), "{line}");
    let tile = tmp.path().join("tile");
    ok(&["simulate", s(&a), "--out", s(&tile), "--shard", "1/2"]);
    assert!(ok(&["check-set", s(&tile)]).contains("5 file(s)"));
    // 18 files, then the marker: 19 renames.
    let (mut refused_sets, mut whole) = (0, 0);
    for k in 1..=19 {
        ok(&["simulate", s(&a), "--out", s(&out)]);
        let o = bin()
            .args(["simulate", s(&b), "--out", s(&out)])
            .env("TOFPROBE_TEST_KILL_AFTER_RENAMES", k.to_string())
            .output()
            .unwrap();
        assert!(
            !o.status.success(),
            "k = {k}: the hook must stop the commit"
        );
        let c = run(&["check-set", s(&out)]);
        let t = text(&c);
        match c.status.code() {
            Some(0) => {
                // Whole: every file of run b (seed 2), as its summary says.
                let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
                assert!(k == 19, "k = {k}: whole before the marker's rename: {t}");
                assert!(
                    summary.contains("\"configuration\": \"b.toml\""),
                    "{summary}"
                );
                whole += 1;
            }
            Some(2) => {
                assert!(
                    t.contains("was cut short: moved in, beside what was there before:")
                        && t.contains("registers.npy")
                        && t.contains("still staged:"),
                    "k = {k}: {t}"
                );
                refused_sets += 1;
            }
            c => panic!("check-set exit {c:?}: {t}"),
        }
    }
    assert_eq!((refused_sets, whole), (18, 1));
    // The next run completes or discards the cut commit: whole again, nothing hidden left.
    ok(&["simulate", s(&a), "--out", s(&out)]);
    ok(&["check-set", s(&out)]);
    assert!(
        listing(&out).iter().all(|n| !n.starts_with('.')),
        "{:?}",
        listing(&out)
    );
}

/// Item 6: `simulate --out` and `merge --out` refuse a directory holding a file of the
/// user's under one of the set's names (before the model runs), naming it, and leave it
/// as it was; a file of the previous set is replaced, one the user edited since is not.
#[test]
fn array_sets_never_overwrite_a_users_file() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let data = tmp.path().join("data");
    std::fs::create_dir(&data).unwrap();
    for name in ["registers.npy", "summary.json"] {
        std::fs::write(data.join(name), b"the user's own\n").unwrap();
        let e = fails(
            &["simulate", s(&cfg), "--out", s(&data)],
            &[
                name,
                "is not a file of the tofprobe set",
                "nothing was run or written",
            ],
        );
        assert!(!e.contains("array model"), "{e}");
        assert_eq!(std::fs::read(data.join(name)).unwrap(), b"the user's own\n");
        std::fs::remove_file(data.join(name)).unwrap();
    }
    // A user's file of another name stays beside the set.
    std::fs::write(data.join("notes.txt"), b"mine").unwrap();
    ok(&["simulate", s(&cfg), "--out", s(&data)]);
    ok(&["simulate", s(&cfg), "--out", s(&data)]);
    assert_eq!(std::fs::read(data.join("notes.txt")).unwrap(), b"mine");
    // A generated file the user edited since is theirs now.
    let uff = data.join("vibration.uff");
    let edited = std::fs::read_to_string(&uff).unwrap() + "my note\n";
    std::fs::write(&uff, &edited).unwrap();
    fails(
        &["simulate", s(&cfg), "--out", s(&data)],
        &["vibration.uff", "changed since tofprobe wrote it"],
    );
    assert_eq!(std::fs::read_to_string(&uff).unwrap(), edited);
    // merge --out likewise, before any tile is read.
    let sets: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = tmp.path().join(format!("t{i}"));
            ok(&[
                "simulate",
                s(&cfg),
                "--out",
                s(&d),
                "--shard",
                &format!("{i}/2"),
            ]);
            d
        })
        .collect();
    let mine = tmp.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("detections.npy"), b"x").unwrap();
    fails(
        &["merge", s(&sets[0]), s(&sets[1]), "--out", s(&mine)],
        &["detections.npy is not a file of the tofprobe set"],
    );
    assert_eq!(listing(&mine), ["detections.npy"]);
    // A tile set into a directory with a user's manifest.json: refused too.
    let t = tmp.path().join("tuser");
    std::fs::create_dir(&t).unwrap();
    std::fs::write(t.join("manifest.json"), b"{}").unwrap();
    fails(
        &["simulate", s(&cfg), "--out", s(&t), "--shard", "0/2"],
        &["manifest.json is not a file of the tofprobe set"],
    );
}

/// Item 7: a Haar set written over a Fourier one, and B = 3 over B = 4, leave none of the
/// earlier set's files behind (only the files its marker lists, unchanged); the user's
/// file stays.
#[test]
fn a_new_array_set_drops_the_files_of_the_one_it_replaces() {
    let tmp = tempfile::tempdir().unwrap();
    let four = plate(tmp.path(), "four.toml", &[]);
    let three = plate(tmp.path(), "three.toml", &[("bins = 4 ", "bins = 3 ")]);
    let out = tmp.path().join("out");
    ok(&["simulate", s(&four), "--out", s(&out)]);
    assert!(out.join("amplitude_bin03.svg").exists());
    std::fs::write(out.join("notes.txt"), b"mine").unwrap();
    ok(&["simulate", s(&three), "--out", s(&out)]);
    let files = listing(&out);
    assert!(
        !files.iter().any(|f| f.contains("bin03")),
        "the fourth bin's maps stayed: {files:?}"
    );
    assert_eq!(files.len(), 2 + 2 + 2 + 2 * 3 + 3 + 2 + 1, "{files:?}");
    ok(&["check-set", s(&out)]);
    // Haar over Fourier: the 13 Fourier-only files go.
    let edge = include_str!("../../../../scenes/edge-sweep.toml")
        .replacen("rows = 32", "rows = 4", 1)
        .replacen("cols = 32", "cols = 3", 1)
        // 16384 pulses: 512 per cell, so a pixel's transition threshold (8 σ of a cell
        // mean, 8 × 10 codes/√512 ≈ 2.7 mm) is under the edge's 4 mm (at 4096 it is 5.3 mm
        // and no pixel would have a time); the edge crosses columns 0–2 at 0.15–0.35 ms of
        // the 1.6 ms frame.
        .replacen("pulses = 65536", "pulses = 16384", 1);
    let haar = tmp.path().join("edge.toml");
    std::fs::write(&haar, edge).unwrap();
    ok(&["simulate", s(&haar), "--out", s(&out)]);
    assert_eq!(
        listing(&out),
        [
            "detections.npy",
            "event_time.svg",
            "event_time_ms.npy",
            "event_time_sd_ms.npy",
            "level.npy",
            "level.svg",
            "notes.txt",
            "registers.npy",
            "summary.json",
            "tofprobe-set.toml"
        ]
    );
    ok(&["check-set", s(&out)]);
    // Each pixel's sd beside its time: the same [R, C], −1 exactly where the time is −1,
    // positive and finite elsewhere.
    let read =
        |n: &str| tofprobe_io::npy::from_bytes(&std::fs::read(out.join(n)).unwrap()).unwrap();
    let (t, sd) = (read("event_time_ms.npy"), read("event_time_sd_ms.npy"));
    assert_eq!(
        (t.shape.clone(), sd.shape.clone()),
        (vec![4, 3], vec![4, 3])
    );
    for (t, sd) in t.data.iter().zip(&sd.data) {
        assert!(
            if *t < 0.0 {
                *sd == -1.0
            } else {
                sd.is_finite() && *sd > 0.0
            },
            "time {t} ms, sd {sd} ms"
        );
    }
    assert!(t.data.iter().any(|&t| t >= 0.0), "{:?}", t.data);
}

/// Rewrites `dir/manifest.json` through `edit`.
fn edit_manifest(dir: &Path, edit: impl Fn(&mut serde_json::Value)) {
    let p = dir.join("manifest.json");
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    edit(&mut m);
    std::fs::write(&p, serde_json::to_vec(&m).unwrap()).unwrap();
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for n in listing(from) {
        std::fs::copy(from.join(&n), to.join(&n)).unwrap();
    }
}

/// Item 1: manifests claiming shapes that overflowed, wrapped or asked for 16 TiB are
/// refused at once, naming the set and the claim, under a 4 GiB address-space limit.
#[test]
fn merge_refuses_a_tampered_manifest_before_sizing_anything() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let sets: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = tmp.path().join(format!("s{i}"));
            ok(&[
                "simulate",
                s(&cfg),
                "--out",
                s(&d),
                "--shard",
                &format!("{i}/2"),
            ]);
            d
        })
        .collect();
    let bad = tmp.path().join("bad");
    let out = tmp.path().join("out");
    type Tamper = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Tamper, &[&str])> = vec![
        (
            "2^31 × 2^31",
            Box::new(|m| {
                m["array_rows"] = (1u64 << 31).into();
                m["array_cols"] = (1u64 << 31).into();
            }),
            &["claims a 2147483648 × 2147483648 array", "is 4 × 3"],
        ),
        (
            "2^33 × 2^31 (the product wraps)",
            Box::new(|m| {
                m["array_rows"] = (1u64 << 33).into();
                m["array_cols"] = (1u64 << 31).into();
            }),
            &["claims a 8589934592 × 2147483648 array"],
        ),
        (
            "2^20 × 2^20 in the design too (16 TiB)",
            Box::new(|m| {
                for k in ["array_rows", "array_cols"] {
                    m[k] = (1u64 << 20).into();
                }
                m["design"]["array"]["rows"] = (1u64 << 20).into();
                m["design"]["array"]["cols"] = (1u64 << 20).into();
            }),
            &["array.rows = 1048576", "allowed 1..=4096"],
        ),
        (
            "a tile outside the array",
            Box::new(|m| m["rows"] = serde_json::json!({"start": 2, "end": u64::MAX})),
            &["is not a non-empty part of the 4 × 3 array"],
        ),
        (
            "u64::MAX registers per pixel",
            Box::new(|m| m["registers_per_pixel"] = u64::MAX.into()),
            &["claims 18446744073709551615 registers per pixel"],
        ),
    ];
    for (what, edit, needles) in cases {
        let _ = std::fs::remove_dir_all(&bad);
        copy_dir(&sets[0], &bad);
        edit_manifest(&bad, edit);
        let r = bounded(
            &["merge", s(&bad), s(&sets[1]), "--out", s(&out)],
            Duration::from_secs(20),
        );
        let mut all = vec!["tile set", s(&bad)];
        all.extend(needles.iter().copied());
        refused(&r, &all);
        assert!(r.seconds < 5.0, "{what}: {} s", r.seconds);
        assert!(!out.exists(), "{what}: a refused merge wrote {out:?}");
    }
}

/// Item 4: the shards of a configuration whose rate-map image changed between them, and a
/// tile set whose registers or detections were edited, are refused naming the set (and
/// the file).
#[test]
fn merge_refuses_sets_of_another_design_or_with_edited_files() {
    let tmp = tempfile::tempdir().unwrap();
    let pgm = |v: u8| {
        let mut img = b"P5\n3 4\n255\n".to_vec();
        img.extend([v; 12]);
        std::fs::write(tmp.path().join("refl.pgm"), img).unwrap();
    };
    let cfg = plate(
        tmp.path(),
        "p.toml",
        &[(
            "mm_per_pixel = 80.0",
            "mm_per_pixel = 80.0\nsignal_map = { kind = \"image\", path = \"refl.pgm\", scale = 0.1 }",
        )],
    );
    pgm(200);
    let s0 = tmp.path().join("s0");
    ok(&["simulate", s(&cfg), "--out", s(&s0), "--shard", "0/2"]);
    pgm(100); // the image changes between the shards; the TOML does not
    let s1 = tmp.path().join("s1");
    ok(&["simulate", s(&cfg), "--out", s(&s1), "--shard", "1/2"]);
    let out = tmp.path().join("out");
    fails(
        &["merge", s(&s0), s(&s1), "--out", s(&out)],
        &["tile set", s(&s1), "a different design", "map image"],
    );
    pgm(200);
    let good = tmp.path().join("good");
    ok(&["simulate", s(&cfg), "--out", s(&good), "--shard", "1/2"]);
    ok(&["merge", s(&s0), s(&good), "--out", s(&out)]);
    // One register, one detection count changed in place: the marker's hash names them.
    for name in ["registers.npy", "detections.npy"] {
        let t = tmp.path().join(format!("edited-{name}"));
        copy_dir(&good, &t);
        let mut b = std::fs::read(t.join(name)).unwrap();
        let last = b.len() - 1;
        b[last - 7] ^= 1;
        std::fs::write(t.join(name), b).unwrap();
        fails(
            &["merge", s(&s0), s(&t), "--out", s(&tmp.path().join("o2"))],
            &["tile set", s(&t), name, "was changed"],
        );
    }
    // A map part edited and the marker rewritten to match: the joined maps no longer give
    // the design hash the manifests name.
    let t = tmp.path().join("remarked");
    copy_dir(&good, &t);
    let mut b = std::fs::read(t.join("signal_rate.npy")).unwrap();
    let last = b.len() - 2;
    b[last] ^= 1;
    std::fs::write(t.join("signal_rate.npy"), &b).unwrap();
    let marker = std::fs::read_to_string(t.join("tofprobe-set.toml")).unwrap();
    let old = marker
        .lines()
        .find(|l| l.starts_with("\"signal_rate.npy\""))
        .unwrap()
        .to_string();
    let new = format!(
        "\"signal_rate.npy\" = \"{:016x}\"",
        tofprobe_io::fnv1a64(&b)
    );
    std::fs::write(t.join("tofprobe-set.toml"), marker.replace(&old, &new)).unwrap();
    // The manifest carries each data file's hash as the shard wrote it.
    fails(
        &["merge", s(&s0), s(&t), "--out", s(&tmp.path().join("o3"))],
        &[
            "tile set",
            "signal_rate.npy is not the file its shard wrote",
            "run its shard again",
        ],
    );
    // The manifest's hash rewritten too (and the marker re-sealed over it): the joined maps
    // no longer give the design hash the manifests name.
    let mpath = t.join("manifest.json");
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(&mpath).unwrap()).unwrap();
    m["files"]["signal_rate.npy"] = format!("{:016x}", tofprobe_io::fnv1a64(&b)).into();
    let mtext = serde_json::to_vec_pretty(&m).unwrap();
    std::fs::write(&mpath, &mtext).unwrap();
    let marker = std::fs::read_to_string(t.join("tofprobe-set.toml")).unwrap();
    let old = marker
        .lines()
        .find(|l| l.starts_with("\"manifest.json\""))
        .unwrap()
        .to_string();
    let new = format!(
        "\"manifest.json\" = \"{:016x}\"",
        tofprobe_io::fnv1a64(&mtext)
    );
    std::fs::write(t.join("tofprobe-set.toml"), marker.replace(&old, &new)).unwrap();
    fails(
        &["merge", s(&s0), s(&t), "--out", s(&tmp.path().join("o4"))],
        &[
            "tile set",
            "join into a design of hash",
            "a map file was changed",
        ],
    );
}
