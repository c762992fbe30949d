//! The array surface soaked through the binary (issue 45's "done when"; the figures and the
//! command are in docs/reliability.md). Each seeded case draws an array configuration —
//! Fourier or Haar, 1..=12 SPAD rows and columns in superpixels of G = 1..=3, single or double
//! buffered, ρ_s and ρ_b from the extremes, and one case in six an out-of-range array key —
//! and runs it as a user would:
//! - `simulate --out` (refusals: exit 2 naming the key, nothing written); an accepted run's
//!   peak resident memory (GNU time) stays under the bytes the resolution states for it
//!   (`SensorArray::bytes_needed`) and the set passes `check-set`;
//! - a second run into the same directory killed after a random rename of its commit
//!   (`TOFPROBE_TEST_KILL_AFTER_RENAMES`): `check-set` passes only if the set is whole (the
//!   killed run's own, after its marker's rename), else refuses it as cut short; the next
//!   run makes it whole again;
//! - the same configuration in 2..=4 shards (at most one a pixel), merged: byte-identical to
//!   the whole run;
//! - a user's file beside the set is never touched.
//!
//! `TOFPROBE_ARRAY_SOAK=N` runs N cases (default 3, ≈ 10 runs each, a few seconds).

use std::path::{Path, PathBuf};
use std::process::Command;

use tofprobe_design::array::SensorArray;
use tofprobe_testkit::params::Rng;

use crate::bounds::clip;

fn cases() -> usize {
    std::env::var("TOFPROBE_ARRAY_SOAK")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3)
}

/// One drawn configuration: its text, registers and bins per pixel, SPADs per pixel, and the
/// key that makes it out of range (`None`: valid).
struct Drawn {
    text: String,
    rows: u64,
    cols: u64,
    registers: u64,
    bins: u64,
    spads: u64,
    bad_key: Option<&'static str>,
    what: String,
}

fn replace(mut t: String, edits: &[(&str, String)]) -> String {
    for (a, b) in edits {
        assert!(t.contains(a), "{a}");
        t = t.replacen(a, b, 1);
    }
    t
}

/// Values no array key accepts, by key: (key, line prefix in the scene, bad value).
const BAD: &[(&str, &str, &str)] = &[
    ("array.rows", "rows = ", "0"),
    ("array.rows", "rows = ", "4097"),
    ("array.cols", "cols = ", "2147483648"),
    ("array.cols", "cols = ", "-1"),
    ("array.cols", "cols = ", "\"x\""),
    ("array.pitch_um", "pitch_um = ", "0.0"),
    ("array.pitch_um", "pitch_um = ", "nan"),
    ("array.superpixel", "superpixel = ", "0"),
    ("array.superpixel", "superpixel = ", "4096"),
];

fn draw(rng: &mut Rng) -> Drawn {
    // Rows and columns count SPADs: a whole number of G × G superpixels.
    let g = 1 + rng.below(3);
    let rows = g * (1 + rng.below(12 / g));
    let cols = g * (1 + rng.below(12 / g));
    let dbuf = rng.chance(50);
    let rho_s = *rng.pick(&["1.0", "0.3", "0.03"]);
    let rho_b = *rng.pick(&["0.0", "0.3"]);
    let seed = 1 + rng.below(1 << 40);
    let haar = rng.chance(40);
    let array_tail = format!("superpixel = {g}\ndouble_buffer = {dbuf}\n");
    let (mut text, registers, bins) = if haar {
        let t = replace(
            include_str!("../../../../scenes/edge-sweep.toml").to_string(),
            &[
                ("rows = 32", format!("rows = {rows}")),
                ("cols = 32", format!("cols = {cols}")),
                ("pulses = 65536", "pulses = 1024".into()),
            ],
        );
        (t, 31, 0)
    } else {
        let t = replace(
            include_str!("../../../../scenes/plate-mode.toml").to_string(),
            &[
                ("rows = 32", format!("rows = {rows}")),
                ("cols = 32", format!("cols = {cols}")),
                ("pulses = 1000000", "pulses = 20000".into()),
                (
                    "mm_per_pixel = 10.0",
                    format!("mm_per_pixel = {}.0", 320 / cols),
                ),
                // Double-buffered, the swap edge must follow the last register write.
                (
                    "cycles_per_pulse = 4",
                    format!("cycles_per_pulse = {}", if dbuf { 5 } else { 4 }),
                ),
            ],
        );
        (t, 8, 4)
    };
    text = replace(
        text,
        &[
            ("signal_rate = 1.0", format!("signal_rate = {rho_s}")),
            (
                "background_rate = 0.0",
                format!("background_rate = {rho_b}"),
            ),
            ("seed = 1", format!("seed = {seed}")),
        ],
    );
    text.push_str(&array_tail);
    let mut bad_key = None;
    let mut what = format!(
        "{} {rows} x {cols}, G = {g}, double buffer {dbuf}, rho_s {rho_s}, rho_b {rho_b}, seed {seed}",
        if haar { "haar" } else { "fourier" }
    );
    if rng.chance(17) {
        let (key, prefix, value) = *rng.pick(BAD);
        // The array table's line of that key (the scene's last table): replaced there only.
        let at = text.rfind("[array]").unwrap();
        let (head, tail) = text.split_at(at);
        let start = tail.find(&format!("\n{prefix}")).map(|i| i + 1).unwrap();
        let end = start + tail[start..].find('\n').unwrap();
        text = format!("{head}{}{prefix}{value}{}", &tail[..start], &tail[end..]);
        bad_key = Some(key);
        what.push_str(&format!(", {key} = {value}"));
    }
    Drawn {
        text,
        rows,
        cols,
        registers,
        bins,
        spads: g * g,
        bad_key,
        what,
    }
}

