//! The superpixel front end's RTL (`templates/superpixel.v`) against its model
//! (`tofprobe_pixel::Superpixel::combine`): `verilator --lint-only -Wall` clean, and Icarus
//! driving it with every input of G = 2 at T = 3 (2^4 valid patterns × 8^4 codes) and random
//! inputs of G = 2, 3, 4 at T = 7 and 16, bit-exact, the first mismatching vector named. A
//! module with a wrong table word is caught by the same run.

use std::path::{Path, PathBuf};
use std::process::Command;

use tofprobe_pixel::{NO_DETECTION, PixelParams, Superpixel};
use tofprobe_rtlgen::RenderOptions;
use tofprobe_rtlgen::superpixel::{module_name, render_superpixel};
use tofprobe_scene::SplitMix64;

fn have(tools: &[&str]) -> bool {
    tofprobe_testkit::tools::have(tools, "tofprobe-rtlgen superpixel")
}

fn pixel(t: u32) -> PixelParams {
    PixelParams {
        tdc_bits: t,
        ..PixelParams::default()
    }
}

/// Renders the front end of (G, T) into its own directory; `corrupt` alters the text.
fn render(g: u32, t: u32, corrupt: impl Fn(String) -> String) -> (PathBuf, Superpixel) {
    let sp = Superpixel::new(g, t).unwrap();
    let f = render_superpixel(&pixel(t), &sp, &RenderOptions::default()).unwrap();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("superpixel-g{g}-t{t}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(&f.name), corrupt(f.contents)).unwrap();
    (dir, sp)
}

/// The vectors: each pulse's G² SPAD codes (compact form) and the model's answer, as hex
/// lines {spad_valid, spad_tdc} and {valid, tdc}.
fn vectors(sp: &Superpixel, pulses: &[Vec<u32>]) -> (String, String) {
    let (n, t) = (sp.spads(), sp.tdc_bits());
    let (mut inputs, mut expected) = (String::new(), String::new());
    for codes in pulses {
        // Bits: valid[n-1..0] then tdc[n·t-1..0], SPAD i's code at i·t.
        let mut bits = vec![false; n + n * t as usize];
        for (i, &c) in codes.iter().enumerate() {
            let valid = c != NO_DETECTION;
            bits[n * t as usize + i] = valid;
            for b in 0..t {
                bits[i * t as usize + b as usize] = valid && (c >> b) & 1 == 1;
            }
        }
        inputs += &hex(&bits);
        inputs.push('\n');
        let out = sp.combine(codes);
        let mut o = vec![false; 1 + t as usize];
        o[t as usize] = out != NO_DETECTION;
        for b in 0..t {
            o[b as usize] = out != NO_DETECTION && (out >> b) & 1 == 1;
        }
        expected += &hex(&o);
        expected.push('\n');
    }
    (inputs, expected)
}

/// Bits (LSB first) as hex, most significant digit first.
fn hex(bits: &[bool]) -> String {
    bits.chunks(4)
        .rev()
        .map(|c| {
            let v = c
                .iter()
                .enumerate()
                .map(|(i, &b)| u32::from(b) << i)
                .sum::<u32>();
            char::from_digit(v, 16).unwrap()
        })
        .collect()
}

/// Runs Icarus on `pulses` through the module in `dir`: `Ok(())` or the first mismatch
/// line of the testbench.
fn simulate(dir: &Path, sp: &Superpixel, pulses: &[Vec<u32>]) -> Result<(), String> {
    let (n, t) = (sp.spads(), sp.tdc_bits() as usize);
    let (inputs, expected) = vectors(sp, pulses);
    std::fs::write(dir.join("in.hex"), inputs).unwrap();
    std::fs::write(dir.join("out.hex"), expected).unwrap();
    let name = module_name("tofprobe");
    let tb = format!(
        "`timescale 1ns/1ps
module tb;
    reg [{iw}:0] vin [0:{last}];
    reg [{t}:0] vout [0:{last}];
    reg [{iw}:0] v;
    wire valid;
    wire [{tm}:0] tdc;
    {name} dut (.spad_valid(v[{iw}:{nt}]), .spad_tdc(v[{ntm}:0]), .valid(valid), .tdc(tdc));
    integer i;
    initial begin
        $readmemh(\"in.hex\", vin);
        $readmemh(\"out.hex\", vout);
        for (i = 0; i <= {last}; i = i + 1) begin
            v = vin[i];
            #1;
            if ({{valid, tdc}} !== vout[i]) begin
                $display(\"MISMATCH vector %0d: in %h, rtl %b %0d, model %b %0d\", i, vin[i], valid, tdc, vout[i][{t}], vout[i][{tm}:0]);
                $finish;
            end
        end
        $display(\"PASS %0d\", i);
        $finish;
    end
endmodule
",
        iw = n + n * t - 1,
        last = pulses.len() - 1,
        tm = t - 1,
        nt = n * t,
        ntm = n * t - 1,
    );
    std::fs::write(dir.join("tb.v"), tb).unwrap();
    let out = Command::new("iverilog")
        .current_dir(dir)
        .args(["-g2012", "-o", "sim", "tb.v", &format!("{name}.v")])
        .output()
        .expect("iverilog runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new("vvp")
        .current_dir(dir)
        .arg("sim")
        .output()
        .expect("vvp runs");
    let text = String::from_utf8_lossy(&run.stdout);
    match text.lines().find(|l| l.starts_with("MISMATCH")) {
        Some(l) => Err(l.to_string()),
        None => {
            assert!(text.contains(&format!("PASS {}", pulses.len())), "{text}");
            Ok(())
        }
    }
}

/// `count` random pulses of G² SPADs, each valid with probability ½, codes of T bits.
fn random(sp: &Superpixel, count: usize, seed: u64) -> Vec<Vec<u32>> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            (0..sp.spads())
                .map(|_| {
                    let r = rng.next_u64();
                    if r & 1 == 0 {
                        NO_DETECTION
                    } else {
                        ((r >> 1) as u32) & ((1 << sp.tdc_bits()) - 1)
                    }
                })
                .collect()
        })
        .collect()
}

#[test]
fn verilator_lints_the_front_end_clean() {
    if !have(&["verilator"]) {
        return;
    }
    for (g, t) in [(2, 1), (2, 7), (3, 7), (4, 1), (4, 16)] {
        let (dir, _) = render(g, t, |s| s);
        let out = Command::new("verilator")
            .current_dir(&dir)
            .args([
                "--lint-only",
                "-Wall",
                "--top-module",
                &module_name("tofprobe"),
            ])
            .arg(format!("{}.v", module_name("tofprobe")))
            .output()
            .expect("verilator runs");
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success() && text.trim().is_empty(),
            "G = {g}, T = {t}: {text}"
        );
    }
}

#[test]
fn icarus_matches_the_model_bit_for_bit() {
    if !have(&["iverilog", "vvp"]) {
        return;
    }
    // Every input of G = 2 at T = 3: 16 valid patterns × 8^4 codes.
    let (dir, sp) = render(2, 3, |s| s);
    let all: Vec<Vec<u32>> = (0..1u32 << 16)
        .map(|x| {
            (0..4)
                .map(|i| {
                    if (x >> (12 + i)) & 1 == 0 {
                        NO_DETECTION
                    } else {
                        (x >> (3 * i)) & 7
                    }
                })
                .collect()
        })
        .collect();
    simulate(&dir, &sp, &all).unwrap_or_else(|m| panic!("G = 2, T = 3: {m}"));
    for (g, t) in [(3, 7), (4, 7), (4, 16)] {
        let (dir, sp) = render(g, t, |s| s);
        simulate(&dir, &sp, &random(&sp, 4000, u64::from(g * 100 + t)))
            .unwrap_or_else(|m| panic!("G = {g}, T = {t}: {m}"));
    }
    // A wrong table word (M[3] one less, ⌊2^k/3⌋) is caught and the vector named.
    let sp = Superpixel::new(2, 3).unwrap();
    let (m3, mw) = (sp.table()[2], sp.table_bits());
    let (dir, sp) = render(2, 3, |s| {
        let right = format!("'d3: recip = {mw}'d{m3};");
        assert!(s.contains(&right), "{s}");
        s.replace(&right, &format!("'d3: recip = {mw}'d{};", m3 - 1))
    });
    let e = simulate(&dir, &sp, &all).unwrap_err();
    assert!(e.starts_with("MISMATCH vector"), "{e}");
}
