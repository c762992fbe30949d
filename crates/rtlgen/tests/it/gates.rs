//! Quality gates on the rendered RTL of several configurations (both modes, odd widths,
//! A > 1, registers keeping G < F fraction bits, case-table and `$readmemh` ROMs): `verilator --lint-only -Wall` with zero
//! warnings (the top with either sequencer), yosys `synth -top` with no latches (but the
//! clock gate's one, with `register_file = "clock_gated"`, and the registers' R·W with
//! `"latch"`) and no warnings beyond the register file's
//! memory-to-registers note, and `iverilog -g2005` compiles. Skipped loudly only when a tool
//! is missing (CI installs them).

use std::path::{Path, PathBuf};
use std::process::Command;
use tofprobe_pixel::{DirectedOptions, Mode, PixelParams, RegisterFile};
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;
use tofprobe_rtlgen::{DEFAULT_MODULE_PREFIX, module_names};

fn have(tool: &str) -> bool {
    tofprobe_testkit::tools::have(&[tool], "tofprobe-rtlgen gates")
}

fn configs() -> Vec<(&'static str, PixelParams)> {
    let d = PixelParams::default();
    vec![
        ("default", d.clone()),
        // The committed rtl/'s shape: a periodic ROM of 20,000 entries, not a power of two,
        // loaded by $readmemh (yosys maps it in ≈ 40 s).
        (
            "default_periodic_rom",
            PixelParams {
                rom_depth: 20_000,
                ..d.clone()
            },
        ),
        (
            "haar_default",
            PixelParams {
                mode: Mode::Haar,
                frame_pulses: 1 << 20,
                ..d.clone()
            },
        ),
        (
            "odd_widths",
            PixelParams {
                bins: 3,
                adders: 4,
                cycles_per_pulse: 2,
                tdc_bits: 5,
                zoom: 7,
                shift: 0,
                frac_bits: 3,
                // The registers keep 1 of x's 3 fraction bits: op is a slice of x.
                register_frac_bits: Some(1),
                width: 17,
                frame_pulses: 1000,
                rom_depth: 37,
                ..d.clone()
            },
        ),
        (
            "f0_one_adder",
            PixelParams {
                bins: 2,
                adders: 1,
                cycles_per_pulse: 5,
                tdc_bits: 3,
                shift: 15,
                frac_bits: 0,
                width: 63,
                frame_pulses: 1,
                rom_depth: 1,
                ..d.clone()
            },
        ),
        (
            "haar_a3",
            PixelParams {
                mode: Mode::Haar,
                haar_scales: 3,
                adders: 3,
                cycles_per_pulse: 2,
                tdc_bits: 7,
                zoom: 100,
                width: 11,
                frame_pulses: 64,
                ..d.clone()
            },
        ),
        // One latch-based clock gate per register, no enable multiplexer (both modes).
        (
            "clock_gated",
            PixelParams {
                register_file: RegisterFile::ClockGated,
                ..d.clone()
            },
        ),
        (
            "haar_clock_gated",
            PixelParams {
                mode: Mode::Haar,
                haar_scales: 2,
                adders: 2,
                cycles_per_pulse: 4,
                frame_pulses: 256,
                width: 20,
                register_file: RegisterFile::ClockGated,
                ..d.clone()
            },
        ),
        // Latch registers written in clk's low phase through one clock gate each (both modes).
        (
            "latch",
            PixelParams {
                register_file: RegisterFile::Latch,
                ..d.clone()
            },
        ),
        (
            "haar_latch",
            PixelParams {
                mode: Mode::Haar,
                haar_scales: 2,
                adders: 2,
                cycles_per_pulse: 4,
                frame_pulses: 256,
                width: 20,
                register_file: RegisterFile::Latch,
                ..d.clone()
            },
        ),
    ]
}

fn render_to(name: &str, p: &PixelParams) -> PathBuf {
    render_with(name, p, &RenderOptions::default())
}

fn render_with(name: &str, p: &PixelParams, o: &RenderOptions) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("gates")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let files = tofprobe_rtlgen::render(p, &sign_probe_rom(p), o).expect("renders");
    let pairs: Vec<(String, String)> = files.into_iter().map(|f| (f.name, f.contents)).collect();
    write_generated(&dir, &pairs).expect("writes");
    dir
}

