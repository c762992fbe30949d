//! The committed generated files are what the CLI makes of the embedded default today:
//! `rtl/` (with the default's periodic ΣΔ probe ROM) and the short-frame set under
//! `testbench/default-short/` are regenerated with the commands in their headers (the
//! same three as scripts/check-generated.sh) and compared byte for byte, file set
//! included. The first differing file and line are reported.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run(cwd: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run tofprobe");
    assert!(
        out.status.success(),
        "tofprobe {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn same_dir(fresh: &Path, committed: &Path) {
    assert_eq!(
        files(fresh),
        files(committed),
        "{}: file set",
        committed.display()
    );
    for name in files(fresh) {
        let a = std::fs::read_to_string(fresh.join(&name)).expect("fresh");
        let b = std::fs::read_to_string(committed.join(&name)).expect("committed");
        if a != b {
            let line = a
                .lines()
                .zip(b.lines())
                .position(|(x, y)| x != y)
                .map_or(a.lines().count().min(b.lines().count()) + 1, |i| i + 1);
            panic!(
                "{}/{name} differs from a fresh run at line {line}: regenerate with the \
                 command in its header (or scripts/check-generated.sh)",
                committed.display()
            );
        }
    }
}

#[test]
fn committed_rtl_and_short_vectors_regenerate_byte_for_byte() {
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("committed-regen");
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).expect("tmp");
    run(&tmp, &["rtl", "--out", "rtl"]);
    run(
        &tmp,
        &[
            "rtl",
            "--out",
            "testbench/default-short/rtl",
            "--frame-pulses",
            "64",
            "--core-vectors",
            "testbench/default-short/vectors",
            "--core-testbench",
            "testbench/tb.v",
        ],
    );
    run(
        &tmp,
        &[
            "vectors",
            "--out",
            "testbench/default-short/vectors",
            "--frame-pulses",
            "64",
            "--frames",
            "2",
            "--seed",
            "1",
        ],
    );
    same_dir(&tmp.join("rtl"), &root().join("rtl"));
    same_dir(
        &tmp.join("testbench/default-short/rtl"),
        &root().join("testbench/default-short/rtl"),
    );
    same_dir(
        &tmp.join("testbench/default-short/vectors"),
        &root().join("testbench/default-short/vectors"),
    );
    // The committed chip ROM is the default's ΣΔ ROM, not a placeholder: 20,000 entries
    // of 32 bits, and a clean wrap recorded in its header.
    let hex = std::fs::read_to_string(root().join("rtl/tofprobe_probe_rom.hex")).expect("hex");
    assert!(hex.contains("ΣΔ probe ROM (periodic rectangular") && hex.contains("wrap clean"));
    let entries: Vec<&str> = hex
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .collect();
    assert_eq!(entries.len(), 20_000);
    assert!(entries.iter().all(|e| e.len() == 8));
    // Its manifest loads the committed image (content hash checked) and carries what a
    // readout needs to be normalised.
    let (m, image) =
        tofprobe_dsp::rom::RomManifest::read(&root().join("rtl/tofprobe_probe_rom.toml"))
            .expect("the committed ROM manifest reads");
    assert_eq!((image.depth(), image.registers()), (20_000, 32));
    assert_eq!(
        (m.mode.as_str(), m.window.as_str()),
        ("periodic", "rectangular")
    );
    assert_eq!(m.bin_indices.len(), 16);
    assert_eq!((m.bin_indices[0], m.bin_frequencies_hz[0]), (9, 4500.0));
    assert_eq!((m.amplitude, m.coherent_gain), (0.5, 1.0));
    assert!(m.wrap_clean && m.wrap_error_ratio > 0.0 && m.wrap_error_ratio <= 0.05);
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The committed 2 × 2 array example (`testbench/array-2x2/`) regenerates byte for byte
/// with the commands in its headers (the two of scripts/check-generated.sh), and replays
/// bit-exactly under Icarus with the committed testbench.
#[test]
fn committed_array_example_regenerates_and_replays() {
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("committed-array-regen");
    let _ = std::fs::remove_dir_all(&tmp);
    let ex = "testbench/array-2x2";
    std::fs::create_dir_all(tmp.join(ex)).expect("tmp");
    let cfg = format!("{ex}/array-2x2.toml");
    std::fs::copy(root().join(&cfg), tmp.join(&cfg)).expect("config");
    let rtl = format!("{ex}/rtl");
    let vec = format!("{ex}/vectors");
    let short = ["--frame-pulses", "16", "--rom-depth", "16"];
    run(&tmp, &[&["rtl", &cfg, "--out", &rtl][..], &short].concat());
    run(
        &tmp,
        &[
            &["vectors", &cfg, "--out", &vec][..],
            &short,
            &["--frames", "2"],
        ]
        .concat(),
    );
    same_dir(&tmp.join(&rtl), &root().join(&rtl));
    same_dir(&tmp.join(&vec), &root().join(&vec));
    let core = std::fs::read_to_string(root().join(&rtl).join("tofprobe.core")).expect("core");
    assert!(core.contains("toplevel: tofprobe_array"), "{core}");
    if tofprobe_testkit::tools::have(&["iverilog", "vvp"], "committed array example") {
        let dir = root().join(&rtl);
        // The RTL: the set's verification kit carries its own copy of the testbench
        // (crates/cli/tests/it/array_kit.rs runs it); here the repository's replays the
        // vectors directory.
        let mut sources: Vec<String> = files(&dir)
            .into_iter()
            .filter(|n| n.ends_with(".v") && n != "array_tb.v")
            .collect();
        sources.sort();
        let exe = tmp.join("tb.vvp");
        let out = Command::new("iverilog")
            .current_dir(&dir)
            .args(["-g2005", "-o"])
            .arg(&exe)
            .args([
                "-I",
                "../vectors",
                "-DAR_VECTORS=\"../vectors/\"",
                "../../array_tb.v",
            ])
            .args(&sources)
            .output()
            .expect("iverilog");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = Command::new("vvp")
            .current_dir(&dir)
            .arg("-n")
            .arg(&exe)
            .output()
            .expect("vvp");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains("TOFPROBE-COSIM-DONE cycles=218 mismatches=0"),
            "{text}"
        );
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
