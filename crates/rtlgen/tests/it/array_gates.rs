//! Quality gates on the array RTL (`templates/array.v`): `verilator --lint-only -Wall` with
//! zero warnings, `iverilog -g2005 -Wall` compiles, yosys `synth` with no latch and no
//! warning beyond the pixel's register-file note, for a 2 × 2 Fourier array on a one-word
//! port, a 1 × 1, a 1 × 7 and a 7 × 1 array, a 3 × 5 Haar array on a 5-bit port (3 beats per word), a 2 × 3 array with beats
//! 3 cycles apart, superpixel arrays (G = 2, and a tile at G = 3), double-buffered arrays
//! (Fourier, Haar: the synthesised shadow is (R+1)·W flops per pixel) and each array
//! mutant; and the renderer's refusals.

use std::path::PathBuf;
use std::process::Command;

use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::array::{ArrayFault, ArraySpec, ArrayTile, array_module_name, render_array};
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, RtlError};

fn have(tool: &str) -> bool {
    tofprobe_testkit::tools::have(&[tool], "tofprobe-rtlgen array gates")
}

fn small(mode: Mode) -> PixelParams {
    let mut p = PixelParams::fourier_default(24, 8, 8);
    p.bins = 3;
    p.cycles_per_pulse = 4;
    p.tdc_bits = 5;
    p.frac_bits = 4;
    p.shift = 2;
    if mode == Mode::Haar {
        p.mode = Mode::Haar;
        p.haar_scales = 2;
        (p.frac_bits, p.shift, p.adders, p.cycles_per_pulse, p.width) = (0, 0, 1, 3, 13);
    }
    p.validate().unwrap();
    p
}

fn spec(p: &PixelParams, rows: usize, cols: usize, bits: u32, g: u64) -> ArraySpec {
    let k = p.width.div_ceil(bits) as usize;
    ArraySpec {
        rows,
        cols,
        bits,
        beats_per_word: k,
        beat_cycles: g,
        slot_cycles: (p.registers() as u64 + 1) * k as u64 * g,
        fault: None,
        tile: None,
        superpixel: 1,
        double_buffer: false,
    }
}

fn configs() -> Vec<(String, PixelParams, ArraySpec)> {
    let f = small(Mode::Fourier);
    let h = small(Mode::Haar);
    let mut v = vec![
        ("2x2".to_string(), f.clone(), spec(&f, 2, 2, 24, 1)),
        // The degenerate shapes: one pixel, one row, one column (the counters' widths
        // bottom out at one bit).
        ("1x1".to_string(), f.clone(), spec(&f, 1, 1, 24, 1)),
        ("1x7".to_string(), f.clone(), spec(&f, 1, 7, 8, 2)),
        ("7x1-haar".to_string(), h.clone(), spec(&h, 7, 1, 13, 1)),
        ("3x5-haar-k3".to_string(), h.clone(), spec(&h, 3, 5, 5, 1)),
        ("2x3-g3".to_string(), f.clone(), spec(&f, 2, 3, 10, 3)),
        // A 64 × 64 array's far-corner tile: the whole array's sequencer and readout.
        (
            "64x64-tile".to_string(),
            f.clone(),
            ArraySpec {
                tile: Some(ArrayTile {
                    row0: 62,
                    col0: 62,
                    rows: 2,
                    cols: 2,
                }),
                ..spec(&f, 64, 64, 24, 1)
            },
        ),
        // Superpixels: 2 × 3 pixels of 2 × 2 SPADs, and a 3 × 3 tile of 3 × 3 SPADs each.
        (
            "2x3-sp2".to_string(),
            f.clone(),
            ArraySpec {
                superpixel: 2,
                ..spec(&f, 2, 3, 24, 1)
            },
        ),
        (
            "4x4-tile-sp3".to_string(),
            f.clone(),
            ArraySpec {
                superpixel: 3,
                tile: Some(ArrayTile {
                    row0: 1,
                    col0: 1,
                    rows: 3,
                    cols: 3,
                }),
                ..spec(&f, 4, 4, 24, 1)
            },
        ),
        (
            "2x2-sp2-neighbour_tdc".to_string(),
            f.clone(),
            ArraySpec {
                superpixel: 2,
                fault: Some(ArrayFault::NeighbourTdc { row: 0, col: 1 }),
                ..spec(&f, 2, 2, 24, 1)
            },
        ),
    ];
    // Double-buffered (the shadow registers and the swap): Fourier, and Haar at C = 4 (the
    // swap needs C above its 3 slots), and the shadow taken a cycle late.
    let mut h4 = h.clone();
    h4.cycles_per_pulse = 4;
    let db = |s: ArraySpec| ArraySpec {
        double_buffer: true,
        ..s
    };
    v.push(("2x2-dbuf".to_string(), f.clone(), db(spec(&f, 2, 2, 24, 1))));
    v.push((
        "3x5-haar-dbuf-k3".to_string(),
        h4.clone(),
        db(spec(&h4, 3, 5, 5, 1)),
    ));
    v.push((
        "2x2-dbuf-swap_late".to_string(),
        f.clone(),
        ArraySpec {
            fault: Some(ArrayFault::SwapLate),
            ..db(spec(&f, 2, 2, 24, 1))
        },
    ));
    for fault in [
        ArrayFault::RowLate { row: 1 },
        ArrayFault::NeighbourTdc { row: 0, col: 1 },
        ArrayFault::OrderSwap,
        ArrayFault::RowStuck { row: 0 },
    ] {
        let s = ArraySpec {
            fault: Some(fault),
            ..spec(&f, 2, 2, 24, 1)
        };
        v.push((format!("2x2-{}", fault.name()), f.clone(), s));
    }
    v
}

