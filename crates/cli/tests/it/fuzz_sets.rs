//! Seeded fuzzing of the array's sets and of numeric options at 64-bit edges, through the
//! binary (issue 45). Each run is bounded by a time limit and a 4 GiB address space:
//! - tampered tile sets (manifest fields set to 64-bit edges and wrong types, files cut,
//!   grown, flipped, removed, `.npy` headers rewritten, the marker removed or re-sealed to
//!   match the tampering) through `merge` and `check-set`: exit 0 or 2, never a panic,
//!   abort or hang; a refusal names the set; a merge that succeeds wrote exactly the
//!   reference set (a tampering it cannot see must not change a byte), and `check-set`
//!   passes only a set whose files all have the marker's hashes;
//! - `cosim --tile`, `simulate --shard`, `--max-out-gib` and the co-simulation's counts at
//!   64-bit edges: exit 0 or 2, no panic, no hang.
//!
//! `TOFPROBE_SET_MUTATIONS=N` runs N tamperings and N/3 option cases of six runs each
//! (default 24: ≈ 3 s and ≈ 8 s).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use tofprobe_testkit::params::Rng;

use crate::array_sets::plate;

fn cases() -> usize {
    std::env::var("TOFPROBE_SET_MUTATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(24)
}

/// Runs the binary under `ulimit -v` 4 GiB with a time limit: (exit code, stderr), or the
/// hang.
fn run(args: &[&str], limit: Duration) -> Result<(Option<i32>, String), String> {
    // No tool on the PATH: a valid co-simulation is refused at once (Verilator missing)
    // instead of building for seconds per case.
    let mut cmd = Command::new("/bin/sh");
    cmd.arg("-c")
        .arg("ulimit -v 4194304 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .env("PATH", "");
    crate::common::run_limited(cmd, limit).map(|(code, err, _)| (code, err))
}

/// 64-bit edges and wrong types a manifest field is set to.
const EDGES: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967297",
    "8589934592",
    "9007199254740993",
    "9223372036854775807",
    "18446744073709551615",
    "-1",
    "1e300",
    "-0.0",
    "\"x\"",
    "null",
    "[]",
    "{}",
    "{\"start\": 0, \"end\": 18446744073709551615}",
    "{\"start\": 18446744073709551615, \"end\": 0}",
];

/// JSON paths of the manifest a mutation sets.
const FIELDS: &[&[&str]] = &[
    &["array_rows"],
    &["array_cols"],
    &["rows"],
    &["cols"],
    &["rows", "end"],
    &["cols", "start"],
    &["registers_per_pixel"],
    &["seed"],
    &["shard", "index"],
    &["shard", "count"],
    &["model_seconds"],
    &["version"],
    &["kind"],
    &["design_hash"],
    &["design", "array", "rows"],
    &["design", "array", "cols"],
    &["design", "array", "superpixel"],
    &["design", "pixel", "bins"],
    &["design", "pixel", "frame_pulses"],
    &["design", "array", "signal_rate"],
];

const FILES: &[&str] = &[
    "manifest.json",
    "registers.npy",
    "detections.npy",
    "signal_rate.npy",
    "background_rate.npy",
    "tofprobe-set.toml",
];

fn copy_dir(from: &Path, to: &Path) {
    let _ = std::fs::remove_dir_all(to);
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// Rewrites the marker so its hashes match the files as they are now (a tampering that
/// also re-seals the set: only the checks behind the marker can see it).
fn reseal(dir: &Path) {
    let m = dir.join("tofprobe-set.toml");
    let Ok(text) = std::fs::read_to_string(&m) else {
        return;
    };
    let Some(files) = tofprobe_io::marker::marker_files(&text) else {
        return;
    };
    let now = files
        .keys()
        .filter_map(|n| {
            let h = tofprobe_io::marker::hash_file(&dir.join(n)).ok()?;
            Some((n.clone(), h))
        })
        .collect();
    std::fs::write(&m, tofprobe_io::marker::marker_text("", &now)).unwrap();
}

/// One random tampering of the tile set in `dir`; its description.
fn tamper(rng: &mut Rng, dir: &Path) -> String {
    match rng.below(7) {
        0 | 1 => {
            let path = *rng.pick(FIELDS);
            let lit = *rng.pick(EDGES);
            let p = dir.join("manifest.json");
            // An earlier tampering of this case may have cut or removed the manifest.
            let Some(mut m) = std::fs::read(&p)
                .ok()
                .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
            else {
                return "manifest.json no longer JSON".into();
            };
            let mut at = &mut m;
            for k in &path[..path.len() - 1] {
                // serde_json's index panics on a scalar (an earlier tampering's).
                if !(at.is_object() || at.is_null()) {
                    return format!("manifest {path:?} under a scalar");
                }
                at = &mut at[*k];
            }
            if !(at.is_object() || at.is_null()) {
                return format!("manifest {path:?} under a scalar");
            }
            at[*path.last().unwrap()] = serde_json::from_str(lit).unwrap();
            std::fs::write(&p, serde_json::to_vec(&m).unwrap()).unwrap();
            format!("manifest {path:?} = {lit}")
        }
        2 => {
            let f = *rng.pick(FILES);
            let p = dir.join(f);
            let Ok(b) = std::fs::read(&p) else {
                return format!("{f} already gone");
            };
            let cut = rng.index(b.len() + 1);
            std::fs::write(&p, &b[..cut]).unwrap();
            format!("{f} cut to {cut} bytes")
        }
        3 => {
            let f = *rng.pick(FILES);
            let p = dir.join(f);
            let Ok(mut b) = std::fs::read(&p) else {
                return format!("{f} already gone");
            };
            if b.is_empty() {
                return format!("{f} empty");
            }
            let i = rng.index(b.len());
            b[i] ^= 1 << rng.below(8);
            std::fs::write(&p, &b).unwrap();
            format!("{f} byte {i} flipped")
        }
        4 => {
            let f = *rng.pick(FILES);
            let _ = std::fs::remove_file(dir.join(f));
            format!("{f} removed")
        }
        5 => {
            // An .npy's header claims another shape (same length, so only its dict).
            let f = *rng.pick(&FILES[1..5]);
            let p = dir.join(f);
            let Ok(b) = std::fs::read(&p) else {
                return format!("{f} already gone");
            };
            let t = String::from_utf8_lossy(&b[..b.len().min(128)]).into_owned();
            let dims = *rng.pick(&[
                "(4294967296, 1, 8)",
                "(0, 3)",
                "(1, 2, 18446744073709551615)",
                "(2, 3)",
            ]);
            let Some(at) = t.find("'shape': (") else {
                return format!("{f} has no shape");
            };
            let end = t[at..].find(')').map_or(at, |e| at + e + 1);
            let mut new = t[..at].to_string() + "'shape': " + dims + &t[end..];
            new.truncate(t.len().min(new.len()));
            let mut out = new.into_bytes();
            out.resize(t.len(), b' ');
            out.extend_from_slice(&b[t.len()..]);
            std::fs::write(&p, out).unwrap();
            format!("{f} header shape {dims}")
        }
        _ => {
            let big = vec![b'0'; rng.index(1 << 16)];
            let f = *rng.pick(FILES);
            let mut b = std::fs::read(dir.join(f)).unwrap_or_default();
            b.extend_from_slice(&big);
            std::fs::write(dir.join(f), b).unwrap();
            format!("{f} grown by {} bytes", big.len())
        }
    }
}

fn listing_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .filter(|(n, _)| n != "summary.json" && n != "tofprobe-set.toml")
        .collect();
    v.sort();
    v
}

#[test]
fn tampered_tile_sets_are_refused_or_merge_into_the_reference_set() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let sets: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = tmp.path().join(format!("s{i}"));
            let (c, e) = run(
                &[
                    "simulate",
                    cfg.to_str().unwrap(),
                    "--out",
                    d.to_str().unwrap(),
                    "--shard",
                    &format!("{i}/2"),
                ],
                Duration::from_secs(60),
            )
            .unwrap();
            assert_eq!(c, Some(0), "{e}");
            d
        })
        .collect();
    let reference = tmp.path().join("reference");
    let (c, e) = run(
        &[
            "merge",
            sets[0].to_str().unwrap(),
            sets[1].to_str().unwrap(),
            "--out",
            reference.to_str().unwrap(),
        ],
        Duration::from_secs(60),
    )
    .unwrap();
    assert_eq!(c, Some(0), "{e}");
    let want = listing_bytes(&reference);
    let mut rng = Rng(0x45_5e75_2026);
    let (mut refused, mut merged, mut whole_sets) = (0, 0, 0);
    let mut failures = Vec::new();
    let n = cases();
    for case in 0..n {
        let which = rng.index(2);
        let bad = tmp.path().join(format!("bad{case}"));
        copy_dir(&sets[which], &bad);
        let mut what: Vec<String> = (0..1 + rng.below(3))
            .map(|_| tamper(&mut rng, &bad))
            .collect();
        if rng.chance(50) {
            reseal(&bad);
            what.push("marker re-sealed".into());
        }
        let out = tmp.path().join(format!("out{case}"));
        let mut args = vec!["merge".to_string()];
        for (i, s) in sets.iter().enumerate() {
            args.push(
                if i == which { bad.clone() } else { s.clone() }
                    .to_str()
                    .unwrap()
                    .into(),
            );
        }
        args.extend(["--out".into(), out.to_str().unwrap().into()]);
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        match run(&a, Duration::from_secs(30)) {
            Err(hang) => failures.push(format!("case {case} {what:?}: {hang}")),
            Ok((Some(0), _)) => {
                merged += 1;
                if listing_bytes(&out) != want {
                    failures.push(format!(
                        "case {case} {what:?}: merged a set unlike the reference"
                    ));
                }
            }
            Ok((Some(2), e)) if e.contains("tile set") && !e.contains("panicked") => refused += 1,
            Ok((code, e)) => {
                failures.push(format!("case {case} {what:?}: merge exit {code:?}: {e}"))
            }
        }
        match run(
            &["check-set", bad.to_str().unwrap()],
            Duration::from_secs(30),
        ) {
            Err(hang) => failures.push(format!("case {case} check-set: {hang}")),
            Ok((Some(0), _)) => {
                whole_sets += 1;
                let listed = std::fs::read_to_string(bad.join("tofprobe-set.toml"))
                    .ok()
                    .and_then(|t| tofprobe_io::marker::marker_files(&t))
                    .unwrap_or_default();
                let all_hold = !listed.is_empty()
                    && listed.iter().all(|(f, h)| {
                        tofprobe_io::marker::hash_file(&bad.join(f)).is_ok_and(|x| x == *h)
                    });
                if !all_hold {
                    failures.push(format!("case {case} {what:?}: check-set passed a torn set"));
                }
            }
            Ok((Some(2), e)) if e.contains("is not a whole output set") => {}
            Ok((code, e)) => failures.push(format!(
                "case {case} {what:?}: check-set exit {code:?}: {e}"
            )),
        }
    }
    eprintln!(
        "tile-set tampering: {n} cases: merge refused {refused} (naming the set), merged {merged} (each the reference set); check-set passed {whole_sets}; {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// 64-bit edges of the numeric options.
const NUMBERS: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "4",
    "4294967295",
    "4294967296",
    "4294967297",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "-1",
    "",
    "x",
    "1e3",
];

