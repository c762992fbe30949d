//! Mutated time-tagged records through `tofprobe replay` (issue 31, item 5): the real
//! PicoQuant records of third_party/picoquant-tttr (cut to their first 4000 records, the header's
//! record count patched, so a run takes about a second) and a B&H SPC file built here (no
//! real one is shipped), mutated in their header tags (integers, floats, strings' lengths
//! left alone: every 8-byte value of a scalar tag), their records (all-ones overflow
//! records, overflow markers with huge counts, random words), their length, and the
//! resolution given on the command line. Every run must end within a time limit (a hang
//! fails the test: the overflow walks of issue 31 took 13.7 s and a day), exit 0 or 2, print
//! no panic, and a refusal is an `error: …` line. Deterministic (a fixed seed);
//! `TOFPROBE_RECORD_MUTATIONS=N` runs N cases (default 12, about ten seconds) for a soak.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use tofprobe_testkit::params::Rng;

/// Records kept of each real file.
const KEEP_RECORDS: usize = 4000;
/// A run past this is a hang (the slowest base runs in about a second).
const LIMIT: Duration = Duration::from_secs(20);

fn data(name: &str) -> PathBuf {
    tofprobe_testkit::data::tttr_record(name)
}

/// A PTU header tag: its name, type and where its 8-byte value sits.
struct Tag {
    name: String,
    typ: u32,
    value_at: usize,
}

/// The tags of a PTU header and the offset of the first record (after `Header_End`).
fn tags(d: &[u8]) -> (Vec<Tag>, usize) {
    let mut v = Vec::new();
    let mut i = 16;
    while i + 48 <= d.len() {
        let name = String::from_utf8_lossy(&d[i..i + 32])
            .trim_end_matches('\0')
            .to_string();
        let typ = u32::from_le_bytes(d[i + 36..i + 40].try_into().unwrap());
        let value = i64::from_le_bytes(d[i + 40..i + 48].try_into().unwrap());
        v.push(Tag {
            name: name.clone(),
            typ,
            value_at: i + 40,
        });
        i += 48;
        // Arrays, strings and blobs: the value is the length of the bytes that follow.
        if matches!(typ, 0x2001_FFFF | 0x4001_FFFF | 0x4002_FFFF | 0xFFFF_FFFF) {
            i += usize::try_from(value).unwrap_or(0);
        }
        if name == "Header_End" {
            return (v, i);
        }
    }
    (v, d.len())
}

/// The real record `name` cut to its first [`KEEP_RECORDS`] records, its record count
/// patched to match (so the cut file is a valid record).
fn cut_ptu(name: &str) -> Vec<u8> {
    let path = data(name);
    let mut d = std::fs::read(&path)
        .unwrap_or_else(|e| panic!("the vendored record {}: {e}", path.display()));
    let (tags, start) = tags(&d);
    let n = tags
        .iter()
        .find(|t| t.name == "TTResult_NumberOfRecords")
        .unwrap_or_else(|| panic!("{name}: no TTResult_NumberOfRecords tag"));
    let keep = KEEP_RECORDS.min((d.len() - start) / 4);
    d[n.value_at..n.value_at + 8].copy_from_slice(&(keep as i64).to_le_bytes());
    d.truncate(start + 4 * keep);
    d
}