fn render_to(name: &str, p: &PixelParams, s: &ArraySpec) -> (PathBuf, Vec<String>) {
    let dir = std::env::temp_dir().join(format!(
        "tofprobe-array-gates-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let files = render_array(p, &sign_probe_rom(p), &RenderOptions::default(), s).unwrap();
    let pairs: Vec<(String, String)> = files.into_iter().map(|f| (f.name, f.contents)).collect();
    write_generated(&dir, &pairs).unwrap();
    let mut v: Vec<String> = pairs
        .into_iter()
        .map(|p| p.0)
        .filter(|n| n.ends_with(".v"))
        .collect();
    v.sort();
    (dir, v)
}

fn top() -> String {
    array_module_name(DEFAULT_MODULE_PREFIX)
}

#[test]
fn array_lint_iverilog_and_yosys_are_clean() {
    let (v, i, y) = (have("verilator"), have("iverilog"), have("yosys"));
    let mut flops = std::collections::HashMap::new();
    for (name, p, s) in configs() {
        let (dir, sources) = render_to(&name, &p, &s);
        if v {
            let out = Command::new("verilator")
                .current_dir(&dir)
                .args(["--lint-only", "-Wall", "--top-module", &top()])
                .args(&sources)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stderr);
            assert!(
                out.status.success() && text.trim().is_empty(),
                "{name}: {text}"
            );
        }
        if i {
            let out = Command::new("iverilog")
                .current_dir(&dir)
                .args(["-g2005", "-Wall", "-o", "/dev/null", "-s", &top()])
                .args(&sources)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stderr);
            // The pixel's `@*` over its register file is the pixel gates' business (it
            // warns, as in crates/rtlgen/tests/it/gates.rs); the array file warns nothing.
            let own: Vec<&str> = text
                .lines()
                .filter(|l| !l.starts_with("tofprobe_pixel.v:"))
                .collect();
            assert!(out.status.success() && own.is_empty(), "{name}: {text}");
        }
        // yosys on the correct arrays only (the mutants differ by a register or a wire).
        if y && s.fault.is_none() {
            let script = format!(
                "read_verilog {}; synth -top {}; select -assert-count 0 t:$dlatch t:$_DLATCH_*; tee -o stat.txt stat",
                sources.join(" "),
                top()
            );
            let out = Command::new("yosys")
                .current_dir(&dir)
                .args(["-q", "-p", &script])
                .output()
                .unwrap();
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            assert!(out.status.success(), "{name}: {text}");
            for line in text.lines().filter(|l| l.contains("Warning")) {
                assert!(
                    line.contains("Replacing memory \\y with list of registers"),
                    "{name}: {line}"
                );
            }
            // Every pixel's register file survives: at least R·C·registers·W flip-flops,
            // twice that double-buffered (the shadow is kept: the readout reads it).
            let stat = std::fs::read_to_string(dir.join("stat.txt")).unwrap();
            let dff: u64 = stat
                .lines()
                .filter(|l| {
                    l.trim_start().starts_with("$_SDFF") || l.trim_start().starts_with("$_DFF")
                })
                .filter_map(|l| l.split_whitespace().last()?.parse::<u64>().ok())
                .sum();
            let present = s.tile.map_or(s.rows * s.cols, |t| t.pixels());
            let copies = if s.double_buffer { 2 } else { 1 };
            let need = (copies * present * p.registers()) as u64 * u64::from(p.width);
            assert!(dff >= need, "{name}: {dff} flip-flops < {need}");
            flops.insert(name.clone(), (dff, p.registers(), p.width));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    // The rendered shadow costs what the size report's estimate counts: (R+1)·W flops per
    // pixel (the registers and the status word), plus the array's swap broadcast and hold
    // (b_swap, one r_swap per row, `hold` and its 1-bit `wt` here: at most 5 flops). The
    // summed `stat` lists the pixel module once, the array module's own flops, and the
    // hierarchy's total (P pixels and the array's own again): the shadow shows (1 + P)
    // times, the array's part twice.
    if let (Some(&(single, r, w)), Some(&(double, ..))) = (flops.get("2x2"), flops.get("2x2-dbuf"))
    {
        let shadow = (1 + 4) * (r as u64 + 1) * u64::from(w);
        assert!(
            (shadow..=shadow + 2 * 5).contains(&(double - single)),
            "{double} - {single} flops is not 5 × (R+1)·W = {shadow} (+ ≤ 2 × 5)"
        );
    }
}

/// The array file instantiates the one pixel module (in a generate loop over the rows and
/// columns), the one sequencer and the ROM, and nothing else of its own; the set holds no
/// single-pixel top. Its size does not grow with the array: a 256 × 256 array's file is a
/// 2 × 2's but for the digits of its parameters' defaults and its header.
#[test]
fn the_array_is_instances_of_the_one_pixel() {
    let p = small(Mode::Fourier);
    let render = |rows, cols| {
        render_array(
            &p,
            &sign_probe_rom(&p),
            &RenderOptions::default(),
            &spec(&p, rows, cols, 24, 1),
        )
        .unwrap()
    };
    let files = render(3, 5);
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "tofprobe_pixel.v",
            "tofprobe_probe_rom.v",
            "tofprobe_sequencer.v",
            "tofprobe_array.v"
        ]
    );
    let a = &files[3].contents;
    assert_eq!(a.matches("tofprobe_pixel u_pixel (").count(), 1);
    assert_eq!(a.matches("tofprobe_sequencer #(").count(), 1);
    assert_eq!(a.matches("tofprobe_probe_rom u_rom").count(), 1);
    assert_eq!(a.matches("\nmodule ").count(), 1);
    assert!(a.contains("parameter integer ROWS = 3,") && a.contains("parameter integer COLS = 5,"));
    let small_len = render(2, 2)[3].contents.len();
    let large_len = render(256, 256)[3].contents.len();
    // The defaults' digits (4 × 2 more) and the header's line naming the shape.
    assert!(
        large_len.abs_diff(small_len) < 64,
        "256 × 256: {large_len} bytes against 2 × 2: {small_len}"
    );
}

