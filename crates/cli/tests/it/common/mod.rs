//! Helpers shared by the CLI's integration tests: the built binary, the embedded default's
//! text and its edits, and the short windowed frame with a tone on a bin that several
//! tests run on. Each test binary uses a subset.
#![allow(dead_code)]

pub mod finite;

use std::path::Path;
use std::process::{Command, Output};

/// `tofprobe reproduce --quick --json --out DIR`, run once per test binary and shared by the
/// tests that read it (≈ 25 s each time): its output and the figures' directory.
pub fn reproduce_quick() -> &'static (Output, std::path::PathBuf) {
    static RUN: std::sync::OnceLock<(Output, std::path::PathBuf)> = std::sync::OnceLock::new();
    RUN.get_or_init(|| {
        let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("reproduce-quick-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let out = tofprobe(&[
            "reproduce",
            "--quick",
            "--json",
            "--out",
            dir.to_str().expect("utf-8 path"),
        ]);
        (out, dir)
    })
}

/// Runs the built `tofprobe` with `args`.
pub fn tofprobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .output()
        .expect("run tofprobe")
}

/// Whether every one of `tools` is installed; the first missing one is named on stderr
/// (the EDA tests skip without them).
pub fn have_tools(tools: &[&'static str]) -> bool {
    tofprobe_testkit::tools::have(tools, "tofprobe-cli test")
}

/// The JSON object a `--json` command printed on its last stdout line (panics with both
/// streams when it is not one).
pub fn last_json(o: &Output) -> serde_json::Value {
    let text = String::from_utf8_lossy(&o.stdout);
    serde_json::from_str(text.lines().last().unwrap_or("")).unwrap_or_else(|e| {
        panic!(
            "not JSON ({e}): {text}\n{}",
            String::from_utf8_lossy(&o.stderr)
        )
    })
}

/// The embedded default configuration's text (`config --print-default`).
pub fn default_text() -> String {
    String::from_utf8(tofprobe(&["config", "--print-default"]).stdout).expect("utf-8")
}

/// `text` with each `(from, to)` replaced once; each `from` must occur.
pub fn edit(mut text: String, edits: &[(&str, &str)]) -> String {
    for (from, to) in edits {
        assert!(text.contains(from), "configuration lacks `{from}`");
        text = text.replacen(from, to, 1);
    }
    text
}

/// The default with its periodic ROM (L = 20,000) switched to windowed (L = N): what the
/// short-frame tests need, whose bins lie on k·f_s/N.
pub fn windowed_default() -> String {
    edit(
        default_text(),
        &[("rom_mode = \"periodic\"", "rom_mode = \"windowed\"")],
    )
}

/// The windowed default shortened to `n` pulses, the tone made 1 mm and moved onto bin 30
/// (30·f_s/n), B = 4 bins (C = 4).
pub fn short_tone_frame(n: u64) -> String {
    let f = 30.0 * 10e6 / n as f64;
    edit(
        windowed_default(),
        &[
            ("duration_s = 1.0", &format!("pulses = {n}")),
            ("amplitude_mm = 0.1", "amplitude_mm = 1.0"),
            ("frequency_hz = 4500.0", &format!("frequency_hz = {f}")),
            ("bins = 16", "bins = 4"),
            ("cycles_per_pulse = 16", "cycles_per_pulse = 4"),
        ],
    )
}

/// Every entry of `dir` (names), sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The manifest's seed when every file matches the manifest's hashes (a whole set), else
/// `None`.
pub fn whole_set_seed(dir: &Path) -> Option<u64> {
    let m: toml::Table =
        toml::from_str(&std::fs::read_to_string(dir.join("manifest.toml")).ok()?).ok()?;
    let files = m.get("files")?.as_table()?;
    for (name, hash) in files {
        let bytes = std::fs::read(dir.join(name)).ok()?;
        if format!("{:016x}", tofprobe_io::fnv1a64(&bytes)) != hash.as_str()? {
            return None;
        }
    }
    let visible: Vec<String> = listing(dir)
        .into_iter()
        .filter(|n| !n.starts_with('.'))
        .collect();
    let mut expected: Vec<String> = files.keys().cloned().collect();
    expected.push("manifest.toml".into());
    expected.sort();
    (visible == expected).then(|| m.get("seed")?.as_integer().map(|s| s as u64))?
}

/// Runs `cmd` (stdout discarded, stderr captured) with a time limit: (exit code, stderr,
/// seconds), or an error naming the hang when it runs past `limit` (killed then). The
/// fuzz tests' one runner: a hang fails the test instead of stalling CI.
pub fn run_limited(
    mut cmd: Command,
    limit: std::time::Duration,
) -> Result<(Option<i32>, String, f64), String> {
    use std::io::Read;
    let mut child = cmd
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {cmd:?}: {e}"))?;
    let t0 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
            break s;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("{cmd:?} still running after {limit:?}"));
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        e.read_to_string(&mut err).map_err(|e| e.to_string())?;
    }
    Ok((status.code(), err, t0.elapsed().as_secs_f64()))
}

/// One synthesis cache for the tests that only read what a synthesis reports (its keys are
/// the design's and the liberty's content, and it serves concurrent runs:
/// `concurrency::the_synthesis_cache_rebuilds_a_half_written_netlist_and_serves_concurrent_runs`),
/// so a pixel several tests size is synthesised once per liberty in a run, not once per
/// test (the tiny pixel of size.rs and array_size.rs: 17 syntheses of 4 designs). A test
/// about the cache itself, a missing tool before synthesis, or the files a synthesis
/// writes keeps its own. Fresh for each run of the test binary (a stale cache could hide
/// a synthesis regression between runs); the directories of finished runs are removed.
pub fn shared_synth_cache() -> &'static Path {
    static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR"));
        let prefix = "synth-cache-";
        for e in std::fs::read_dir(root).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if let Some(pid) = name.strip_prefix(prefix)
                && !Path::new("/proc").join(pid).exists()
            {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
        let dir = root.join(format!("{prefix}{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("the shared synthesis cache");
        dir
    })
}
