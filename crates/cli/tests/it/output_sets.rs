//! Output sets through the binary (issue 31, item 2): every set (`rtl`, `vectors`, `flow`'s
//! directory) is whole or refused by every reader. A commit is stopped after each of its
//! renames (`TOFPROBE_TEST_KILL_AFTER_RENAMES=k`: the process aborts there, no handler
//! runs, as under SIGKILL); `tofprobe check-set` and `cosim --rtl` must then refuse the
//! directory as incomplete or find it whole — never a torn set accepted. A Haar set written
//! over a Fourier one drops the old ROM files (only those the old marker lists); `--out d`
//! and `--out /abs/d` give the same bytes; a flow interrupted leaves no old PASS report, and
//! a flow that fails removes the directory it created.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{have_tools, listing};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-sets-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn bin(cwd: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    c.current_dir(cwd);
    c
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", text(&o));
    o
}

/// `tofprobe check-set dir`: `Ok` when whole, else the refusal (exit status 2).
fn check_set(dir: &Path) -> Result<(), String> {
    let o = bin(Path::new("/"))
        .arg("check-set")
        .arg(dir)
        .output()
        .unwrap();
    match o.status.code() {
        Some(0) => Ok(()),
        Some(2) => Err(text(&o)),
        c => panic!("check-set exit {c:?}: {}", text(&o)),
    }
}

/// The configuration hash in each generated file's header (`Configuration hash …`), by file.
fn config_hashes(dir: &Path) -> Vec<(String, String)> {
    let mut v = Vec::new();
    for name in listing(dir) {
        let Ok(t) = std::fs::read_to_string(dir.join(&name)) else {
            continue;
        };
        let h = t.lines().take(6).find_map(|l| {
            let at = l.find("onfiguration hash")? + "onfiguration hash".len();
            let rest = l[at..].trim_start_matches([':', ' ']);
            Some(rest.chars().take(16).collect::<String>())
        });
        if let Some(h) = h {
            v.push((name, h));
        }
    }
    v
}

/// Rewrites `dir` with `args` (set A), then for every k from 1 to `renames` writes set B
/// (`b_args`) killed after its k-th rename: each time `check-set` refuses the directory or
/// finds it whole, and whole only with all of B; some kill point leaves a torn directory
/// (files of A and B side by side), which must be refused. Returns the refusals seen.
fn kill_every_rename(dir: &Path, a_args: &[&str], b_args: &[&str], renames: usize) -> usize {
    let cwd = dir.parent().unwrap();
    let mut refused = 0;
    let mut torn = 0;
    for k in 1..=renames {
        ok(bin(cwd).args(a_args).output().unwrap());
        check_set(dir).expect("set A whole");
        let o = bin(cwd)
            .args(b_args)
            .env("TOFPROBE_TEST_KILL_AFTER_RENAMES", k.to_string())
            .output()
            .unwrap();
        assert!(
            !o.status.success(),
            "k = {k}: the hook must stop the commit"
        );
        let hashes = config_hashes(dir);
        let distinct: std::collections::BTreeSet<&String> = hashes.iter().map(|(_, h)| h).collect();
        torn += usize::from(distinct.len() > 1);
        match check_set(dir) {
            Ok(()) => assert!(
                distinct.len() <= 1,
                "k = {k}: a torn set accepted: {hashes:?}"
            ),
            Err(e) => {
                assert!(e.contains("is not a whole output set"), "k = {k}: {e}");
                refused += 1;
            }
        }
    }
    assert!(
        torn >= 1,
        "no kill point left a torn directory: the test proves nothing"
    );
    // The next write completes or discards what the killed run left: whole again.
    ok(bin(cwd).args(a_args).output().unwrap());
    check_set(dir).expect("whole after the next run");
    assert!(
        listing(dir).iter().all(|n| !n.starts_with('.')),
        "{:?}",
        listing(dir)
    );
    refused
}