/// Runs the binary with `args` under GNU time and a time limit: exit code (`None`: killed
/// by a signal), stderr, peak resident bytes. A run past the limit is killed by `timeout`
/// (exit 124).
fn measured(args: &[&str], env: Option<(&str, String)>) -> (Option<i32>, String, u64) {
    let mut cmd = Command::new("timeout");
    cmd.args(["120", "/usr/bin/time", "-f", "peak-kb %M"])
        .arg(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args);
    if let Some((k, v)) = env {
        cmd.env(k, v);
    }
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let kb: u64 = err
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("peak-kb "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0);
    // GNU time reports a child killed by a signal as "Command terminated by signal N" and
    // exits 128 + N: read as no exit code.
    let code = o
        .status
        .code()
        .filter(|_| !err.contains("terminated by signal"));
    (code, err, kb * 1024)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The set's files and their bytes (the summary's timing and the marker left out: they
/// differ between a whole run and a merge).
fn set_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<_> = entries
        .map(|e| {
            let e = e.unwrap();
            (e.file_name().into_string().unwrap(), e.path())
        })
        .filter(|(n, p)| {
            !n.starts_with('.')
                && p.is_file()
                && !matches!(
                    n.as_str(),
                    "summary.json" | "tofprobe-set.toml" | "notes.txt"
                )
        })
        .map(|(n, p)| (n, std::fs::read(p).unwrap()))
        .collect();
    v.sort();
    v
}

