//! SIGINT and SIGTERM through the binary (docs/reliability.md): an interrupted `vectors`
//! exits with 130 and leaves no temporary, and the directory holds the old set or the new
//! set, whole, without any recovery by a later run; an interrupted Verilator build leaves
//! no build directory in the cache.

use crate::common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{listing, whole_set_seed};

/// Sends `signal` (INT, TERM) to `child` through kill(1): the workspace has no unsafe code
/// and no libc binding.
fn signal(child: &Child, signal: &str) {
    let ok = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .expect("run kill");
    assert!(ok.success(), "kill -{signal} failed");
}

/// Waits for `child` at most `limit`; its exit code.
fn wait(child: &mut Child, limit: Duration) -> Option<i32> {
    let t0 = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("the run did not end within {limit:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn vectors(dir: &Path, seed: u64) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    c.args([
        "vectors",
        "--frame-pulses",
        "4096",
        "--frames",
        "2",
        "--seed",
    ])
    .arg(seed.to_string())
    .arg("--out")
    .arg(dir)
    .stdout(Stdio::null())
    .stderr(Stdio::piped());
    c
}

#[test]
fn an_interrupted_vectors_run_leaves_the_old_set_or_the_new_set_and_no_temporary() {
    let tmp = tempfile::tempdir().unwrap();
    // Into a directory that does not exist yet: the run leaves a whole set or no directory.
    let fresh = tmp.path().join("fresh");
    let mut child = vectors(&fresh, 1).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    signal(&child, "INT");
    let code = wait(&mut child, Duration::from_secs(10));
    assert!(
        !fresh.exists() || whole_set_seed(&fresh) == Some(1),
        "interrupted into a new directory: {code:?} {:?}",
        listing(&fresh)
    );
    assert_eq!(
        listing(tmp.path())
            .iter()
            .filter(|n| n.starts_with('.'))
            .count(),
        0
    );

    let dir = tmp.path().join("v");
    let t0 = std::time::Instant::now();
    assert!(vectors(&dir, 1).status().unwrap().success());
    // How long an uninterrupted run takes on this machine now: a signal in its first half
    // must interrupt it (one later may find it committed already).
    let run_ms = t0.elapsed().as_millis() as u64;
    assert_eq!(whole_set_seed(&dir), Some(1));
    // Signal points spread over a run (≈ 2 s on the shared box: ROM, model, staging with
    // fsync, commit); fixed, so the test is deterministic in what it asks.
    let (mut interrupted, mut finished, mut early) = (0, 0, 0);
    let mut seed = 1;
    for sig in ["INT", "TERM"] {
        for ms in [50u64, 400, 900, 1500] {
            seed += 1;
            early += usize::from(ms < run_ms / 2);
            let mut child = vectors(&dir, seed).spawn().unwrap();
            std::thread::sleep(Duration::from_millis(ms));
            signal(&child, sig);
            let code = wait(&mut child, Duration::from_secs(10));
            let err = {
                use std::io::Read;
                let mut s = String::new();
                child.stderr.take().unwrap().read_to_string(&mut s).unwrap();
                s
            };
            assert!(!err.contains("panicked"), "{err}");
            // No recovery here: the handler alone must have left the directory clean.
            let left = listing(&dir);
            assert!(
                left.iter().all(|n| !n.starts_with('.')),
                "SIG{sig} at {ms} ms left temporaries: {left:?}"
            );
            let now = whole_set_seed(&dir).expect("a whole set after the signal");
            match code {
                Some(130) => {
                    interrupted += 1;
                    // Interrupted before or after the commit: the old set or the new.
                    assert!(now <= seed, "seed {now}");
                }
                Some(0) => {
                    finished += 1;
                    assert_eq!(now, seed, "a finished run installs its set");
                }
                other => panic!("SIG{sig} at {ms} ms: exit {other:?}: {err}"),
            }
        }
    }
    eprintln!(
        "signal test: {interrupted} interrupted (exit 130), {finished} finished; a run takes {run_ms} ms"
    );
    // The 50 ms signals always land in the first half (a run is ≥ 0.4 s: ROM, model,
    // fsync'd staging), so at least 2 interruptions are asked of every machine.
    assert!(
        interrupted >= early.max(2),
        "the signals in a run's first half ({early}) must interrupt it: {interrupted} did"
    );
}

/// Ctrl-C during a Verilator build: the build directory in progress (`.HASH.PID.N` in the
/// cache) goes with the run. Skipped without verilator.
#[test]
fn an_interrupted_verilator_build_leaves_no_build_directory() {
    if Command::new("verilator").arg("--version").output().is_err() {
        eprintln!("skipped: no verilator on PATH; the interrupted-build test did not run");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let builds = cache.join("verilator");
    for (sig, ms) in [("INT", 1500u64), ("TERM", 3000)] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
            .args(["cosim", "--frame-pulses", "256", "--out"])
            .arg(tmp.path().join("work"))
            .env("TOFPROBE_CACHE", &cache)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Wait until the build directory exists, then a little longer (the compile runs).
        let t0 = Instant::now();
        while listing(&builds).is_empty() && t0.elapsed() < Duration::from_secs(20) {
            std::thread::sleep(Duration::from_millis(20));
        }
        std::thread::sleep(Duration::from_millis(ms));
        signal(&child, sig);
        let code = wait(&mut child, Duration::from_secs(20));
        // Verilator's own children (make, the compiler) got no signal from kill(1): give
        // them a moment to fail on their vanished directory.
        std::thread::sleep(Duration::from_millis(500));
        let left = listing(&builds);
        match code {
            Some(130) => assert!(
                left.iter().all(|n| !n.starts_with('.')),
                "SIG{sig}: an interrupted build left {left:?}"
            ),
            // The build finished before the signal: only the published cache entry.
            Some(0) => assert!(left.iter().all(|n| !n.starts_with('.')), "{left:?}"),
            other => panic!("SIG{sig}: exit {other:?}"),
        }
        eprintln!(
            "verilator build, SIG{sig} {ms} ms into the build: exit {code:?}, cache {left:?}"
        );
    }
}
