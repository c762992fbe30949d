//! Issue 45 items 8 and 13 through the binary: two runs at once.
//! - Two writers into one `--out` (item 8): while an array run holds the directory (its
//!   stage is there), a second `simulate --out` or `merge --out` into it is refused at once,
//!   naming the first's process, and the first's set ends whole — no interleaved commits.
//! - The synthesis cache (item 13): an entry whose netlist is half written (what a second
//!   run met while the first's yosys still wrote it in place) is synthesised again, not
//!   read; two cold `size` runs on one cache both succeed with the same figures.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::array_sets::plate;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The pid of the live stage directory in `dir`, once one appears (within `limit`).
fn stage_pid(dir: &Path, limit: Duration) -> Option<u32> {
    let t0 = Instant::now();
    while t0.elapsed() < limit {
        if let Ok(rd) = std::fs::read_dir(dir) {
            for e in rd.flatten() {
                let n = e.file_name().to_string_lossy().into_owned();
                if let Some(pid) = n
                    .strip_prefix(".output-set.tofprobe-")
                    .and_then(|r| r.strip_suffix(".stage"))
                {
                    return pid.parse().ok();
                }
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    None
}

#[test]
fn a_second_writer_into_a_directory_being_written_is_refused_naming_the_first() {
    let tmp = tempfile::tempdir().unwrap();
    // ≈ 1–3 s of model: 96 × 96 pixels at 40,000 pulses.
    let big = plate(
        tmp.path(),
        "big.toml",
        &[
            ("rows = 4", "rows = 96"),
            ("cols = 3", "cols = 96"),
            ("mm_per_pixel = 80.0", "mm_per_pixel = 4.0"),
        ],
    );
    let small = plate(tmp.path(), "small.toml", &[]);
    let sets: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = tmp.path().join(format!("t{i}"));
            let o = bin()
                .args([
                    "simulate",
                    s(&small),
                    "--out",
                    s(&d),
                    "--shard",
                    &format!("{i}/2"),
                ])
                .output()
                .unwrap();
            assert!(o.status.success());
            d
        })
        .collect();
    let out = tmp.path().join("out");
    let mut first = bin()
        .args(["simulate", s(&big), "--out", s(&out)])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let holder = stage_pid(&out, Duration::from_secs(20)).expect("the first run's stage");
    assert_eq!(holder, first.id());
    for args in [
        vec!["simulate", s(&small), "--out", s(&out)],
        vec!["merge", s(&sets[0]), s(&sets[1]), "--out", s(&out)],
    ] {
        let t0 = Instant::now();
        let o = bin().args(&args).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains(&format!("is being written by tofprobe process {holder}")),
            "{args:?}: {e}"
        );
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "refused at once, not after the model"
        );
    }
    let status = first.wait().unwrap();
    assert!(status.success());
    let o = bin().args(["check-set", s(&out)]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"rows\": 96"),
        "the first run's set, whole"
    );
}

/// `tofprobe size` of a two-bin pixel (one synthesis, ≈ 7 s cold) with the cache `cache`;
/// its area and timing figures.
fn size(cfg: &Path, cache: &Path) -> Result<serde_json::Value, String> {
    let o = bin()
        .arg("size")
        .arg(cfg)
        .args([
            "--no-sky130",
            "--sweep-bins",
            "2",
            "--sweep-widths",
            "39",
            "--corner-trials",
            "0",
            "--json",
        ])
        .env("TOFPROBE_CACHE", cache)
        .output()
        .unwrap();
    if !o.status.success() {
        return Err(String::from_utf8_lossy(&o.stderr).into_owned());
    }
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).map_err(|e| e.to_string())?;
    Ok(serde_json::json!({ "area": v["area"], "timing": v["timing"] }))
}

#[test]
fn the_synthesis_cache_rebuilds_a_half_written_netlist_and_serves_concurrent_runs() {
    if !tofprobe_testkit::tools::have(&["yosys", "sta"], "synthesis cache under concurrency") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let text = String::from_utf8(
        bin()
            .args(["config", "--print-default"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let text = crate::common::edit(
        text,
        &[
            ("bins = 16 ", "bins = 2 "),
            ("cycles_per_pulse = 16 ", "cycles_per_pulse = 2 "),
        ],
    );
    let cfg = tmp.path().join("two-bins.toml");
    std::fs::write(&cfg, text).unwrap();
    let cache = tmp.path().join("cache");
    let want = size(&cfg, &cache).unwrap();
    // The state a second run met while the first's yosys rewrote the entry in place: its
    // result there, its netlist half written, nothing timed from it yet.
    let entries: Vec<PathBuf> = std::fs::read_dir(cache.join("synth/synth"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let netlist = entries[0].join("netlist.v");
    let whole = std::fs::read(&netlist).unwrap();
    std::fs::write(&netlist, &whole[..whole.len() / 2]).unwrap();
    for f in std::fs::read_dir(&entries[0]).unwrap() {
        let p = f.unwrap().path();
        let n = p.file_name().unwrap().to_string_lossy().into_owned();
        if n.starts_with("timing") || n.starts_with("split") {
            std::fs::remove_file(p).unwrap();
        }
    }
    let again = size(&cfg, &cache).expect("a half-written netlist is synthesised again, not read");
    assert_eq!(again, want);
    assert_eq!(std::fs::read(&netlist).unwrap(), whole);
    // Two cold runs on one fresh cache at once: one synthesis, both runs succeed.
    let fresh = tmp.path().join("fresh");
    let runs: Vec<_> = std::thread::scope(|sc| {
        let hs: Vec<_> = (0..2).map(|_| sc.spawn(|| size(&cfg, &fresh))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for r in runs {
        assert_eq!(r.unwrap(), want);
    }
    let hidden: Vec<_> = std::fs::read_dir(fresh.join("synth/synth"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}
