//! Batch farms without Python, through the binary: `simulate --shard i/n` tile sets joined
//! by `merge` give the very set `simulate --out` writes (byte for byte, summary.json up to
//! its timing), `merge` refuses sets of other configurations or seeds, overlapping tiles
//! and missing ones, naming the set (exit 2, nothing written), and `cosim --random N
//! --shard i/n` runs exactly the configurations of the unsharded soak.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// Exit 2 with `error: merge: tile set …` naming `set`; returns the message.
fn refused(args: &[&str], set: &str) -> String {
    let o = run(args);
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(
        e.contains(&format!("tile set {set}")),
        "{args:?} should name {set}: {e}"
    );
    e
}

/// scenes/plate-mode.toml at 4 × 3 pixels, 40 000 pulses, `seed`.
fn config(dir: &Path, name: &str, seed: u64, amplitude: &str) -> PathBuf {
    let text = include_str!("../../../../scenes/plate-mode.toml");
    let mut t = text.to_string();
    for (a, b) in [
        ("pulses = 1000000", "pulses = 40000".to_string()),
        ("rows = 32", "rows = 4".into()),
        ("cols = 32", "cols = 3".into()),
        ("mm_per_pixel = 10.0", "mm_per_pixel = 80.0".into()),
        ("seed = 1\n", format!("seed = {seed}\n")),
        ("amplitude_mm = 0.5", format!("amplitude_mm = {amplitude}")),
    ] {
        assert!(t.contains(a), "{a}");
        t = t.replacen(a, &b, 1);
    }
    let p = dir.join(name);
    std::fs::write(&p, t).unwrap();
    p
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn shards_merge_into_the_single_runs_set_and_bad_sets_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = config(tmp.path(), "plate.toml", 1, "0.5");
    let whole = tmp.path().join("whole");
    ok(&["simulate", s(&cfg), "--out", s(&whole)]);
    let n = 5;
    let sets: Vec<PathBuf> = (0..n)
        .map(|i| {
            let d = tmp.path().join(format!("set{i}"));
            let line = ok(&[
                "simulate",
                s(&cfg),
                "--out",
                s(&d),
                "--shard",
                &format!("{i}/{n}"),
            ]);
            assert!(line.contains(&format!("shard {i}/{n}")), "{line}");
            assert!(d.join("manifest.json").is_file() && d.join("registers.npy").is_file());
            d
        })
        .collect();
    let set = |i: usize| s(&sets[i]).to_string();
    let merged = tmp.path().join("merged");
    let mut args = vec!["merge".to_string()];
    args.extend((0..n).rev().map(set));
    args.extend(["--out".into(), s(&merged).into()]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = ok(&a);
    assert!(
        out.contains("output set") && out.contains("merged"),
        "{out}"
    );
    let (got, want) = (files(&merged), files(&whole));
    assert_eq!(
        got.iter().map(|f| &f.0).collect::<Vec<_>>(),
        want.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for ((name, g), (_, w)) in got.iter().zip(&want) {
        if name == "tofprobe-set.toml" {
            // The same files and hashes but the summary's (its timing).
            let listed = |b: &[u8]| {
                let mut f =
                    tofprobe_io::marker::marker_files(std::str::from_utf8(b).unwrap()).unwrap();
                f.remove("summary.json").unwrap();
                f
            };
            assert_eq!(listed(g), listed(w));
        } else if name == "summary.json" {
            let strip = |b: &[u8]| {
                let mut v: serde_json::Value = serde_json::from_slice(b).unwrap();
                let o = v.as_object_mut().unwrap();
                o.remove("model_seconds").unwrap();
                o.remove("pixel_pulses_per_s").unwrap();
                v
            };
            assert_eq!(strip(g), strip(w));
        } else {
            assert!(g == w, "{name} differs from the single run's");
        }
    }

    let out2 = tmp.path().join("out2");
    let o2 = s(&out2).to_string();
    // Another seed, another configuration: named.
    let seed2 = config(tmp.path(), "seed2.toml", 2, "0.5");
    let s2 = tmp.path().join("seed2set");
    ok(&["simulate", s(&seed2), "--out", s(&s2), "--shard", "1/5"]);
    let e = refused(
        &[
            "merge",
            &set(0),
            s(&s2),
            &set(2),
            &set(3),
            &set(4),
            "--out",
            &o2,
        ],
        s(&s2),
    );
    assert!(e.contains("seed 2"), "{e}");
    let other = config(tmp.path(), "other.toml", 1, "0.25");
    let os = tmp.path().join("otherset");
    ok(&["simulate", s(&other), "--out", s(&os), "--shard", "1/5"]);
    let e = refused(
        &[
            "merge",
            &set(0),
            s(&os),
            &set(2),
            &set(3),
            &set(4),
            "--out",
            &o2,
        ],
        s(&os),
    );
    assert!(e.contains("different design"), "{e}");
    // Overlapping and missing tiles.
    let e = refused(
        &[
            "merge",
            &set(0),
            &set(1),
            &set(1),
            &set(2),
            &set(3),
            &set(4),
            "--out",
            &o2,
        ],
        &set(1),
    );
    assert!(e.contains("overlaps"), "{e}");
    let e = refused(
        &["merge", &set(0), &set(1), &set(3), &set(4), "--out", &o2],
        &set(0),
    );
    assert!(
        e.contains("uncovered") && e.contains("missing shard(s): 2/5"),
        "{e}"
    );
    assert!(!out2.exists(), "a refused merge writes nothing");
    // --shard checks its value, and needs an array and --out.
    let o = run(&["simulate", s(&cfg), "--out", s(&out2), "--shard", "5/5"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        e.contains("--shard") && e.contains("0 ≤ i < n") && e.contains("5/5"),
        "{e}"
    );
    let o = run(&["simulate", "--out", s(&out2), "--shard", "0/2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("[array]"));
    assert_eq!(
        run(&["simulate", s(&cfg), "--shard", "0/2"]).status.code(),
        Some(2)
    );
}

#[test]
fn cosim_shards_cover_exactly_the_soaks_configurations() {
    if !tofprobe_testkit::tools::have(&["verilator"], "cosim --random --shard") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let lines = |extra: &[&str]| -> Vec<serde_json::Value> {
        let out = tmp.path().join("co");
        let mut a = vec![
            "cosim",
            "--random",
            "2",
            "--seed",
            "5",
            "--json",
            "--out",
            s(&out),
        ];
        a.extend(extra);
        ok(&a)
            .lines()
            .filter(|l| l.starts_with('{'))
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let whole = lines(&[]);
    assert_eq!(whole.len(), 2);
    let mut union = Vec::new();
    for i in 0..2 {
        union.extend(lines(&["--shard", &format!("{i}/2")]));
    }
    assert_eq!(
        union, whole,
        "the shards' configurations, in order, are the soak's"
    );
    let o = run(&["cosim", "--random", "2", "--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--shard"));
}
