//! The committed generated files are consistent: the configuration recorded in each header
//! is re-rendered with the recorded command and the committed probe ROM and compared byte
//! for byte (rtl/ and testbench/default-short/, the FuseSoC core included), and the committed short-frame vectors are
//! regenerated from their manifest's seed and frame count with the pixel model as judge.
//! The ROM's own content is regenerated from the configuration by the CLI's test
//! (crates/cli/tests/committed.rs) and scripts/check-generated.sh.

use std::path::{Path, PathBuf};
use tofprobe_cosim::driver::rom_from_rtl;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::core::{CoreSim, relative_path, render_core};
use tofprobe_rtlgen::render::{RenderOptions, render};
use tofprobe_rtlgen::stimulus::random_stimulus;
use tofprobe_rtlgen::vectors::golden_run;
use tofprobe_rtlgen::vectors::{VectorOptions, write_vectors};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Reads (command, parameters) back from a generated file's header.
fn from_header(text: &str) -> (String, PixelParams) {
    let cmd = text
        .lines()
        .find_map(|l| l.strip_prefix("// DO NOT EDIT: regenerate with `"))
        .and_then(|l| l.strip_suffix("`."))
        .expect("header names the command")
        .to_string();
    let list = text
        .lines()
        .find(|l| l.starts_with("// Configuration hash:"))
        .and_then(|l| l.split_once('(').map(|x| x.1.trim_end_matches(").")))
        .expect("header lists the configuration");
    let mut p = PixelParams::default();
    for (i, item) in list.split(", ").enumerate() {
        if i == 0 {
            p.mode = if item == "Haar" {
                Mode::Haar
            } else {
                Mode::Fourier
            };
            continue;
        }
        let (k, v) = item.split_once('=').expect("key=value");
        let n: u64 = v.parse().expect("number");
        match k {
            "B" => p.bins = n as usize,
            "U" => p.haar_scales = n as u32,
            "A" => p.adders = n as usize,
            "C" => p.cycles_per_pulse = n as usize,
            "T" => p.tdc_bits = n as u32,
            "Z" => p.zoom = n as u32,
            "S" => p.shift = n as u32,
            "F" => p.frac_bits = n as u32,
            "W" => p.width = n as u32,
            "N" => p.frame_pulses = n,
            "L" => p.rom_depth = n as usize,
            other => panic!("unknown header key {other}"),
        }
    }
    (cmd, p)
}

fn check_rtl_dir(dir: &Path) -> PixelParams {
    let top = std::fs::read_to_string(dir.join("tofprobe_top.v")).expect("committed top");
    let (command, p) = from_header(&top);
    let rom_note = top
        .lines()
        .find_map(|l| l.strip_prefix("// Probe ROM: "))
        .unwrap_or("")
        .to_string();
    let rom = rom_from_rtl(&p, dir).expect("committed ROM reads");
    // The FuseSoC core's sim paths, from the recorded command (relative to the repository
    // root, where it was run), made relative to the core as `tofprobe rtl` does.
    let arg = |flag: &str| {
        let mut t = command.split_whitespace();
        t.find(|w| *w == flag).and(t.next()).map(Path::new)
    };
    let sim = match (arg("--out"), arg("--core-vectors"), arg("--core-testbench")) {
        (Some(out), Some(v), Some(tb)) => Some(CoreSim {
            vectors_dir: relative_path(&root(), out, v),
            testbench: relative_path(&root(), out, tb),
        }),
        _ => None,
    };
    let options = RenderOptions {
        command: command.clone(),
        rom_note,
        ..RenderOptions::default()
    };
    let mut files = render(&p, &rom, &options).expect("renders");
    let core = render_core(&p, &files, &options, sim.as_ref()).expect("core renders");
    files.extend(core);
    // The ROM's TOML manifest is the CLI's (crates/cli/tests/committed.rs checks it).
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml"))
        .collect();
    names.sort();
    let mut fresh: Vec<String> = files.iter().map(|f| f.name.clone()).collect();
    fresh.sort();
    assert_eq!(names, fresh, "{}: file set", dir.display());
    for f in files {
        let old = std::fs::read_to_string(dir.join(&f.name)).expect("committed file");
        assert!(
            old == f.contents,
            "{}/{} differs from a fresh render",
            dir.display(),
            f.name
        );
    }
    p
}

#[test]
fn committed_rtl_is_current() {
    let p = check_rtl_dir(&root().join("rtl"));
    assert_eq!(
        (p.frame_pulses, p.registers(), p.rom_depth),
        (10_000_000, 32, 20_000)
    );
    check_rtl_dir(&root().join("testbench/default-short/rtl"));
}

#[test]
fn committed_vectors_are_current() {
    let base = root().join("testbench/default-short");
    let top = std::fs::read_to_string(base.join("rtl/tofprobe_top.v")).expect("committed top");
    let (_, p) = from_header(&top);
    let o = VectorOptions {
        frames: 2,
        seed: 1,
        ..VectorOptions::default()
    };
    let stim = random_stimulus(&p, o.frames * p.frame_pulses, o.seed);
    let rom = rom_from_rtl(&p, &base.join("rtl")).expect("committed ROM reads");
    // The judge: the pixel crate's cycle model.
    let (g, w) = golden_run(&p, &stim, &rom, &o).expect("pixel model accepts");
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("committed-vectors");
    let _ = std::fs::remove_dir_all(&tmp);
    write_vectors(&tmp, &p, &stim, &rom, &g, w, &o).expect("writes");
    for e in std::fs::read_dir(&tmp).expect("dir") {
        let name = e.expect("entry").file_name();
        let fresh = std::fs::read(tmp.join(&name)).expect("fresh");
        let old = std::fs::read(base.join("vectors").join(&name)).expect("committed vector file");
        assert!(
            old == fresh,
            "vectors/{} differs from a fresh run",
            name.to_string_lossy()
        );
    }
}
