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
pub(crate) struct Run {
    pub(crate) code: Option<i32>,
    pub(crate) stderr: String,
    pub(crate) stdout: String,
    pub(crate) seconds: f64,
}

/// Runs the binary with `args` under a 4 GiB address-space limit, killed after `limit`
/// (then the test fails, naming the command).
pub(crate) fn run(args: &[&str], limit: Duration) -> Run {
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
pub(crate) fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("bounds")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("mkdir");
    d
}

pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A refusal: exit 2, no panic, the message holds every one of `needles`.
#[track_caller]
pub(crate) fn refused(r: &Run, needles: &[&str]) {
    assert_eq!(r.code, Some(2), "stderr: {}", clip(&r.stderr));
    assert!(!r.stderr.contains("panicked"), "{}", clip(&r.stderr));
    for n in needles {
        assert!(r.stderr.contains(n), "`{n}` not in: {}", clip(&r.stderr));
    }
}

pub(crate) fn clip(s: &str) -> String {
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

/// The HydraHarp v2 T3 sample record (BSD-3-Clause, third_party/picoquant-tttr).
fn hydraharp_t3() -> Vec<u8> {
    let p = tofprobe_testkit::data::tttr_record("hydraharp_v20_t3.ptu");
    std::fs::read(p).expect("sample record")
}

/// `ptu` with the 8-byte value of header tag `ident` replaced by `value`.
fn patch_tag(ptu: &[u8], ident: &str, value: [u8; 8]) -> Vec<u8> {
    let mut key = ident.as_bytes().to_vec();
    key.push(0);
    let at = ptu
        .windows(key.len())
        .position(|w| w == key.as_slice())
        .unwrap_or_else(|| panic!("tag {ident}"));
    let mut out = ptu.to_vec();
    out[at + 40..at + 48].copy_from_slice(&value);
    out
}

/// The sample's header with `TTResult_NumberOfRecords` set, followed by `records`.
fn ptu_with_records(records: &[u32]) -> Vec<u8> {
    let src = hydraharp_t3();
    let end = src
        .windows(11)
        .position(|w| w == b"Header_End\0")
        .expect("Header_End")
        + 48;
    let mut out = patch_tag(
        &src[..end],
        "TTResult_NumberOfRecords",
        (records.len() as i64).to_le_bytes(),
    );
    for r in records {
        out.extend_from_slice(&r.to_le_bytes());
    }
    out
}

/// A HydraHarp v2 T3 overflow record of `wraps` × 1024 sync periods (1 ≤ wraps ≤ 1023).
fn hh_overflow(wraps: u32) -> u32 {
    0x8000_0000 | (63 << 25) | wraps
}

/// A record's pulses are counted from the sync counts its records carry, and a record
/// spanning more than 2^32 pulses is refused at the record that crosses the cap, within a
/// second. The 16-byte B&H SPC file whose "multiple macro-time overflow" record claims
/// 2^28 − 1 overflows (≈ 1.1·10^12 pulses: about a day of CPU, walked pulse by pulse) and
/// 30,000 all-ones HydraHarp records (1,047,552 pulses each: 13.7 s) are refused naming
/// record 1 (byte 8) and record 4100 (byte 22200): 4100 × 1,047,552 + 1 ≤ 2^32 <
/// 4101 × 1,047,552 + 1, and the header is 5800 bytes. At exactly 2^32 pulses a record
/// still replays (with a configuration: no fit of the whole span), one pulse more is refused.
#[test]
fn records_implying_more_pulses_than_the_cap_are_refused_by_record() {
    let d = scratch("record-span");
    let spc = d.join("overflow.spc");
    let words: [u32; 4] = [500, (100 << 16) | 5, 0xCFFF_FFFF, (100 << 16) | 7];
    std::fs::write(&spc, words.map(u32::to_le_bytes).concat()).expect("spc");
    assert_eq!(std::fs::metadata(&spc).expect("spc").len(), 16);
    let r = run(
        &["replay", s(&spc), "--resolution-s", "1.2e-11"],
        Duration::from_secs(10),
    );
    refused(
        &r,
        &[
            "overflow.spc: record 1 (byte 8)",
            "268435455 wrap-around(s)",
            "1099511623681 pulses",
            "at most 4294967296 laser pulses",
        ],
    );
    assert!(r.seconds < 1.0, "{} s", r.seconds);

    let ptu = d.join("overflows.ptu");
    std::fs::write(&ptu, ptu_with_records(&[u32::MAX; 30_000])).expect("ptu");
    let r = run(&["replay", s(&ptu)], Duration::from_secs(10));
    refused(
        &r,
        &[
            "overflows.ptu: record 4100 (byte 22200)",
            "1023 wrap-around(s)",
            "4296010753 pulses",
        ],
    );
    assert!(r.seconds < 1.0, "{} s", r.seconds);

    // 4100 × 1023 + 3 wraps of 1024, then a photon at nsync 1023: last sync count
    // 2^32 − 1, so 2^32 pulses exactly.
    let mut records = vec![u32::MAX; 4100];
    records.push(hh_overflow(3));
    records.push((100 << 10) | 1023);
    let edge = d.join("edge.ptu");
    std::fs::write(&edge, ptu_with_records(&records)).expect("ptu");
    let cfg = write(
        &d,
        "frame.toml",
        &edit(default_text(), &[("duration_s = 1.0 ", "pulses = 20000 ")]),
    );
    let r = run(&["replay", s(&edge), s(&cfg)], Duration::from_secs(60));
    assert_eq!(r.code, Some(0), "{}", clip(&r.stderr));
    assert!(r.stdout.contains("4102 records"), "{}", r.stdout);
    records.push(hh_overflow(1));
    std::fs::write(&edge, ptu_with_records(&records)).expect("ptu");
    let r = run(&["replay", s(&edge), s(&cfg)], Duration::from_secs(10));
    refused(&r, &["record 4102 (byte 22208)", "4294967297 pulses"]);
}

/// A delay resolution of 10^-20 s (from the header or `--resolution-s`) printed σ 0 and
/// every amplitude 0 with exit 0; it is refused naming the header tag or the option with
/// the range 1e-15 ≤ s < 1. A sync rate of 1 Hz in the header (`TTResult_SyncRate = 1`) is
/// refused naming that tag, not `sensor.tdc_lsb_ps` (which the fit derived from it).
#[test]
fn absurd_record_headers_are_refused_naming_the_header_tag() {
    let d = scratch("record-header");
    let src = hydraharp_t3();
    let tiny = d.join("tiny-resolution.ptu");
    std::fs::write(
        &tiny,
        patch_tag(&src, "MeasDesc_Resolution", 1e-20f64.to_le_bytes()),
    )
    .expect("ptu");
    let r = run(&["replay", s(&tiny)], Duration::from_secs(20));
    refused(
        &r,
        &[
            "tiny-resolution.ptu: header tag `MeasDesc_Resolution`",
            "1e-15 <= s < 1",
            "found 1e-20",
        ],
    );
    let good = d.join("sample.ptu");
    std::fs::write(&good, &src).expect("ptu");
    let r = run(
        &["replay", s(&good), "--resolution-s", "1e-20"],
        Duration::from_secs(20),
    );
    refused(&r, &["--resolution-s = 1e-20", "1e-15 <= s < 1"]);

    let slow = d.join("sync-1hz.ptu");
    std::fs::write(
        &slow,
        patch_tag(&src, "TTResult_SyncRate", 1i64.to_le_bytes()),
    )
    .expect("ptu");
    let r = run(&["replay", s(&slow)], Duration::from_secs(20));
    refused(
        &r,
        &[
            "sync-1hz.ptu: header tag `TTResult_SyncRate`",
            "found 1 Hz",
            "1000 to 1e10 Hz",
        ],
    );
    assert!(!r.stderr.contains("tdc_lsb_ps"), "{}", r.stderr);
    // The unpatched sample still replays (its 1 ps bins and 5 MHz sync are inside).
    let r = run(&["replay", s(&good)], Duration::from_secs(60));
    assert_eq!(r.code, Some(0), "{}", clip(&r.stderr));
}

/// `--rom-depth` of the RTL commands builds its sign ROM whole as well: 2^30 aborted out of
/// memory (8 GiB); it is refused by `rtl` and `vectors` with the same cap, 2^21.
#[test]
fn the_rom_depth_option_has_the_same_cap() {
    let d = scratch("rom-depth-option");
    for cmd in ["rtl", "vectors"] {
        let out = d.join(cmd);
        let r = run(
            &[
                cmd,
                "--rom-depth",
                "1073741824",
                "--frame-pulses",
                "64",
                "--out",
                s(&out),
            ],
            Duration::from_secs(20),
        );
        refused(
            &r,
            &[
                "rom_depth = 1073741824",
                "--rom-depth is at most 2097152",
                "nearest valid value: 2097152",
            ],
        );
        assert!(r.seconds < 1.0, "{cmd}: {} s", r.seconds);
    }
}