#[test]
fn numeric_options_at_64_bit_edges_exit_0_or_2() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let cfg = cfg.to_str().unwrap();
    let mut rng = Rng(0x7113_2026);
    let (mut ok, mut refused) = (0, 0);
    let mut failures = Vec::new();
    let out = tmp.path().join("o");
    let out = out.to_str().unwrap();
    // Six runs a case, each resolving the configuration (≈ 0.15 s): a third of the cases.
    for case in 0..cases().div_ceil(3) {
        let mut pick = || rng.pick(NUMBERS).to_string();
        let tile = format!("--tile={},{},{},{}", pick(), pick(), pick(), pick());
        let shard = format!("--shard={}/{}", pick(), pick());
        let gib = format!("--max-out-gib={}", pick());
        let frames = format!("--frames={}", pick());
        let pulses = format!("--frame-pulses={}", pick());
        let depth = format!("--rom-depth={}", pick());
        let runs: Vec<Vec<&str>> = vec![
            vec!["cosim", cfg, &tile, "--out", out],
            vec!["simulate", cfg, "--out", out, &shard],
            vec!["simulate", cfg, "--out", out, &gib],
            vec!["cosim", cfg, &frames, "--tile=0,0,1,1", "--out", out],
            vec!["vectors", &pulses, "--out", out],
            vec!["rtl", &depth, "--out", out],
        ];
        for args in runs {
            match run(&args, Duration::from_secs(60)) {
                Err(hang) => failures.push(format!("case {case} {args:?}: {hang}")),
                Ok((Some(0), _)) => ok += 1,
                Ok((Some(2), e)) if !e.contains("panicked") => refused += 1,
                Ok((code, e)) => failures.push(format!("case {case} {args:?}: exit {code:?}: {e}")),
            }
        }
    }
    eprintln!(
        "numeric options at 64-bit edges: {ok} exit 0, {refused} exit 2, {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
