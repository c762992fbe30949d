//! The array RTL's own structure lints in time about linear in R × C: a 64 × 64 array whose
//! pixel is a stub lints clean under `verilator --lint-only -Wall` within a CPU budget that
//! a structure folded in time superlinear in R × C overruns (docs/performance.md "The array
//! RTL at scale"; the whole array, pixels and all, at 256 × 256 is `scripts/array-lint.sh
//! 256 256`, minutes and gigabytes: not a test).

use std::process::Command;

use tofprobe_pixel::PixelParams;
use tofprobe_rtlgen::array::{ArraySpec, array_module_name};
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, array::render_array};

/// A stub of the rendered pixel `text`: its ports verbatim, every output a register (or for
/// `ready`, a wire) of the XOR of every input but the clock, so the array's logic on the
/// pixels' outputs stays live (a constant output would be folded away, and with it the
/// structure under test) while the pixel's own logic is out of the measurement.
fn stub(text: &str) -> String {
    let start = text.find("module ").expect("a module");
    let end = start + text[start..].find(");").expect("a port list") + 2;
    let ports = &text[start..end];
    let mut inputs = Vec::new();
    let mut body = String::new();
    for line in ports.lines().map(str::trim) {
        let decl = line.trim_end_matches(',');
        let name = decl.split_whitespace().last().unwrap_or_default();
        // The width `[N:0]` of a vector port, or 1.
        let width = decl
            .split_once('[')
            .and_then(|(_, r)| r.split_once(':'))
            .and_then(|(n, _)| n.trim().parse::<u32>().ok())
            .map_or(1, |n| n + 1);
        if decl.starts_with("input") && name != "clk" {
            inputs.push(name.to_string());
        } else if decl.starts_with("output wire") {
            body.push_str(&format!("    assign {name} = h;\n"));
        } else if decl.starts_with("output reg") {
            body.push_str(&format!(
                "    always @(posedge clk) {name} <= {{{width}{{h}}}};\n"
            ));
        }
    }
    format!(
        "{ports}\n    wire h = ^{{{}}};\n{body}endmodule\n",
        inputs.join(", ")
    )
}

/// The CPU seconds (user + system) of `verilator` linting `sources` in `dir`, through the
/// shell's `times` (this command's children alone, whatever else the test binary runs).
fn lint_cpu_seconds(dir: &std::path::Path, sources: &[String]) -> (bool, String, f64) {
    let script = format!(
        "verilator --lint-only -Wall --top-module {} {} 2>&1; s=$?; times; exit $s",
        array_module_name(DEFAULT_MODULE_PREFIX),
        sources.join(" ")
    );
    let out = Command::new("sh")
        .current_dir(dir)
        .args(["-c", &script])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    // `times`: the shell's user and system time, then its children's ("0m13.20s 0m0.41s").
    let secs = |f: &str| -> f64 {
        let (m, s) = f.trim_end_matches('s').split_once('m').unwrap();
        m.parse::<f64>().unwrap() * 60.0 + s.parse::<f64>().unwrap()
    };
    let children = text.lines().last().unwrap_or_default().to_string();
    let cpu: f64 = children.split_whitespace().map(secs).sum();
    let n = text.lines().count().saturating_sub(2);
    let lint = text.lines().take(n).collect::<Vec<_>>().join("\n");
    (out.status.success(), lint, cpu)
}

/// A 64 × 64 array of a stub pixel lints clean in under 60 CPU-s. Measured: about 18 CPU-s
/// with `ready` the AND of the rows' ANDs (4.4 s at 32 × 32, 84 s at 128 × 128: linear);
/// with it one AND over the 4096 pixels' (Verilator folds one such expression in time cubic
/// in its inputs) this test measured 137 CPU-s and failed. The bound is three times the
/// linear figure — a loaded machine's slowdown of CPU time stays within it — and well
/// under the cubic one.
#[test]
fn a_64_by_64_array_lints_in_time_linear_in_its_pixels() {
    if !tofprobe_testkit::tools::have(&["verilator"], "tofprobe-rtlgen array scale") {
        return;
    }
    let mut p = PixelParams::fourier_default(24, 8, 8);
    // The array gates' small pixel (crates/rtlgen/tests/it/array_gates.rs).
    (p.bins, p.cycles_per_pulse, p.tdc_bits, p.frac_bits, p.shift) = (3, 4, 5, 4, 2);
    p.validate().unwrap();
    let k = p.width.div_ceil(24) as usize;
    let spec = ArraySpec {
        rows: 64,
        cols: 64,
        bits: 24,
        beats_per_word: k,
        beat_cycles: 1,
        slot_cycles: (p.registers() as u64 + 1) * k as u64,
        fault: None,
        tile: None,
        superpixel: 1,
        double_buffer: false,
    };
    let files = render_array(&p, &sign_probe_rom(&p), &RenderOptions::default(), &spec).unwrap();
    let mut pairs: Vec<(String, String)> =
        files.into_iter().map(|f| (f.name, f.contents)).collect();
    for (name, text) in &mut pairs {
        if name.ends_with("_pixel.v") {
            *text = stub(text);
        }
    }
    let dir = std::env::temp_dir().join(format!("tofprobe-array-scale-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_generated(&dir, &pairs).unwrap();
    let mut sources: Vec<String> = pairs
        .iter()
        .map(|p| p.0.clone())
        .filter(|n| n.ends_with(".v"))
        .collect();
    sources.sort();
    let (ok, lint, cpu) = lint_cpu_seconds(&dir, &sources);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(ok && lint.trim().is_empty(), "{lint}");
    assert!(
        cpu < 60.0,
        "64 × 64 lint took {cpu:.1} CPU-s (linear: about 18)"
    );
}

/// The stub keeps the pixel's ports and drives every output from the inputs.
#[test]
fn the_stub_keeps_the_pixels_ports() {
    let text = "// header\nmodule tofprobe_pixel (\n    input  wire clk,\n    input  wire [6:0] tdc,\n    output wire ready,\n    output reg  [2:0] rd_index\n);\n    wire x;\nendmodule\n";
    let s = stub(text);
    assert!(
        s.starts_with("module tofprobe_pixel (\n    input  wire clk,"),
        "{s}"
    );
    assert!(s.contains("wire h = ^{tdc};"), "{s}");
    assert!(s.contains("assign ready = h;"), "{s}");
    assert!(s.contains("rd_index <= {3{h}};"), "{s}");
    assert!(!s.contains("wire x;"), "{s}");
}