#[test]
fn a_killed_rtl_commit_is_refused_by_every_reader_or_whole() {
    let tmp = scratch("rtl-kill");
    let dir = tmp.join("rtl");
    let a = ["rtl", "--out", "rtl", "--frame-pulses", "64"];
    let b = ["rtl", "--out", "rtl", "--frame-pulses", "128"];
    // The set's files and the marker: one rename each; the marker's is the last.
    let files = listing_after(&tmp, &a, &dir);
    assert!(files >= 7, "{files} files");
    let refused = kill_every_rename(&dir, &a, &b, files + 1);
    assert_eq!(
        refused, files,
        "refused before the marker's rename, whole after it"
    );
    // cosim --rtl refuses an interrupted set before anything else (no tool needed).
    ok(bin(&tmp).args(a).output().unwrap());
    let o = bin(&tmp)
        .args(b)
        .env("TOFPROBE_TEST_KILL_AFTER_RENAMES", "3")
        .output()
        .unwrap();
    assert!(!o.status.success());
    let o = bin(&tmp)
        .args([
            "cosim",
            "--rtl",
            "rtl",
            "--frame-pulses",
            "128",
            "--out",
            "work",
        ])
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("is not a whole output set: its completion marker tofprobe-set.toml is missing"),
        "{t}"
    );
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn a_killed_vectors_commit_is_refused_or_whole() {
    let tmp = scratch("vec-kill");
    let dir = tmp.join("v");
    let a = [
        "vectors",
        "--out",
        "v",
        "--frame-pulses",
        "64",
        "--seed",
        "1",
    ];
    let b = [
        "vectors",
        "--out",
        "v",
        "--frame-pulses",
        "128",
        "--seed",
        "2",
    ];
    let n = 1 + listing_after(&tmp, &a, &dir);
    kill_every_rename(&dir, &a, &b, n - 1);
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The number of files the run `args` leaves in `dir` besides its marker.
fn listing_after(cwd: &Path, args: &[&str], dir: &Path) -> usize {
    ok(bin(cwd).args(args).output().unwrap());
    listing(dir).len() - 1
}

#[test]
fn a_haar_set_over_a_fourier_set_drops_the_old_rom_files_only() {
    let tmp = scratch("shrink");
    let dir = tmp.join("rtl");
    ok(bin(&tmp).args(["rtl", "--out", "rtl"]).output().unwrap());
    assert!(dir.join("tofprobe_probe_rom.hex").exists());
    // A file of the user's, and a generated file the user edited since: both stay.
    std::fs::write(dir.join("notes.txt"), "mine\n").unwrap();
    let core = dir.join("tofprobe_yosys_synth.tcl");
    let edited = std::fs::read_to_string(&core).unwrap() + "# my edit\n";
    std::fs::write(&core, &edited).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/fig12-step.toml");
    ok(bin(&tmp)
        .arg("rtl")
        .arg(&scene)
        .args(["--out", "rtl"])
        .output()
        .unwrap());
    let files = listing(&dir);
    assert!(
        files.iter().all(|n| !n.starts_with("tofprobe_probe_rom")),
        "old ROM files left: {files:?}"
    );
    assert!(files.contains(&"notes.txt".to_string()), "{files:?}");
    check_set(&dir).expect("the Haar set is whole");
    // Every generated file carries the Haar configuration's hash.
    let hashes = config_hashes(&dir);
    assert!(hashes.windows(2).all(|w| w[0].1 == w[1].1), "{hashes:?}");
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn out_relative_and_absolute_give_the_same_bytes_and_no_machine_path() {
    let tmp = scratch("abs");
    let read_all = |d: &Path| -> Vec<(String, Vec<u8>)> {
        listing(d)
            .into_iter()
            .map(|n| {
                let b = std::fs::read(d.join(&n)).unwrap();
                (n, b)
            })
            .collect()
    };
    ok(bin(&tmp).args(["rtl", "--out", "d"]).output().unwrap());
    let rel = read_all(&tmp.join("d"));
    std::fs::remove_dir_all(tmp.join("d")).unwrap();
    let abs = tmp.join("d");
    ok(bin(&tmp)
        .arg("rtl")
        .arg("--out")
        .arg(&abs)
        .output()
        .unwrap());
    let absolute = read_all(&abs);
    assert_eq!(rel.len(), absolute.len());
    let machine = tmp.to_string_lossy().into_owned();
    for ((n, x), (_, y)) in rel.iter().zip(&absolute) {
        assert!(x == y, "{n} differs between --out d and --out /abs/d");
        assert!(
            !String::from_utf8_lossy(y).contains(&machine),
            "{n} records the machine's path {machine}"
        );
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// A flow that fails (here: Verilator missing, after the RTL and vectors were written)
/// leaves no directory it created; no tool is needed.
#[test]
fn a_failed_flow_removes_the_directory_it_created() {
    let tmp = scratch("flow-fail");
    let out = tmp.join("new-flow");
    let o = bin(&tmp)
        .args([
            "flow",
            "--out",
            "new-flow",
            "--no-size",
            "--frame-pulses",
            "64",
        ])
        .env("PATH", "")
        .env("TOFPROBE_CACHE", tmp.join("empty-cache"))
        .output()
        .unwrap();
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.to_lowercase().contains("verilator"), "{t}");
    assert!(!out.exists(), "left {:?}", listing(&out));
    let _ = std::fs::remove_dir_all(&tmp);
}

/// A finished flow's directory is whole (`check-set`); a flow interrupted in its first
/// commit leaves neither the previous report (PASS) nor a marker beside the new RTL.
#[test]
fn an_interrupted_flow_leaves_no_previous_report() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let tmp = scratch("flow-kill");
    let out = tmp.join("f");
    let flow = ["flow", "--out", "f", "--no-size", "--frame-pulses", "64"];
    ok(bin(&tmp).args(flow).output().unwrap());
    assert!(
        std::fs::read_to_string(out.join("report.md"))
            .unwrap()
            .contains("PASS")
    );
    check_set(&out).expect("a finished flow is whole");
    let o = bin(&tmp)
        .args(["flow", "--out", "f", "--no-size", "--frame-pulses", "128"])
        .env("TOFPROBE_TEST_KILL_AFTER_RENAMES", "2")
        .output()
        .unwrap();
    assert!(!o.status.success(), "{}", text(&o));
    assert!(
        !out.join("report.md").exists(),
        "the old PASS report stayed"
    );
    let e = check_set(&out).expect_err("an interrupted flow is not whole");
    assert!(e.contains("tofprobe-set.toml is missing"), "{e}");
    let _ = std::fs::remove_dir_all(&tmp);
}

/// `reproduce --out DIR` (the run the test binary shares) is a marked set: `check-set`
/// finds it whole and its marker lists every figure it wrote.
#[test]
fn reproduce_writes_a_marked_set() {
    let (o, dir) = common::reproduce_quick();
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", text(o));
    check_set(dir).expect("reproduce's set is whole");
    let marker = std::fs::read_to_string(dir.join("tofprobe-set.toml")).unwrap();
    let svgs: Vec<String> = listing(dir)
        .into_iter()
        .filter(|n| n.ends_with(".svg"))
        .collect();
    assert!(svgs.len() >= 10, "{svgs:?}");
    for n in &svgs {
        assert!(
            marker.contains(&format!("\"{n}\" = ")),
            "{n} not in the marker"
        );
    }
}
