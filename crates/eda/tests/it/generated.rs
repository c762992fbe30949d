//! The generated pixel (tofprobe-rtlgen) through yosys and OpenSTA on osu018: one small
//! configuration, so the test stays at about a second.

use std::path::Path;
use tofprobe_eda::analysis::analyse_point;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_pixel::PixelParams;

#[test]
fn generated_pixel_synthesises_and_splits() {
    let base = PixelParams {
        bins: 2,
        tdc_bits: 4,
        frac_bits: 2,
        width: 10,
        frame_pulses: 1024,
        rom_depth: 16,
        ..PixelParams::default()
    };
    let px = GeneratedPixel { base };
    let lib = Liberty::load(Path::new(
        "/usr/share/qflow/tech/osu018/osu018_stdcells.lib",
    ))
    .unwrap();
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-cache/generated");
    let p = analyse_point(&px, 2, 10, &lib, true, "clk", &cache, Some(6250.0)).unwrap();
    let s = &p.split;
    // R = 2B = 4 registers of W = 10 bits: 40 register-file flops of 96 µm² each.
    assert_eq!(s.registers_found, 4);
    assert_eq!(s.register_file.flops, 40);
    // held (T+1 = 5) + x and op (T+1+F = 7 each) + primed: at most 20 hold/prefilter flops
    // (yosys may sweep constant bits, never add any).
    assert!((12..=20).contains(&s.hold_prefilter.flops), "{s:?}");
    assert!(s.adders.cells > 0 && s.control.flops > 0, "{s:?}");
    let cells = s.register_file.cells + s.adders.cells + s.hold_prefilter.cells + s.control.cells;
    assert_eq!(cells, p.synthesis.cell_count);
    let t = p.timing.unwrap();
    assert!(t.f_max_mhz > 50.0 && t.f_max_mhz < 2000.0, "{t:?}");
}
