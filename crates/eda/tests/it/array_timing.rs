//! The array's slice timing model (`tofprobe_eda::array::timing`) against the whole array
//! it stands for: an 8 × 8 array of a one-bin pixel timed whole and as a row (1 × 8) and
//! a column (8 × 1) on osu018. The slices keep every fan-out and fan-in of the whole, so
//! their worst broadcast and readout paths must be the whole's, within what the
//! synthesis of a different netlist moves (ABC maps each top on its own: a few %).

use std::path::PathBuf;

use tofprobe_eda::array::timing::{ArrayTiming, WHOLE_TIMING_MAX_PIXELS, array_timing, slices};
use tofprobe_eda::array::{ArrayEdaSpec, ArraySlice};
use tofprobe_pixel::PixelParams;
use tofprobe_rtlgen::ArraySpec;

const OSU018: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

/// The spec of an 8 × 8 array of the default pixel with one bin (N = L = 4096, W = 28 as
/// the sizing resolves it: `tofprobe_flow`'s crates/flow/tests/it/array_spec.rs), its
/// netlists those of [`slices`] up to `whole_max` pixels whole. The readout is the one the
/// contract resolves by default: b = W bits a beat (W ≤ 63), one beat a word, a beat a
/// cycle, so a pixel's slot is R + 1 = 3 cycles.
fn spec(whole_max: usize) -> ArrayEdaSpec {
    let pixel = PixelParams {
        bins: 1,
        ..PixelParams::fourier_default(28, 4096, 4096)
    };
    let slot = pixel.registers() as u64 + 1;
    let slices = slices(8, 8, whole_max)
        .into_iter()
        .map(|(name, rows, cols)| ArraySlice {
            name,
            array: ArraySpec {
                rows,
                cols,
                bits: pixel.width,
                beats_per_word: 1,
                beat_cycles: 1,
                slot_cycles: slot,
                fault: None,
                tile: None,
                superpixel: 1,
                double_buffer: false,
            },
        })
        .collect();
    ArrayEdaSpec {
        clock_mhz: pixel.cycles_per_pulse as f64 * 10.0,
        rom: vec![0; pixel.rom_depth],
        pixel,
        rows: 8,
        cols: 8,
        slices,
        double_buffer: false,
        superpixel: None,
        node_nm: 130.0,
        utilisation: 0.7,
    }
}

#[test]
fn the_row_and_column_slices_time_the_whole_eight_by_eight_array() {
    if !tofprobe_testkit::tools::have(&["yosys", "sta", OSU018], "tofprobe-eda array_timing") {
        return;
    }
    let cache = std::env::temp_dir().join(format!("tofprobe-eda-slices-{}", std::process::id()));
    let libs = [(PathBuf::from(OSU018), None)];
    let whole = array_timing(&spec(WHOLE_TIMING_MAX_PIXELS), &libs, &cache).unwrap();
    let sliced = array_timing(&spec(0), &libs, &cache).unwrap();
    assert_eq!(whole.len(), 1);
    assert_eq!(whole[0].netlist, "whole 8 × 8");
    assert_eq!(sliced.len(), 2);
    assert_eq!(sliced[0].netlist, "row 1 × 8");
    assert_eq!(sliced[1].netlist, "column 8 × 1");
    let worst = |f: fn(&ArrayTiming) -> f64| sliced.iter().map(f).fold(0.0, f64::max);
    let b = worst(|t| t.broadcast.delay_ns);
    let r = worst(|t| t.readout.delay_ns);
    let (wb, wr) = (whole[0].broadcast.delay_ns, whole[0].readout.delay_ns);
    // Within 15 %: the same paths, each top mapped by ABC on its own.
    assert!(
        (b / wb - 1.0).abs() < 0.15,
        "broadcast: slices {b} ns, whole {wb} ns"
    );
    assert!(
        (r / wr - 1.0).abs() < 0.15,
        "readout: slices {r} ns, whole {wr} ns"
    );
    // The slices' logic (row × R + column) bounds the whole's from above, and not by
    // more than the root counted R times over.
    let bound = sliced[0].shared_logic_um2 * 8.0 + sliced[1].shared_logic_um2;
    assert!(
        bound >= whole[0].shared_logic_um2,
        "{bound} < {}",
        whole[0].shared_logic_um2
    );
    // A broken slice model — the row slice alone, which has no column bus over R rows —
    // misses the readout's fan-in: its readout is shorter than the whole's.
    assert!(sliced[0].readout.delay_ns <= wr * 1.02);
    let _ = std::fs::remove_dir_all(&cache);
}
