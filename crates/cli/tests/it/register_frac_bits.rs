//! `[pixel] register_frac_bits = G` through the binary (issue 16, point 1b): the registers
//! add x >>> (F − G) instead of x. A G = 2 pixel (F = 8) renders registers F − G = 6 bits
//! narrower than the default's, at the width the sizing's closed form gives, co-simulates
//! bit-exact under Verilator, and the same RTL with the operand slice one bit off fails
//! under Icarus at a reported cycle; G > F and Haar + G are refused naming the key. The
//! operand's floor and its mean bias are checked in crates/pixel/tests/numerics.rs.

use crate::common;

use std::path::{Path, PathBuf};

use common::{default_text, edit, have_tools, tofprobe};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-gbits-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn config_with_g(dir: &Path, g: &str) -> PathBuf {
    let text = edit(
        default_text(),
        &[(
            "adders = 2 ",
            &format!("register_frac_bits = {g}\nadders = 2 "),
        )],
    );
    let p = dir.join(format!("g{g}.toml"));
    std::fs::write(&p, text).expect("write config");
    p
}

/// The register width W a rendered pixel declares (`reg [W-1:0] y [...]`).
fn rendered_width(pixel: &str) -> u32 {
    let line = pixel
        .lines()
        .find(|l| l.trim_start().starts_with("reg [") && l.contains(" y ["))
        .unwrap_or_else(|| panic!("no register file in the rendered pixel"));
    let msb: u32 = line.trim_start()["reg [".len()..]
        .split(':')
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    msb + 1
}

/// The default width's closed form: the whole window (codes 0..=79, zoom 0) over the
/// configured N = 10^7 pulses of any sign, operands of 79·2^G: a sum of magnitude up to
/// N·79·2^G, plus a sign bit.
fn closed_form_width(g: u32) -> u32 {
    let bound: u64 = (10_000_000 * 79) << g;
    (64 - bound.leading_zeros()) + 1
}

fn run(args: &[String]) -> (Option<i32>, String) {
    let o = tofprobe(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    (o.status.code(), text)
}

#[test]
fn narrower_registers_cosimulate_and_a_wrong_slice_does_not() {
    let dir = scratch("cosim");
    // The default (G = F = 8) rendered for the same short frame: the reference width.
    let (code, text) = run(&[
        "rtl".into(),
        "--out".into(),
        dir.join("rtl-default").to_str().unwrap().into(),
        "--frame-pulses".into(),
        "2000".into(),
    ]);
    assert_eq!(code, Some(0), "{text}");
    let default_pixel =
        std::fs::read_to_string(dir.join("rtl-default/tofprobe_pixel.v")).expect("pixel");
    let w_default = rendered_width(&default_pixel);
    assert_eq!(w_default, closed_form_width(8));
    assert!(
        !default_pixel.contains("op_new"),
        "the default keeps op <= x_new"
    );

    if !have_tools(&["verilator", "iverilog"]) {
        return;
    }
    let cfg = config_with_g(&dir, "2");
    let out_dir = dir.join("out");
    let args = |out: &Path, simulator: &str| -> Vec<String> {
        vec![
            "cosim".into(),
            cfg.to_str().unwrap().into(),
            "--frame-pulses".into(),
            "2000".into(),
            "--frames".into(),
            "2".into(),
            "--simulator".into(),
            simulator.into(),
            // The verdict and first mismatch only: no traced Verilator build for a VCD.
            "--no-vcd".into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let (code, text) = run(&args(&out_dir, "verilator"));
    assert!(code == Some(0) && text.contains("cosim PASS"), "{text}");
    let pixel =
        std::fs::read_to_string(out_dir.join("rtl/tofprobe_pixel.v")).expect("rendered pixel");
    // 33 = 39 − 6: every register F − G bits narrower, at the sizing's width.
    let w = rendered_width(&pixel);
    assert_eq!(w, closed_form_width(2));
    assert_eq!(w, w_default - 6);
    assert!(pixel.contains(", G=2)."), "the header names G");
    // x keeps T+1+F = 16 bits; the operand is its top T+1+G = 10.
    let slice = "wire [9:0] op_new = x_new[15:6];";
    assert!(pixel.contains(slice), "{pixel}");
    assert!(pixel.contains("reg [15:0] x;") && pixel.contains("reg [9:0] op;"));

    // The slice one bit low (bits 14:5: the operand doubled and its sign lost): the
    // co-simulation must catch it at a cycle.
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    for e in std::fs::read_dir(out_dir.join("rtl")).unwrap().flatten() {
        std::fs::copy(e.path(), broken.join(e.file_name())).unwrap();
    }
    let wrong = pixel.replace(slice, "wire [9:0] op_new = x_new[14:5];");
    std::fs::write(broken.join("tofprobe_pixel.v"), wrong).unwrap();
    let mut a = args(&dir.join("out-broken"), "icarus");
    a.extend(["--rtl".to_string(), broken.to_str().unwrap().to_string()]);
    let (code, text) = run(&a);
    assert_eq!(code, Some(1), "{text}");
    // At the first operand it adds: ρ_s = 1, so pulse 0 primes (and adds nothing), pulse 1
    // is accepted at edge 2 + C = 18 (two reset cycles) and its slot 0 writes y[0] at 19.
    assert!(
        text.contains("cosim FAIL at cycle 19 (pulse 1): y[0]"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn g_above_f_and_haar_g_are_refused() {
    let dir = scratch("refused");
    let cfg = config_with_g(&dir, "9");
    let (code, err) = run(&["config".into(), cfg.to_str().unwrap().into()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("pixel.register_frac_bits = 9") && err.contains("0..=8"),
        "{err}"
    );

    let text = edit(
        default_text(),
        &[
            ("mode = \"fourier\"", "mode = \"haar\""),
            ("adders = 2 ", "register_frac_bits = 2\nadders = 2 "),
            ("duration_s = 1.0", "pulses = 65536"),
            ("rom_depth = 20000", "rom_depth = 16384"),
        ],
    );
    let p = dir.join("haar.toml");
    std::fs::write(&p, text).unwrap();
    let (code, err) = run(&["config".into(), p.to_str().unwrap().into()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("pixel.register_frac_bits") && err.contains("Haar"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