/// One case; its failures (empty: passed) and the runs it made.
fn soak_case(tmp: &Path, case: usize, rng: &mut Rng) -> (Vec<String>, usize, bool) {
    let d = draw(rng);
    let dir = tmp.join(format!("case{case}"));
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("scene.toml");
    std::fs::write(&cfg, &d.text).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), b"the user's own").unwrap();
    let mut fail = Vec::new();
    let mut runs = 1;
    let (code, err, peak) = measured(&["simulate", s(&cfg), "--out", s(&out)], None);
    let tag = format!("case {case} ({})", d.what);
    if let Some(key) = d.bad_key {
        if code != Some(2) || !err.contains(key) || err.contains("panicked") {
            fail.push(format!(
                "{tag}: exit {code:?}, not a refusal naming {key}: {}",
                clip(&err)
            ));
        }
        if std::fs::read_dir(&out).unwrap().count() != 1 {
            fail.push(format!("{tag}: a refused run wrote into --out"));
        }
        return (fail, runs, false);
    }
    if code != Some(0) {
        fail.push(format!("{tag}: simulate exit {code:?}: {}", clip(&err)));
        return (fail, runs, true);
    }
    let g = (d.spads as f64).sqrt() as u64;
    let stated = SensorArray::bytes_needed(d.rows / g, d.cols / g, d.registers, d.bins, d.spads);
    if peak == 0 || peak > stated {
        fail.push(format!("{tag}: peak {peak} bytes, stated {stated}"));
    }
    let whole = set_bytes(&out);
    runs += 1;
    let (c, e, _) = measured(&["check-set", s(&out)], None);
    if c != Some(0) {
        fail.push(format!(
            "{tag}: check-set refused a whole set: {}",
            clip(&e)
        ));
    }
    // A second seed's run killed after rename k of its commit (files, then the marker).
    let files = whole.len() + 2;
    let k = 1 + rng.index(files);
    let other = dir.join("other.toml");
    std::fs::write(&other, d.text.replacen("\nseed = ", "\nseed = 7", 1)).unwrap();
    runs += 2;
    let (c, e, _) = measured(
        &["simulate", s(&other), "--out", s(&out)],
        Some(("TOFPROBE_TEST_KILL_AFTER_RENAMES", k.to_string())),
    );
    if c == Some(0) || c == Some(101) || e.contains("panicked") {
        fail.push(format!(
            "{tag}: killed after rename {k}: exit {c:?}: {}",
            clip(&e)
        ));
    }
    let (c, e, _) = measured(&["check-set", s(&out)], None);
    match c {
        Some(0) => {
            let summary = std::fs::read_to_string(out.join("summary.json")).unwrap_or_default();
            if !summary.contains("other.toml") {
                fail.push(format!(
                    "{tag}: rename {k}: check-set passed a set that is not the last run's"
                ));
            }
        }
        Some(2) if e.contains("was cut short") => {}
        _ => fail.push(format!(
            "{tag}: rename {k}: check-set exit {c:?}: {}",
            clip(&e)
        )),
    }
    // The next run makes the directory whole again: the first configuration's set.
    runs += 2;
    let (c, e, _) = measured(&["simulate", s(&cfg), "--out", s(&out)], None);
    let (c2, e2, _) = measured(&["check-set", s(&out)], None);
    if c != Some(0) || c2 != Some(0) || set_bytes(&out) != whole {
        fail.push(format!(
            "{tag}: after the kill: exit {c:?}/{c2:?}: {}{}",
            clip(&e),
            clip(&e2)
        ));
    }
    // Shards merged: the whole run's bytes.
    // At most one tile per pixel.
    let n = (2 + rng.index(3)).min((d.rows / g * (d.cols / g)) as usize);
    let mut shards: Vec<PathBuf> = Vec::new();
    for i in 0..n {
        let t = dir.join(format!("tile{i}"));
        runs += 1;
        let (c, e, _) = measured(
            &[
                "simulate",
                s(&cfg),
                "--out",
                s(&t),
                "--shard",
                &format!("{i}/{n}"),
            ],
            None,
        );
        if c != Some(0) {
            fail.push(format!("{tag}: shard {i}/{n}: exit {c:?}: {}", clip(&e)));
        }
        shards.push(t);
    }
    let merged = dir.join("merged");
    let mut args = vec!["merge".to_string()];
    args.extend(shards.iter().map(|p| s(p).to_string()));
    args.extend(["--out".into(), s(&merged).into()]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    runs += 1;
    let (c, e, _) = measured(&a, None);
    if c != Some(0) || set_bytes(&merged) != whole {
        fail.push(format!(
            "{tag}: merge of {n} shards: exit {c:?}, same bytes: {}: {}",
            set_bytes(&merged) == whole,
            clip(&e)
        ));
    }
    if std::fs::read(out.join("notes.txt")).ok().as_deref() != Some(&b"the user's own"[..]) {
        fail.push(format!("{tag}: the user's notes.txt was touched"));
    }
    let _ = std::fs::remove_dir_all(&dir);
    (fail, runs, true)
}

#[test]
fn the_array_surface_soaks_without_panic_torn_set_or_memory_past_its_statement() {
    if !tofprobe_testkit::tools::have(&["/usr/bin/time", "timeout"], "array soak (GNU time)") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let mut rng = Rng(0x45_50a4_2026);
    let (mut failures, mut runs, mut accepted, mut refused) = (Vec::new(), 0, 0, 0);
    let n = cases();
    for case in 0..n {
        let (f, r, ok) = soak_case(tmp.path(), case, &mut rng);
        failures.extend(f);
        runs += r;
        if ok {
            accepted += 1;
        } else {
            refused += 1;
        }
    }
    eprintln!(
        "array soak: {n} cases ({accepted} accepted, {refused} out of range), {runs} runs, {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
