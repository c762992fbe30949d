//! `[probe] convention` through the binary (docs/probe.md): "toolbox" renders a probe
//! ROM whose manifest and summary name the convention and whose bits differ from the
//! committed default's; "tofprobe" written out is the default, bit for bit; a bad value
//! is refused naming the key, the value and the allowed values.

use crate::common;

use common::{default_text, edit, tofprobe};

/// The ROM's words, without the generated header (which names the command's paths).
fn words(hex: &str) -> Vec<&str> {
    hex.lines().filter(|l| !l.starts_with("//")).collect()
}

fn rtl(config: &str, dir: &std::path::Path) -> std::process::Output {
    let cfg = dir.join("probe.toml");
    std::fs::write(&cfg, config).expect("write config");
    let out = dir.join("rtl");
    tofprobe(&[
        "rtl",
        cfg.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ])
}

#[test]
fn the_toolbox_convention_renders_its_own_rom_and_says_so() {
    let committed = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../rtl/tofprobe_probe_rom.hex"
    );
    let committed = std::fs::read_to_string(committed).expect("committed ROM");
    let committed = words(&committed);
    let text = default_text();
    assert!(
        text.contains("convention = \"tofprobe\""),
        "the default documents the key"
    );

    let dir = tempfile::tempdir().expect("tempdir");
    let o = rtl(&text, dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let hex = std::fs::read_to_string(dir.path().join("rtl/tofprobe_probe_rom.hex")).unwrap();
    assert!(
        words(&hex) == committed,
        "the default convention must be the committed ROM"
    );
    let manifest = std::fs::read_to_string(dir.path().join("rtl/tofprobe_probe_rom.toml")).unwrap();
    assert!(!manifest.contains("convention"), "{manifest}");

    let dir = tempfile::tempdir().expect("tempdir");
    let toolbox = edit(
        text.clone(),
        &[("convention = \"tofprobe\"", "convention = \"toolbox\"")],
    );
    let o = rtl(&toolbox, dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("toolbox convention"));
    let hex = std::fs::read_to_string(dir.path().join("rtl/tofprobe_probe_rom.hex")).unwrap();
    assert!(words(&hex) != committed, "the toolbox ROM must differ");
    let manifest = std::fs::read_to_string(dir.path().join("rtl/tofprobe_probe_rom.toml")).unwrap();
    assert!(manifest.contains("convention = \"toolbox\""), "{manifest}");

    let bad = edit(
        text,
        &[("convention = \"tofprobe\"", "convention = \"numpy\"")],
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let o = rtl(&bad, dir.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("probe.convention = \"numpy\"")
            && err.contains("\"tofprobe\" (the default) or \"toolbox\""),
        "{err}"
    );
    assert!(
        !dir.path().join("rtl").exists(),
        "nothing written on a refusal"
    );
}
