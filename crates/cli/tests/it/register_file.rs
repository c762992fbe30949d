//! `[pixel] register_file = "clock_gated"` through the binary (issue 16, point 1c): the
//! rendered pixel clocks each register by a latch-based clock gate on its write enable
//! (no enable multiplexer) and co-simulates bit-exact against the unchanged models, in
//! Verilator and in Icarus; the same RTL with a broken clock gate — the enable not latched
//! (the gate glitches when the enable rises while clk is high), or a register gated by
//! another register's enable — fails at the first edge it writes wrongly, which the
//! harness reports as a register that changed without its write enable. The same for
//! `register_file = "latch"` (issue 30 point 4), Fourier and Haar: the latches are written
//! in clk's low phase from words captured at the edge, observed at the falling edge after
//! it; latches opened in the high phase, or gated by the unregistered enable, fail.

use crate::common;

use std::path::{Path, PathBuf};

use common::{default_text, edit, have_tools, tofprobe};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-regfile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn clock_gated_config(dir: &Path) -> PathBuf {
    kind_config(dir, "clock_gated")
}

/// The default with `register_file = kind`.
fn kind_config(dir: &Path, kind: &str) -> PathBuf {
    let text = edit(
        default_text(),
        &[(
            "adders = 2 ",
            &format!("register_file = \"{kind}\"\nadders = 2 "),
        )],
    );
    let p = dir.join(format!("{kind}.toml"));
    std::fs::write(&p, text).expect("write config");
    p
}

/// A Haar pixel (U = 2: 7 registers, A = 2) with latch registers.
fn haar_latch_config(dir: &Path) -> PathBuf {
    let text = edit(
        default_text(),
        &[
            ("duration_s = 1.0 ", "pulses = 16384 "),
            ("mode = \"fourier\"", "mode = \"haar\"\nhaar_scales = 2"),
            ("shift = 5", ""),
            ("frac_bits = 8", ""),
            ("adders = 2 ", "register_file = \"latch\"\nadders = 2 "),
        ],
    );
    let p = dir.join("haar_latch.toml");
    std::fs::write(&p, text).expect("write config");
    p
}

