//! Runs `scripts/tttr-crosscheck.sh`: our decoder against ptufile and phconvert's SPC
//! algorithm on the real files (a cached venv; the first run installs from PyPI). Skipped,
//! with a message, only when python3 is missing, and never under CI (tofprobe_testkit::tools).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `tttr_dump` example `cargo test` built beside this test's binary.
fn dump_binary() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap(); // target/<profile>/
    dir.join("examples")
        .join(format!("tttr_dump{}", std::env::consts::EXE_SUFFIX))
}

#[test]
fn decoder_agrees_with_ptufile_and_phconvert() {
    if !tofprobe_testkit::tools::have(&["python3"], "the cross-check with ptufile") {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dump = dump_binary();
    let mut cmd = Command::new("bash");
    cmd.arg(root.join("scripts/tttr-crosscheck.sh"))
        .current_dir(&root);
    // `cargo test --workspace` builds the example; a targeted `--test` run does not, and
    // then the script builds it (cargo's build lock is free while tests run).
    if dump.exists() {
        cmd.env("TTTR_DUMP", &dump);
    }
    let out = cmd.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success() && stdout.contains("all 6 files agree"),
        "tttr-crosscheck failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}
