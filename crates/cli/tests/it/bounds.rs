//! Issue 31: no input can hang the tool or exhaust its memory, errors blame the key (or
//! header tag) at fault, and nonsense is refused — through the binary. Every run here is
//! bounded by a time limit (a hang fails the test instead of stalling CI) and by a 4 GiB
//! address-space limit (`ulimit -v`: the defects these tests guard against grew until
//! the OOM killer struck, and must not take the test machine with them).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{default_text, edit};

/// What a bounded run gave: exit code (`None` when killed by a signal), stderr, stdout,
/// wall time.
struct Run {
    code: Option<i32>,
    stderr: String,
    stdout: String,
    seconds: f64,
}

/// Runs the binary with `args` under a 4 GiB address-space limit, killed after `limit`
/// (then the test fails, naming the command).
fn run(args: &[&str], limit: Duration) -> Run {
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 4194304 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("spawn tofprobe");
    let mut out_pipe = child.stdout.take().expect("stdout");
    let mut err_pipe = child.stderr.take().expect("stderr");
    // Drained on threads, so a long message cannot block the child on a full pipe.
    let out = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = out_pipe.read_to_end(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = err_pipe.read_to_end(&mut s);
        s
    });
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("tofprobe {args:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let seconds = t0.elapsed().as_secs_f64();
    Run {
        code: status.code(),
        stderr: String::from_utf8_lossy(&err.join().expect("stderr thread")).into_owned(),
        stdout: String::from_utf8_lossy(&out.join().expect("stdout thread")).into_owned(),
        seconds,
    }
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("bounds")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("mkdir");
    d
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A refusal: exit 2, no panic, the message holds every one of `needles`.
#[track_caller]
fn refused(r: &Run, needles: &[&str]) {
    assert_eq!(r.code, Some(2), "stderr: {}", clip(&r.stderr));
    assert!(!r.stderr.contains("panicked"), "{}", clip(&r.stderr));
    for n in needles {
        assert!(r.stderr.contains(n), "`{n}` not in: {}", clip(&r.stderr));
    }
}

fn clip(s: &str) -> String {
    s.chars().take(2000).collect()
}

/// The configuration file is read only if it is a regular file of at most 16 MiB:
/// `/dev/zero` (which grew to the OOM killer) and a FIFO (which waited for a writer
/// forever) are refused at once, naming the path and what it is; a 17 MiB file is refused
/// by its length before a byte is read, naming the limit.
#[test]
fn configuration_files_are_read_within_a_stated_size() {
    let limit = Duration::from_secs(10);
    let r = run(&["config", "/dev/zero"], limit);
    refused(&r, &["/dev/zero", "character device", "not a regular file"]);
    assert!(r.seconds < 2.0, "{} s", r.seconds);

    let d = scratch("config-size");
    let big = d.join("big.toml");
    let f = std::fs::File::create(&big).expect("create");
    f.set_len((16 << 20) + 1).expect("sparse 16 MiB + 1");
    let r = run(&["simulate", s(&big)], limit);
    refused(&r, &["big.toml", "16777217 bytes", "16777216-byte limit"]);
    // At the limit it is read (and then refused by the TOML parser: NUL bytes).
    f.set_len(16 << 20).expect("16 MiB");
    let r = run(&["config", s(&big)], limit);
    assert_eq!(r.code, Some(2));
    assert!(!r.stderr.contains("limit"), "{}", clip(&r.stderr));

    let fifo = d.join("fifo.toml");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let r = run(&["config", s(&fifo)], limit);
        refused(&r, &["fifo.toml", "FIFO"]);
    }
}

/// `pixel.timing_liberty` is read the same way: `/dev/zero` is refused naming the key and
/// the file kind, before any synthesis (`config --time-adders` loads the liberty first).
#[test]
fn timing_liberty_is_read_within_a_stated_size() {
    let d = scratch("liberty");
    let cfg = write(
        &d,
        "zero-liberty.toml",
        &edit(
            default_text(),
            &[(
                "adders = 2 ",
                "adders = \"auto\"\ntiming_liberty = \"/dev/zero\" ",
            )],
        ),
    );
    let r = run(
        &["config", "--time-adders", s(&cfg)],
        Duration::from_secs(10),
    );
    refused(&r, &["timing_liberty", "/dev/zero", "not a regular file"]);
    assert!(r.seconds < 2.0, "{} s", r.seconds);
}

/// The default made periodic with L = `rom_depth` over a frame of `pulses`.
fn periodic(rom_depth: u64, pulses: u64) -> String {
    edit(
        default_text(),
        &[
            ("rom_depth = 20000 ", &format!("rom_depth = {rom_depth} ")),
            ("duration_s = 1.0 ", &format!("pulses = {pulses} ")),
        ],
    )
}

/// A periodic ROM is capped from the memory it needs (2^21 entries, ≈ 340 MB in
/// `simulate`), at resolution, so every command refuses L = 2^26 alike within a second,
/// naming `probe.rom_depth`, the limit and the deepest depth that fits and divides N
/// (`simulate` took 2 GB at 2^24 and aborted out of memory at 2^26; `rtl` swapped in a
/// 4096-entry sign ROM).
#[test]
fn a_periodic_rom_deeper_than_its_cap_is_refused_by_every_command() {
    let d = scratch("periodic-cap");
    let cfg = write(&d, "deep.toml", &periodic(1 << 26, 1 << 26));
    let out = d.join("out");
    for args in [
        vec!["config", s(&cfg)],
        vec!["simulate", s(&cfg)],
        vec!["rtl", s(&cfg), "--out", s(&out)],
        vec!["vectors", s(&cfg), "--out", s(&out)],
        vec!["size", s(&cfg)],
    ] {
        let r = run(&args, Duration::from_secs(20));
        refused(
            &r,
            &[
                "probe.rom_depth = 67108864",
                "rom_depth <= 2097152",
                "rom_depth = 2097152 (the deepest that fits and divides N = 67108864)",
            ],
        );
        assert!(r.seconds < 1.0, "{args:?}: {} s", r.seconds);
    }
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    // Just past the cap on a frame it does not divide: the hint is the deepest divisor.
    let cfg = write(&d, "past.toml", &periodic((1 << 21) + 1, 6_000_000));
    let r = run(&["config", s(&cfg)], Duration::from_secs(20));
    refused(&r, &["probe.rom_depth = 2097153", "rom_depth = 2000000 "]);
}

/// Below the cap, `rtl` renders the periodic ΣΔ ROM the configuration asks for at its own
/// depth: L = 2^17 is the ROM's depth, never a substituted 4096-entry sign-of-cosine ROM.
#[test]
fn rtl_renders_a_periodic_rom_at_its_depth() {
    let d = scratch("periodic-rtl");
    let cfg = write(&d, "l17.toml", &periodic(1 << 17, 1 << 17));
    let out = d.join("rtl");
    let r = run(&["rtl", s(&cfg), "--out", s(&out)], Duration::from_secs(60));
    assert_eq!(r.code, Some(0), "{}", clip(&r.stderr));
    assert!(
        r.stdout.contains("L = 131072") && r.stdout.contains("ΣΔ probe ROM (periodic"),
        "{}",
        r.stdout
    );
    assert!(!r.stdout.contains("sign-of-cosine"), "{}", r.stdout);
    let hex = std::fs::read_to_string(out.join("tofprobe_probe_rom.hex")).expect("hex");
    let entries = hex
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("//"))
        .count();
    assert_eq!(entries, 1 << 17);
}
