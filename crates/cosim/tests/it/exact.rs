//! `--rtl DIR` is exact and its ROM is checked, not trusted (issue 17, points 1 and 2):
//! every rendered parameter is compared with the configuration before any simulation, and
//! the ROM image is compared with its manifest and with the configuration's ROM, naming the
//! entry and bits that differ. These checks run no simulator.

use std::path::{Path, PathBuf};
use tofprobe_cosim::{CosimError, CosimOptions, cosim, rom_from_rtl};
use tofprobe_pixel::{Mode, PixelParams};

fn committed_short() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl")
}

/// The parameters testbench/default-short/rtl was rendered for (the default, N = 64).
fn short_params() -> PixelParams {
    PixelParams {
        frame_pulses: 64,
        rom_depth: 20_000,
        tdc_bits: 7,
        frac_bits: 8,
        width: 39,
        ..PixelParams::default()
    }
}

fn copy_dir(from: &Path, name: &str) -> PathBuf {
    let to = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("exact")
        .join(name);
    let _ = std::fs::remove_dir_all(&to);
    std::fs::create_dir_all(&to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("dir") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), to.join(e.file_name())).expect("copy");
    }
    to
}

fn run(p: &PixelParams, dir: &Path, rom: Option<Vec<u64>>, name: &str) -> Result<bool, CosimError> {
    let work = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("exact-work")
        .join(name);
    let mut o = CosimOptions::new(work);
    o.rtl_dir = Some(dir.to_path_buf());
    o.rom = rom;
    o.frames = 1;
    cosim(p, &o).map(|r| r.pass)
}

#[test]
fn every_rendered_parameter_is_checked_before_simulating() {
    let dir = committed_short();
    // Each parameter changed alone is named with both values (no simulator is started:
    // the error comes first).
    let cases: Vec<(PixelParams, &str, &str, &str)> = vec![
        (
            PixelParams {
                frame_pulses: 128,
                ..short_params()
            },
            "N (pulses per frame)",
            "64",
            "128",
        ),
        (
            PixelParams {
                rom_depth: 4096,
                ..short_params()
            },
            "L (probe ROM depth)",
            "20000",
            "4096",
        ),
        (
            PixelParams {
                width: 40,
                ..short_params()
            },
            "W (register width)",
            "39",
            "40",
        ),
        (
            PixelParams {
                mode: Mode::Haar,
                ..short_params()
            },
            "mode (analysis mode)",
            "Fourier",
            "Haar",
        ),
        (
            PixelParams {
                zoom: 3,
                ..short_params()
            },
            "Z (zoom (window start code))",
            "0",
            "3",
        ),
        // G is in the header only when below F: the committed RTL has none.
        (
            PixelParams {
                register_frac_bits: Some(2),
                ..short_params()
            },
            "G (register fraction bits)",
            "(absent)",
            "2",
        ),
    ];
    for (p, param, rtl, config) in cases {
        match run(&p, &dir, None, "params") {
            Err(CosimError::RtlMismatch(d)) => {
                assert_eq!(
                    (d.parameter.as_str(), d.rtl.as_str(), d.config.as_str()),
                    (param, rtl, config)
                );
            }
            other => panic!("{param}: expected a parameter mismatch, got {other:?}"),
        }
    }
}

#[test]
fn the_committed_rom_is_read_whole_and_a_short_image_is_refused() {
    let p = short_params();
    let rom = rom_from_rtl(&p, &committed_short()).expect("the committed ROM reads");
    assert_eq!(rom.len(), 20_000, "all 20,000 entries of one 32-bit word");
    // A truncated hex file (4096 of 20,000 lines), manifest removed: refused, not padded.
    let dir = copy_dir(&committed_short(), "short-rom");
    std::fs::remove_file(dir.join("tofprobe_probe_rom.toml")).expect("rm manifest");
    let hex = std::fs::read_to_string(dir.join("tofprobe_probe_rom.hex")).expect("hex");
    let kept: String = hex
        .lines()
        .take(4096 + 3)
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.join("tofprobe_probe_rom.hex"), kept).expect("write");
    let e = rom_from_rtl(&p, &dir).expect_err("a short ROM image is an error");
    let msg = e.to_string();
    assert!(
        msg.contains("entries, the configuration's ROM depth is L = 20000"),
        "{msg}"
    );
}

#[test]
fn a_one_bit_rom_edit_is_caught_with_its_entry_and_bit() {
    let p = short_params();
    let good = rom_from_rtl(&p, &committed_short()).expect("reads");
    let dir = copy_dir(&committed_short(), "rom-bit");
    let hex_path = dir.join("tofprobe_probe_rom.hex");
    let text = std::fs::read_to_string(&hex_path).expect("hex");
    // Entry 17 (the 18th data line), register 5 flipped (bit 1 of the second-last digit).
    let mut data_line = 0;
    let edited: String = text
        .lines()
        .map(|l| {
            let is_data = !l.trim().is_empty() && !l.starts_with("//");
            let out = if is_data && data_line == 17 {
                let mut chars: Vec<char> = l.chars().collect();
                let i = chars.len() - 2;
                let v = chars[i].to_digit(16).expect("hex") ^ 0b10;
                chars[i] = std::char::from_digit(v, 16).expect("digit");
                chars.into_iter().collect()
            } else {
                l.to_string()
            };
            if is_data {
                data_line += 1;
            }
            out + "\n"
        })
        .collect();
    std::fs::write(&hex_path, &edited).expect("write");
    // With the manifest beside it: the content hash no longer matches.
    match run(&p, &dir, Some(good.clone()), "rom-hash") {
        Err(CosimError::RomImage { message, .. }) => {
            assert!(message.contains("content hash"), "{message}")
        }
        other => panic!("expected the manifest's hash to catch it, got {other:?}"),
    }
    // Without the manifest (or with a forged one): the comparison with the
    // configuration's ROM names entry 17, register bit 5.
    std::fs::remove_file(dir.join("tofprobe_probe_rom.toml")).expect("rm manifest");
    match run(&p, &dir, Some(good), "rom-compare") {
        Err(CosimError::RomMismatch(d)) => {
            assert_eq!((d.entry, d.bits.clone(), d.differing), (17, vec![5], 1));
        }
        other => panic!("expected a ROM mismatch, got {other:?}"),
    }
}
