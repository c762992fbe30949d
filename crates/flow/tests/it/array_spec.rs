//! The plain spec the flow hands `tofprobe_eda::array` (`tofprobe_flow::array::report::eda_spec`):
//! the whole array's netlist is the chip's own array (`Chip::array_spec`, the one the RTL
//! commands render), and the slices of a large array keep the readout their shape resolves
//! to. No tool runs.

use tofprobe_design::{Chip, Document, RomPurpose, RtlOverrides, resolve};
use tofprobe_eda::array::timing::WHOLE_TIMING_MAX_PIXELS;
use tofprobe_flow::array::report::eda_spec;

const DEFAULT: &str = include_str!("../../../../scenes/default.toml");

fn eight_by_eight() -> tofprobe_design::ResolvedDesign {
    let text = DEFAULT
        .replacen("duration_s = 1.0", "pulses = 4096", 1)
        .replacen("bins = 16", "bins = 1", 1)
        .replacen("rom_depth = 20000", "rom_depth = 4096", 1)
        + "\n[array]\nrows = 8\ncols = 8\npitch_um = 40.0\nmm_per_pixel = 1.0\n";
    resolve(
        Document::from_toml_str(&text, "8x8.toml").expect("parses"),
        "8x8.toml",
    )
    .expect("resolves")
}

#[test]
fn the_spec_times_the_chips_own_array_and_slices_keep_their_readout() {
    let design = eight_by_eight();
    let chip = Chip::array_of(&design, &RtlOverrides::default(), RomPurpose::Rendered).unwrap();
    let whole = eda_spec(&design, &chip, 130.0, 0.7, WHOLE_TIMING_MAX_PIXELS).unwrap();
    assert_eq!(whole.slices.len(), 1);
    assert_eq!(whole.slices[0].name, "whole 8 × 8");
    assert_eq!(Some(whole.slices[0].array), chip.array_spec(None, None));
    // 160 MHz: C = 16 cycles a pulse at 10 MHz.
    assert_eq!(whole.clock_mhz, 160.0);
    assert_eq!(whole.pixel, chip.pixel);
    assert_eq!(whole.rom, chip.rom.words);
    let sliced = eda_spec(&design, &chip, 130.0, 0.7, 0).unwrap();
    let shapes: Vec<_> = sliced
        .slices
        .iter()
        .map(|s| (s.name.as_str(), s.array.rows, s.array.cols))
        .collect();
    assert_eq!(shapes, [("row 1 × 8", 1, 8), ("column 8 × 1", 8, 1)]);
    // One beat of b = W bits a word, a beat a cycle: a slot is R + 1 = 3 cycles whatever
    // the shape (the readout's figures per pixel do not depend on the array's size).
    for s in &sliced.slices {
        assert_eq!(s.array.bits, chip.pixel.width);
        assert_eq!(s.array.slot_cycles, 3);
    }
}