/// Refusals name the field: a slot that is not (R+1)·k·g, a width beyond W, a mutant
/// outside the array, an array too large to render whole.
#[test]
fn bad_array_specs_are_refused() {
    let p = small(Mode::Fourier);
    let rom = sign_probe_rom(&p);
    let o = RenderOptions::default();
    let cases = [
        (
            ArraySpec {
                slot_cycles: 5,
                ..spec(&p, 2, 2, 24, 1)
            },
            "array slot = 5",
        ),
        (
            ArraySpec {
                bits: 25,
                ..spec(&p, 2, 2, 24, 1)
            },
            "array.readout_bits = 25",
        ),
        (
            ArraySpec {
                fault: Some(ArrayFault::RowLate { row: 2 }),
                ..spec(&p, 2, 2, 24, 1)
            },
            "mutation row = 2",
        ),
        (
            spec(&p, 4097, 64, 24, 1),
            "array.rows × array.cols = 4097 × 64",
        ),
        (
            ArraySpec {
                superpixel: 5,
                ..spec(&p, 2, 2, 24, 1)
            },
            "array.superpixel = 5",
        ),
        (
            ArraySpec {
                fault: Some(ArrayFault::SwapLate),
                ..spec(&p, 2, 2, 24, 1)
            },
            "mutation = swap_late",
        ),
    ];
    for (s, want) in cases {
        let e = render_array(&p, &rom, &o, &s).unwrap_err();
        assert!(
            matches!(e, RtlError::Array { .. }) && e.to_string().contains(want),
            "{e}"
        );
    }
    // Double-buffered with C = K: the swap edge would meet the last slot's write.
    let mut pk = p.clone();
    pk.cycles_per_pulse = pk.slots();
    let s = ArraySpec {
        double_buffer: true,
        ..spec(&pk, 2, 2, 24, 1)
    };
    let e = render_array(&pk, &sign_probe_rom(&pk), &o, &s).unwrap_err();
    assert!(
        e.to_string()
            .contains(&format!("pixel.cycles_per_pulse = {}", pk.slots())),
        "{e}"
    );
}