/// `tofprobe cosim` of `cfg` (N pulses per frame, 2 frames) into `out`, on `rtl` when given.
fn cosim(cfg: &Path, n: u32, out: &Path, rtl: Option<&Path>, simulator: &str) -> (i32, String) {
    let mut a = vec![
        "cosim".to_string(),
        cfg.to_str().unwrap().to_string(),
        "--frame-pulses".into(),
        n.to_string(),
        "--frames".into(),
        "2".into(),
        "--simulator".into(),
        simulator.into(),
        // The verdict and first mismatch only: no traced Verilator build for a VCD.
        "--no-vcd".into(),
        "--out".into(),
        out.to_str().unwrap().to_string(),
    ];
    if let Some(r) = rtl {
        a.extend(["--rtl".to_string(), r.to_str().unwrap().to_string()]);
    }
    let o = tofprobe(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    (o.status.code().unwrap_or(-1), text)
}

/// A copy of `rtl` in `to` with `from` replaced by `with` in the pixel (exactly once).
fn broken_copy(rtl: &Path, to: &Path, from: &str, with: &str) -> PathBuf {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(rtl).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    let pixel = std::fs::read_to_string(rtl.join("tofprobe_pixel.v")).unwrap();
    assert_eq!(pixel.matches(from).count(), 1, "`{from}` in the pixel");
    std::fs::write(to.join("tofprobe_pixel.v"), pixel.replace(from, with)).unwrap();
    to.to_path_buf()
}

/// The cycle of `cosim FAIL at cycle C` and the signal after it.
fn failure(text: &str) -> (u64, String) {
    let rest = text
        .split("cosim FAIL at cycle ")
        .nth(1)
        .unwrap_or_else(|| panic!("no failure reported: {text}"));
    let cycle = rest.split_whitespace().next().unwrap().parse().unwrap();
    let signal = rest
        .split("): ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap();
    (cycle, signal.to_string())
}

#[test]
fn clock_gated_register_file_cosimulates_and_a_broken_gate_does_not() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("verilator");
    let cfg = clock_gated_config(&dir);
    let out = dir.join("out");
    let (code, text) = cosim(&cfg, 1000, &out, None, "verilator");
    assert!(code == 0 && text.contains("cosim PASS"), "{text}");
    let pixel = std::fs::read_to_string(out.join("rtl/tofprobe_pixel.v")).expect("pixel");
    // 32 registers, each on its own gated clock, none behind an enable multiplexer.
    assert_eq!(pixel.matches("tofprobe_pixel_clock_gate cg_").count(), 32);
    assert_eq!(pixel.matches("always @(posedge gclk_").count(), 32);
    assert!(!pixel.contains("if (we["), "an enable multiplexer is left");
    assert!(pixel.contains("// Register file: clock_gated"), "header");

    // The enable not latched: the gate follows `we` while clk is high, so the enable that
    // rises after the edge which starts pulse 1's first slot clocks register 0 in mid-cycle.
    let rtl = out.join("rtl");
    let unlatched = broken_copy(
        &rtl,
        &dir.join("unlatched"),
        "assign gclk = clk & en_l;",
        "assign gclk = clk & en;",
    );
    let (code, text) = cosim(&cfg, 1000, &dir.join("o1"), Some(&unlatched), "verilator");
    assert_eq!(code, 1, "{text}");
    // Pulse 0 only primes (no accumulate); pulse 1 writes registers 0 and 1 from cycle 18 on
    // (measured; the cycle model puts the same write there).
    assert_eq!(failure(&text), (18, "y[0]".to_string()), "{text}");

    // Register 1 gated by register 2's enable: it loads in register 2's slot.
    let wrong = broken_copy(
        &rtl,
        &dir.join("wrong"),
        "cg_1 (.clk(clk), .en(we[1] | rst)",
        "cg_1 (.clk(clk), .en(we[2] | rst)",
    );
    let (code, text) = cosim(&cfg, 1000, &dir.join("o2"), Some(&wrong), "verilator");
    assert_eq!(code, 1, "{text}");
    assert_eq!(failure(&text), (19, "y[1]".to_string()), "{text}");
}

#[test]
fn clock_gated_register_file_passes_in_icarus_and_a_glitching_gate_does_not() {
    if !have_tools(&["verilator", "iverilog", "vvp"]) {
        return;
    }
    let dir = scratch("icarus");
    let cfg = clock_gated_config(&dir);
    let out = dir.join("out");
    let (code, text) = cosim(&cfg, 200, &out, None, "icarus");
    assert!(code == 0 && text.contains("cosim PASS"), "{text}");
    let unlatched = broken_copy(
        &out.join("rtl"),
        &dir.join("unlatched"),
        "assign gclk = clk & en_l;",
        "assign gclk = clk & en;",
    );
    let (code, text) = cosim(&cfg, 200, &dir.join("o1"), Some(&unlatched), "icarus");
    assert_eq!(code, 1, "{text}");
    assert_eq!(failure(&text), (18, "y[0]".to_string()), "{text}");
}

#[test]
fn latch_register_file_cosimulates_and_latches_open_in_the_wrong_phase_do_not() {
    if !have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("latch");
    let cfg = kind_config(&dir, "latch");
    let out = dir.join("out");
    let (code, text) = cosim(&cfg, 1000, &out, None, "verilator");
    assert!(code == 0 && text.contains("cosim PASS"), "{text}");
    let pixel = std::fs::read_to_string(out.join("rtl/tofprobe_pixel.v")).expect("pixel");
    // 32 registers of latches, each behind its own gate on the inverted clock, none a flop.
    assert_eq!(pixel.matches("tofprobe_pixel_clock_gate cg_").count(), 32);
    assert_eq!(pixel.matches(".clk(clk_n), .en(we_q[").count(), 32);
    assert_eq!(pixel.matches("] = wd_").count(), 32);
    assert!(!pixel.contains("if (we["), "an enable multiplexer is left");
    assert!(!pixel.contains("y[0] <="), "a register is still a flop");
    assert!(pixel.contains("// Register file: latch"), "header");

    let rtl = out.join("rtl");
    // Latches open in the high phase after the edge (the gate on clk, not its inverse):
    // register 0 is written one edge late, with the word of the edge before. Pulse 1 writes
    // registers 0 and 1 from cycle 18 on (its first word to register 0 is 0, so the first
    // wrong value shows at cycle 19; measured, the cycle model puts the writes there).
    let high = broken_copy(
        &rtl,
        &dir.join("high"),
        "wire clk_n = ~clk;",
        "wire clk_n = clk;",
    );
    let (code, text) = cosim(&cfg, 1000, &dir.join("o1"), Some(&high), "verilator");
    assert_eq!(code, 1, "{text}");
    assert_eq!(failure(&text), (19, "y[0]".to_string()), "{text}");
    // Register 1's gate fed the enable of the coming edge instead of the last one: it opens
    // a cycle early, at the edge its write is decided, and shows a write `we` does not.
    let early = broken_copy(&rtl, &dir.join("early"), ".en(we_q[1])", ".en(we[1])");
    let (code, text) = cosim(&cfg, 1000, &dir.join("o2"), Some(&early), "verilator");
    assert_eq!(code, 1, "{text}");
    assert_eq!(failure(&text), (18, "y[1]".to_string()), "{text}");

    // Haar (7 registers, 2 adders) bit-exact too.
    let (code, text) = cosim(
        &haar_latch_config(&dir),
        256,
        &dir.join("haar"),
        None,
        "verilator",
    );
    assert!(code == 0 && text.contains("cosim PASS"), "{text}");
}

#[test]
fn latch_register_file_passes_in_icarus_and_latches_open_in_the_high_phase_do_not() {
    if !have_tools(&["verilator", "iverilog", "vvp"]) {
        return;
    }
    let dir = scratch("latch-icarus");
    let cfg = kind_config(&dir, "latch");
    let out = dir.join("out");
    let (code, text) = cosim(&cfg, 200, &out, None, "icarus");
    assert!(code == 0 && text.contains("cosim PASS"), "{text}");
    let high = broken_copy(
        &out.join("rtl"),
        &dir.join("high"),
        "wire clk_n = ~clk;",
        "wire clk_n = clk;",
    );
    let (code, text) = cosim(&cfg, 200, &dir.join("o1"), Some(&high), "icarus");
    assert_eq!(code, 1, "{text}");
    assert_eq!(failure(&text), (19, "y[0]".to_string()), "{text}");
}

/// osu018's liberty without its `LATCH` cell (and it has no integrated clock gate): a
/// clock-gated pixel cannot be built from it, and `tofprobe size` says so naming the
/// option and the missing function, before any area is reported.
#[test]
fn a_liberty_without_latch_or_clock_gate_is_refused_naming_the_option() {
    if !have_tools(&["yosys"]) {
        return;
    }
    let dir = scratch("nolatch");
    let text = std::fs::read_to_string("/usr/share/qflow/tech/osu018/osu018_stdcells.lib")
        .expect("osu018 liberty");
    let start = text.find("cell (LATCH)").expect("osu018 has a LATCH cell");
    // The cell's group ends at the brace that balances its first one.
    let open = start + text[start..].find('{').unwrap();
    let mut depth = 0;
    let mut end = open;
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    end = open + i + 1;
                    break;
                }
            }
            _ => {}
        }
    }
    let lib = dir.join("nolatch.lib");
    std::fs::write(&lib, format!("{}{}", &text[..start], &text[end..])).unwrap();
    let cfg = clock_gated_config(&dir);
    let out = tofprobe(&[
        "size",
        cfg.to_str().unwrap(),
        "--no-sky130",
        "--sweep-bins",
        "16",
        "--sweep-widths",
        "39",
        "--liberty",
        lib.to_str().unwrap(),
        "--cache",
        dir.join("cache").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for part in ["register_file", "clock_gated", "latch", "nolatch.lib"] {
        assert!(err.contains(part), "`{part}` missing from: {err}");
    }
}
