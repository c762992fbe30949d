//! The verification kit of an array set (issue 42, point 6): `tofprobe rtl` on an `[array]`
//! configuration writes, in the same atomic set as the RTL and listed by its completion
//! marker, the self-checking array testbench `testbench/array_tb.v` (copied whole under a
//! generated header) and the golden vectors of the set's configuration
//! (`crate::array_vectors::vector_files`, the files `tofprobe vectors` writes), and
//! the set's FuseSoC core gains targets that run them ([`crate::core::render_array_core`]).
//! A designer re-runs the set after an edit in their own simulator: testbench/README.md
//! "The array set's verification kit".

use tofprobe_pixel::PixelParams;

use crate::render::{RenderOptions, RtlFile, header_from};

/// The array testbench (Icarus and `verilator --binary`), embedded so the binary works
/// outside the source tree.
pub const ARRAY_TB_V: &str = include_str!("../../../testbench/array_tb.v");

/// The kit's testbench file name in the set; the co-simulation's RTL sources skip it.
pub const KIT_TESTBENCH: &str = "array_tb.v";

/// The testbench's top module.
pub const KIT_TOP: &str = "array_tb";

/// The vectors' Verilog include (macros: sizes, cycles, the array module's name).
pub const KIT_PARAMS: &str = "array_params.vh";

/// The vector data the testbench reads with `$readmemh` from its working directory.
pub const KIT_DATA: [&str; 2] = ["array_stim.hex", "array_expect.hex"];

/// The completion line the testbench prints once (then ` cycles=<n> mismatches=<n>`).
pub const KIT_DONE: &str = "TOFPROBE-COSIM-DONE";

/// The most cycles a kit's vectors may replay (as [`crate::vectors::FULL_TRACE_MAX_CYCLES`]:
/// `array_expect.hex` holds one line per cycle); a longer run writes no kit and says how to
/// get one (a shorter `--frame-pulses`, fewer `--kit-frames`).
pub const KIT_MAX_CYCLES: u64 = crate::vectors::FULL_TRACE_MAX_CYCLES;

/// Frames of the kit's vectors by default.
pub const KIT_DEFAULT_FRAMES: u64 = 2;

/// The kit's testbench: `testbench/array_tb.v` under the generated header (source, the
/// regeneration command, DO NOT EDIT, the configuration hash).
pub fn render_kit_testbench(p: &PixelParams, o: &RenderOptions) -> RtlFile {
    let h = header_from(p, "testbench/array_tb.v", "array_tb.v", o);
    RtlFile {
        name: KIT_TESTBENCH.to_string(),
        template: "array_tb.v",
        contents: format!(
            "{h}\n// The set's verification kit: replays array_stim.hex/array_expect.hex (beside this \
             file) through `{}`;\n// testbench/README.md \"The array set's verification kit\".\n{ARRAY_TB_V}",
            crate::array::array_module_name(&o.module_prefix)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kit_testbench_is_the_repository_one_under_a_header() {
        let p = PixelParams::default();
        let o = RenderOptions::default();
        let f = render_kit_testbench(&p, &o);
        assert!(
            f.contents.starts_with(crate::render::HEADER_MARK),
            "{}",
            f.contents
        );
        assert!(f.contents.contains("from testbench/array_tb.v."));
        assert!(
            f.contents
                .contains("DO NOT EDIT: regenerate with `tofprobe rtl --out rtl`")
        );
        assert!(f.contents.ends_with(ARRAY_TB_V));
        assert!(ARRAY_TB_V.contains(&format!("module {KIT_TOP};")));
        assert!(ARRAY_TB_V.contains(&format!("\"{KIT_DONE} cycles=")));
        for d in KIT_DATA {
            assert!(ARRAY_TB_V.contains(&format!("`AR_FILE(\"{d}\")")), "{d}");
        }
        assert!(ARRAY_TB_V.contains(&format!("`include \"{KIT_PARAMS}\"")));
    }
}