/// Double-buffer off renders the pixel and the array byte for byte as before the option
/// existed (the committed testbench/array-2x2 is the check of record:
/// scripts/check-generated.sh); on, the pixel gains the `swap` port and the shadow, and
/// the array the swap broadcast, and nothing else changes in the pixel's file header but
/// its double-buffer line.
#[test]
fn the_double_buffer_is_rendered_only_when_on() {
    let p = small(Mode::Fourier);
    let rom = sign_probe_rom(&p);
    let o = RenderOptions::default();
    let off = render_array(&p, &rom, &o, &spec(&p, 2, 2, 24, 1)).unwrap();
    let on = render_array(
        &p,
        &rom,
        &o,
        &ArraySpec {
            double_buffer: true,
            ..spec(&p, 2, 2, 24, 1)
        },
    )
    .unwrap();
    // Only the array wires the sequencer's swap strobe: its pixels and broadcast do not.
    for f in &off {
        let text = f.contents.replace(".swap(s_swap)", "");
        let own = if f.name.ends_with("_sequencer.v") {
            ""
        } else {
            &text
        };
        assert!(
            !own.contains("swap_q") && !own.contains("input  wire swap"),
            "{}",
            f.name
        );
    }
    assert_eq!(on[2].contents, off[2].contents, "one sequencer for both");
    let (pix_off, pix_on) = (&off[0].contents, &on[0].contents);
    assert!(pix_on.contains("input  wire swap,") && pix_on.contains("sh_0 <= y[0];"));
    assert!(
        !pix_on.contains("!rd_active && (!active"),
        "the readout blocks no pulse"
    );
    assert!(pix_off.contains("!rd_active && (!active"));
    assert_eq!(on[1].contents, off[1].contents, "the ROM is the same");
    assert_eq!(on[3].contents.matches(".swap(r_swap[lr])").count(), 1);
    assert!(
        on[3].contents.contains(".DOUBLE_BUFFER(1)")
            && off[3].contents.contains(".DOUBLE_BUFFER(0)")
    );
}
