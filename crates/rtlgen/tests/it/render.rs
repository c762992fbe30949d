//! Rendering and writing: every valid configuration renders, identifiers cannot inject
//! Verilog, out-of-range fields are named with their range, headers carry what they must,
//! and `write_generated` refuses foreign files without writing anything.

use proptest::prelude::*;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::RtlError;
use tofprobe_rtlgen::naming::{config_hash_with_prefix, validate_identifier};
use tofprobe_rtlgen::render::{HEADER_MARK, RenderOptions, render};
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;

#[test]
fn identifiers_are_validated() {
    for bad in [
        "",
        "Top",
        "a b",
        "x;module evil",
        "module",
        "1abc",
        "a`define",
        &"a".repeat(33),
    ] {
        assert!(
            validate_identifier("module_prefix", bad).is_err(),
            "{bad:?} accepted"
        );
    }
    for good in ["tofprobe", "px_2", "a"] {
        assert!(validate_identifier("module_prefix", good).is_ok());
    }
    let p = PixelParams {
        frame_pulses: 64,
        rom_depth: 8,
        ..PixelParams::default()
    };
    let o = RenderOptions {
        module_prefix: "x;endmodule".into(),
        ..RenderOptions::default()
    };
    let e = render(&p, &sign_probe_rom(&p), &o)
        .expect_err("injection rejected")
        .to_string();
    assert!(
        e.contains("module_prefix") && e.contains("x;endmodule"),
        "{e}"
    );
}

#[test]
fn range_errors_name_field_value_and_fix() {
    let p = PixelParams {
        cycles_per_pulse: 7,
        ..PixelParams::default()
    };
    let e = render(&p, &[], &RenderOptions::default())
        .expect_err("K = 16 > C = 7")
        .to_string();
    assert!(
        e.contains("cycles_per_pulse = 7") && e.contains("C ≥ 16") && e.ends_with(": 16"),
        "{e}"
    );
    let p = PixelParams {
        width: 10,
        ..PixelParams::default()
    };
    let e = render(&p, &[], &RenderOptions::default())
        .expect_err("W below the operand")
        .to_string();
    // Operand T+1+F = 7+1+8 = 16 bits with the default.
    assert!(
        e.contains("width = 10") && e.contains("16 bits") && e.ends_with(": 16"),
        "{e}"
    );
    let p = PixelParams {
        mode: Mode::Haar,
        frame_pulses: 1000,
        ..PixelParams::default()
    };
    let e = render(&p, &[], &RenderOptions::default())
        .expect_err("Haar N not a power of two")
        .to_string();
    assert!(
        e.contains("frame_pulses = 1000") && e.ends_with(": 1024"),
        "{e}"
    );
}

#[test]
fn headers_name_generator_template_command_hash() {
    let p = PixelParams {
        frame_pulses: 64,
        rom_depth: 8,
        ..PixelParams::default()
    };
    let o = RenderOptions {
        command: "tofprobe rtl --out here".into(),
        module_prefix: "px".into(),
        ..RenderOptions::default()
    };
    let files = render(&p, &sign_probe_rom(&p), &o).expect("renders");
    assert_eq!(files.len(), 4, "case-table ROM: pixel, rom, sequencer, top");
    for f in &files {
        assert!(f.contents.starts_with(HEADER_MARK), "{}", f.name);
        let head: String = f.contents.lines().take(4).collect::<Vec<_>>().join("\n");
        assert!(
            head.contains(&format!("templates/{}", f.template)),
            "{head}"
        );
        assert!(
            head.contains("DO NOT EDIT") && head.contains("`tofprobe rtl --out here`"),
            "{head}"
        );
        assert!(head.contains(&config_hash_with_prefix(&p, "px")), "{head}");
        assert!(f.name.starts_with("px_"), "{}", f.name);
    }
}

#[test]
fn foreign_files_are_never_overwritten() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("foreign");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(dir.join("b.v"), "module hand_written; endmodule\n").expect("write");
    let files = vec![
        ("a.v".to_string(), format!("{HEADER_MARK} test\n")),
        ("b.v".to_string(), format!("{HEADER_MARK} test\n")),
    ];
    let e = write_generated(&dir, &files).expect_err("refuses");
    assert!(matches!(e, RtlError::Foreign { .. }), "{e}");
    assert!(
        !dir.join("a.v").exists(),
        "nothing is written when one target is foreign"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("b.v")).expect("kept"),
        "module hand_written; endmodule\n"
    );
    std::fs::remove_file(dir.join("b.v")).expect("rm");
    write_generated(&dir, &files).expect("writes");
    write_generated(&dir, &files).expect("overwrites its own files");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(66), ..ProptestConfig::default() })]
    /// Every configuration the validator accepts renders, with one case per schedule slot
    /// and adder and one write-enable per register.
    #[test]
    fn every_valid_configuration_renders(
        haar in any::<bool>(), b in 1usize..40, u in 0u32..6, a in 1usize..9, ec in 0usize..4,
        t in 1u32..17, s in 0u32..16, f in 0u32..17, ew in 0u32..30, ln in 6u32..24, l in 1usize..300,
        nearest in any::<bool>(), g in 0u32..17,
    ) {
        let mut p = PixelParams {
            mode: if haar { Mode::Haar } else { Mode::Fourier }, bins: b, haar_scales: u,
            adders: 1, cycles_per_pulse: 1, tdc_bits: t, zoom: 0, shift: s, frac_bits: f,
            width: 8, frame_pulses: 1 << ln, rom_depth: l,
            prefilter_rounding: if nearest && !haar {
                tofprobe_pixel::Rounding::Nearest
            } else {
                tofprobe_pixel::Rounding::Floor
            },
            register_frac_bits: (!haar && g < f).then_some(g),
            register_file: Default::default(),
        };
        p.adders = a.min(p.ops_per_pulse());
        p.cycles_per_pulse = p.slots() + ec;
        p.width = (p.operand_bits() + ew).min(63);
        prop_assume!(p.validate().is_ok());
        let files = render(&p, &sign_probe_rom(&p), &RenderOptions::default()).expect("renders");
        let pixel = &files[0].contents;
        let writes = pixel.matches("assign we_c[").count();
        prop_assert_eq!(writes, p.registers());
        let adders = pixel.matches("    reg add_").count();
        prop_assert_eq!(adders, p.adders);
        // G < F: the operand is the top T+1+G bits of the T+1+F-bit x, nothing else.
        let slice = format!(
            "wire [{}:0] op_new = x_new[{}:{}];",
            p.operand_bits() - 1,
            p.prefilter_bits() - 1,
            p.frac_bits.saturating_sub(g),
        );
        prop_assert_eq!(pixel.contains(&slice), !haar && g < f, "{}", slice);
        prop_assert_eq!(pixel.contains("op_new"), !haar && g < f);
    }
}
