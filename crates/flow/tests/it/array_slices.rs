//! The array's slice timing model (`tofprobe_flow::array_timing`) against the whole array
//! it stands for: an 8 × 8 array of a one-bin pixel timed whole and as a row (1 × 8) and
//! a column (8 × 1) on osu018. The slices keep every fan-out and fan-in of the whole, so
//! their worst broadcast and readout paths must be the whole's, within what the
//! synthesis of a different netlist moves (ABC maps each top on its own: a few %).

use std::path::PathBuf;

use tofprobe_design::{Document, resolve};
use tofprobe_flow::array_timing::{WHOLE_TIMING_MAX_PIXELS, array_timing_with};

const DEFAULT: &str = include_str!("../../../../scenes/default.toml");
const OSU018: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

#[test]
fn the_row_and_column_slices_time_the_whole_eight_by_eight_array() {
    if !tofprobe_testkit::tools::have(&["yosys", "sta"], "tofprobe-flow array_slices") {
        return;
    }
    let text = DEFAULT
        .replacen("duration_s = 1.0", "pulses = 4096", 1)
        .replacen("bins = 16", "bins = 1", 1)
        .replacen("rom_depth = 20000", "rom_depth = 4096", 1)
        + "\n[array]\nrows = 8\ncols = 8\npitch_um = 40.0\nmm_per_pixel = 1.0\n";
    let design = resolve(
        Document::from_toml_str(&text, "8x8.toml").expect("parses"),
        "8x8.toml",
    )
    .expect("resolves");
    let cache = std::env::temp_dir().join(format!("tofprobe-flow-slices-{}", std::process::id()));
    let libs = [(PathBuf::from(OSU018), None)];
    let whole = array_timing_with(&design, &libs, &cache, WHOLE_TIMING_MAX_PIXELS).unwrap();
    let sliced = array_timing_with(&design, &libs, &cache, 0).unwrap();
    assert_eq!(whole.len(), 1);
    assert_eq!(whole[0].netlist, "whole 8 × 8");
    assert_eq!(sliced.len(), 2);
    assert_eq!(sliced[0].netlist, "row 1 × 8");
    assert_eq!(sliced[1].netlist, "column 8 × 1");
    let worst = |f: fn(&tofprobe_flow::array_timing::ArrayTiming) -> f64| {
        sliced.iter().map(f).fold(0.0, f64::max)
    };
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