/// A B&H SPC-130 file: the clock word, then `n` photons around ADC code 100 one macro tick
/// (one sync) apart.
fn spc(rng: &mut Rng, n: usize) -> Vec<u8> {
    let mut words = vec![500u32];
    for k in 0..n {
        let adc = 100 + (rng.next_u64() % 16) as u32;
        words.push((adc << 16) | (k as u32 % 4096));
    }
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// Values written over a scalar tag: integers at the edges, floats at the edges and
/// non-finite, random bits.
fn tag_value(rng: &mut Rng, typ: u32) -> [u8; 8] {
    let floats = [
        0.0,
        -1.0,
        1e-30,
        1e-20,
        5e-324,
        1e300,
        f64::NAN,
        f64::INFINITY,
    ];
    let ints = [0i64, 1, -1, 2, i64::MAX, i64::MIN, 1 << 40, 4096];
    match (typ, rng.index(5)) {
        (_, 4) => rng.next_u64().to_le_bytes(),
        (0x2000_0008, _) => floats[rng.index(floats.len())].to_le_bytes(),
        _ => ints[rng.index(ints.len())].to_le_bytes(),
    }
}

/// Record words: all ones (T3: an overflow of 1023 wraps), an overflow marker with a huge
/// count (SPC's multiple macro-time overflow), a T2/T3 special with random bits, anything.
fn record_word(rng: &mut Rng) -> u32 {
    match rng.index(5) {
        0 => u32::MAX,
        1 => 0xC000_0000 | (rng.next_u64() as u32 & 0x0FFF_FFFF),
        2 => 0xFE00_0000 | (rng.next_u64() as u32 & 0x01FF_FFFF),
        3 => 0,
        _ => rng.next_u64() as u32,
    }
}

/// One mutated case: the file bytes, its extension, and extra arguments.
fn mutate(
    rng: &mut Rng,
    bases: &[(String, Vec<u8>)],
) -> (Vec<u8>, &'static str, Vec<String>, String) {
    let mut what = Vec::new();
    let spc_case = rng.index(4) == 0;
    let (mut d, ext, start, tag_list) = if spc_case {
        let d = spc(rng, 2000);
        what.push("spc".to_string());
        (d, "spc", 4, Vec::new())
    } else {
        let (name, d) = &bases[rng.index(bases.len())];
        what.push(name.clone());
        let (t, start) = tags(d);
        (d.clone(), "ptu", start, t)
    };
    for _ in 0..1 + rng.index(3) {
        match rng.index(if tag_list.is_empty() { 3 } else { 4 }) {
            0 | 1 => {
                for _ in 0..1 + rng.index(8) {
                    let records = d.len().saturating_sub(start) / 4;
                    if records == 0 {
                        break;
                    }
                    let at = start + 4 * rng.index(records);
                    let w = record_word(rng);
                    d[at..at + 4].copy_from_slice(&w.to_le_bytes());
                    what.push(format!("record {} = {w:#010x}", (at - start) / 4));
                }
            }
            2 => {
                let at = rng.index(d.len() + 1);
                d.truncate(at);
                what.push(format!("cut at {at}"));
            }
            _ => {
                let scalars: Vec<&Tag> = tag_list
                    .iter()
                    .filter(|t| {
                        !matches!(t.typ, 0x2001_FFFF | 0x4001_FFFF | 0x4002_FFFF | 0xFFFF_FFFF)
                    })
                    .filter(|t| t.name != "Header_End")
                    .collect();
                let t = scalars[rng.index(scalars.len())];
                let v = tag_value(rng, t.typ);
                if t.value_at + 8 <= d.len() {
                    d[t.value_at..t.value_at + 8].copy_from_slice(&v);
                }
                what.push(format!("{} = {:#018x}", t.name, u64::from_le_bytes(v)));
            }
        }
    }
    let mut args = Vec::new();
    let resolutions = ["1.2e-11", "1e-21", "0", "-1e-12", "nan", "1e3", "4e-12"];
    if spc_case || rng.index(4) == 0 {
        // SPC files need it; a PTU's header value is overridden now and then.
        let r = resolutions[rng.index(resolutions.len())];
        args.extend(["--resolution-s".to_string(), r.to_string()]);
        what.push(format!("--resolution-s {r}"));
    }
    (d, ext, args, what.join(", "))
}

/// Runs `replay FILE ARGS` with [`LIMIT`]: (exit code, stderr, seconds) or a hang.
fn replay(file: &Path, args: &[String]) -> Result<(Option<i32>, String, f64), String> {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tofprobe"));
    cmd.arg("replay").arg(file).args(args);
    crate::common::run_limited(cmd, LIMIT)
}

#[test]
fn mutated_records_exit_0_or_2_within_a_time_limit() {
    let cases: usize = std::env::var("TOFPROBE_RECORD_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(12);
    let bases: Vec<(String, Vec<u8>)> = tofprobe_testkit::data::TTTR_RECORDS
        .iter()
        .map(|n| (n.to_string(), cut_ptu(n)))
        .collect();
    let tmp = tempfile::tempdir().unwrap();
    let mut rng = Rng(0x7777_2026_1126);
    let (mut accepted, mut refused, mut slowest) = (0, 0, 0.0f64);
    let mut failures = Vec::new();
    for case in 0..cases {
        let (bytes, ext, args, what) = mutate(&mut rng, &bases);
        let file = tmp.path().join(format!("m{case}.{ext}"));
        std::fs::write(&file, &bytes).unwrap();
        match replay(&file, &args) {
            Err(hang) => failures.push(format!("case {case} ({what}): {hang}")),
            Ok((code, err, s)) => {
                slowest = slowest.max(s);
                let ok = match code {
                    Some(0) => {
                        accepted += 1;
                        true
                    }
                    Some(2) => {
                        refused += 1;
                        err.starts_with("error: ") || err.contains("\nerror: ")
                    }
                    _ => false,
                };
                if !ok || err.contains("panicked") {
                    failures.push(format!("case {case} ({what}): exit {code:?}: {err}"));
                }
            }
        }
        let _ = std::fs::remove_file(&file);
    }
    eprintln!(
        "record mutations: {cases} cases: {accepted} exit 0, {refused} exit 2, slowest {slowest:.2} s, {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
