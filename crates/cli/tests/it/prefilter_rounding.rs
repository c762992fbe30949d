//! `[pixel] prefilter_rounding = "nearest"` through the binary (issue 16's first option):
//! the rendered pixel adds 2^(S−1) before the prefilter's shift and co-simulates bit-exact
//! against the model; the same RTL with the rounding constant removed (what a floor pixel
//! computes) fails at the first pulse the two roundings differ; Haar mode, which has no
//! prefilter, refuses the key. The bias it removes is measured in
//! crates/pixel/tests/numerics.rs (floor −0.0605 code, nearest +0.0020).

use crate::common;

use std::path::{Path, PathBuf};

use common::{default_text, edit, have_tools, tofprobe};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-rounding-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn nearest_config(dir: &Path) -> PathBuf {
    let text = edit(
        default_text(),
        &[(
            "adders = 2 ",
            "prefilter_rounding = \"nearest\"\nadders = 2 ",
        )],
    );
    let p = dir.join("nearest.toml");
    std::fs::write(&p, text).expect("write config");
    p
}

#[test]
fn nearest_rounding_cosimulates_and_floor_rtl_does_not() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("cosim");
    let cfg = nearest_config(&dir);
    let out_dir = dir.join("out");
    let args = |out: &Path| {
        vec![
            "cosim".to_string(),
            cfg.to_str().unwrap().to_string(),
            "--frame-pulses".into(),
            "2000".into(),
            "--frames".into(),
            "2".into(),
            // The verdict and first mismatch only: no traced Verilator build for a VCD.
            "--no-vcd".into(),
            "--out".into(),
            out.to_str().unwrap().to_string(),
        ]
    };
    let a = args(&out_dir);
    let o = tofprobe(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && text.contains("cosim PASS"), "{text}");
    let pixel =
        std::fs::read_to_string(out_dir.join("rtl/tofprobe_pixel.v")).expect("rendered pixel");
    // S = 5: 2^4 added before the shift.
    let line = pixel
        .lines()
        .find(|l| l.contains("wire") && l.contains("diff_r ="))
        .unwrap_or_else(|| panic!("no rounding adder in the nearest pixel"));
    assert!(line.trim_end().ends_with("'d16;"), "{line}");

    // The same RTL rounding by floor: the co-simulation must catch it.
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    for e in std::fs::read_dir(out_dir.join("rtl")).unwrap().flatten() {
        std::fs::copy(e.path(), broken.join(e.file_name())).unwrap();
    }
    let floor = pixel.replace(&line.to_string(), &line.replace("'d16;", "'d0;"));
    std::fs::write(broken.join("tofprobe_pixel.v"), floor).unwrap();
    let mut a = args(&dir.join("out-broken"));
    a.extend(["--rtl".to_string(), broken.to_str().unwrap().to_string()]);
    let o = tofprobe(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{text}");
    assert!(text.contains("cosim FAIL at cycle"), "{text}");
}

#[test]
fn haar_refuses_prefilter_rounding() {
    let dir = scratch("haar");
    let text = edit(
        default_text(),
        &[
            ("mode = \"fourier\"", "mode = \"haar\""),
            (
                "adders = 2 ",
                "prefilter_rounding = \"nearest\"\nadders = 2 ",
            ),
            ("duration_s = 1.0", "pulses = 65536"),
            ("rom_depth = 20000", "rom_depth = 16384"),
        ],
    );
    let p = dir.join("haar.toml");
    std::fs::write(&p, text).unwrap();
    let o = tofprobe(&["config", p.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("pixel.prefilter_rounding")
            && err.contains("\"nearest\"")
            && err.contains("\"floor\""),
        "{err}"
    );
}