fn sources(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    v.sort();
    v
}

#[test]
fn verilator_lint_is_clean() {
    if !have("verilator") {
        return;
    }
    // Both sequencers of the top: the reference one and the directed one (its step table).
    let directed = RenderOptions {
        directed: Some(DirectedOptions::default()),
        ..RenderOptions::default()
    };
    let runs = configs().into_iter().flat_map(|(name, p)| {
        [
            (name.to_string(), p.clone(), RenderOptions::default()),
            (format!("{name}-directed"), p, directed.clone()),
        ]
    });
    for (name, p, o) in runs {
        let dir = render_with(&format!("lint-{name}"), &p, &o);
        let out = Command::new("verilator")
            .current_dir(&dir)
            .args([
                "--lint-only",
                "-Wall",
                "--top-module",
                &module_names(DEFAULT_MODULE_PREFIX).2,
            ])
            .args(sources(&dir))
            .output()
            .expect("verilator runs");
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success() && text.trim().is_empty(),
            "{name}: {text}"
        );
    }
}

#[test]
fn yosys_synthesises_without_latches() {
    if !have("yosys") {
        return;
    }
    // Two syntheses at a time (eleven in a row were this binary's long pole, one core idle
    // for a minute); each configuration's checks run on its own thread.
    let configs = configs();
    let half = configs.len().div_ceil(2);
    std::thread::scope(|s| {
        for chunk in configs.chunks(half) {
            s.spawn(move || {
                for (name, p) in chunk {
                    synthesises_without_latches(name, p);
                }
            });
        }
    });
}

/// One configuration's generic synthesis: no latch but the intended ones, the only
/// warning the register file's, and no register optimised away.
fn synthesises_without_latches(name: &str, p: &PixelParams) {
    let dir = render_to(&format!("yosys-{name}"), p);
    let script = format!(
        "read_verilog {}; synth -top {}; select -assert-count {} t:$dlatch t:$_DLATCH_*; tee -o stat.txt stat",
        sources(&dir).join(" "),
        module_names(DEFAULT_MODULE_PREFIX).2,
        // The only latches: the one of the clock-gate module (instantiated per register),
        // and with latch registers their R·W bits.
        match p.register_file {
            RegisterFile::Flops => 0,
            RegisterFile::ClockGated => 1,
            RegisterFile::Latch => 1 + p.registers() as u64 * u64::from(p.width),
        }
    );
    let out = Command::new("yosys")
        .current_dir(&dir)
        .args(["-q", "-p", &script])
        .output()
        .expect("yosys runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{name}: {text}");
    // The only warning allowed: the register file array becomes flip-flops (intended).
    for line in text.lines().filter(|l| l.contains("Warning")) {
        assert!(
            line.contains("Replacing memory \\y with list of registers"),
            "{name}: {line}"
        );
    }
    // Flip-flop count: at least the register file R·W (no register optimised away).
    let stat = std::fs::read_to_string(dir.join("stat.txt")).expect("yosys wrote stat.txt");
    let dff: u64 = stat
        .lines()
        .filter(|l| l.trim_start().starts_with("$_SDFF") || l.trim_start().starts_with("$_DFF"))
        .filter_map(|l| l.split_whitespace().last()?.parse::<u64>().ok())
        .sum();
    // Latch registers: their write enables and one word per adder instead.
    let floor = match p.register_file {
        RegisterFile::Latch => (p.registers() + p.adders * p.width as usize) as u64,
        _ => (p.registers() as u64) * u64::from(p.width),
    };
    assert!(dff >= floor, "{name}: {dff} flip-flops");
}

#[test]
fn iverilog_compiles() {
    if !have("iverilog") {
        return;
    }
    for (name, p) in configs() {
        let dir = render_to(&format!("iverilog-{name}"), &p);
        let out = Command::new("iverilog")
            .current_dir(&dir)
            .args([
                "-g2005",
                "-Wall",
                "-o",
                "/dev/null",
                "-s",
                &module_names(DEFAULT_MODULE_PREFIX).2,
            ])
            .args(sources(&dir))
            .output()
            .expect("iverilog runs");
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {text}");
    }
}
