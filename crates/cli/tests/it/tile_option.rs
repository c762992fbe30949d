//! Issue 45 item 2 (and item 9's `--tile` refusals): `cosim --tile ROW,COL,ROWS,COLS` at
//! 64-bit edges is refused before anything is built, exit 2, naming the option, its value
//! and the range that fits — never a panic (`0,0,1,2^64−1` and `0,0,2^32+1,2^32−1` once
//! exited 101) nor a wrapped bound (a ROW of 2^64−1 once passed the bounds check and
//! failed elsewhere). `--tile` beside `--random` or on a single pixel is refused, not
//! ignored, and a whole array too large to render is refused at once, naming `--tile`. No
//! tool is needed: every case stops before Verilator.

use std::time::Duration;

use crate::array_sets::plate;
use crate::bounds::{refused, run};

#[test]
fn tile_numbers_at_64_bit_edges_are_refused_naming_the_option() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = plate(tmp.path(), "p.toml", &[]);
    let cfg = cfg.to_str().unwrap();
    let out = tmp.path().join("co");
    let out = out.to_str().unwrap();
    let max = u64::MAX.to_string();
    let cases = [
        format!("0,0,1,{max}"),
        "0,0,4294967297,4294967295".to_string(),
        format!("{max},0,1,1"),
        format!("0,{max},1,1"),
        format!("{max},{max},{max},{max}"),
        "18446744073709551616,0,1,1".to_string(),
        "0,0,0,1".to_string(),
        "3,2,2,1".to_string(),
        "-1,0,1,1".to_string(),
        "0,0,1".to_string(),
        "0,0,1,1,1".to_string(),
        " , , , ".to_string(),
    ];
    for t in &cases {
        // `--tile=VALUE`: a value starting with `-` stays the option's.
        let arg = format!("--tile={t}");
        let r = run(&["cosim", cfg, &arg, "--out", out], Duration::from_secs(30));
        refused(&r, &["--tile", "is out of range", "4 × 3 array"]);
        assert!(r.stderr.contains(t.trim()), "{t}: {}", r.stderr);
        assert!(r.seconds < 5.0, "{t}: {} s", r.seconds);
    }
    // The message says what fits.
    let r = run(
        &[
            "cosim",
            cfg,
            "--tile",
            &format!("0,0,1,{max}"),
            "--out",
            out,
        ],
        Duration::from_secs(30),
    );
    refused(&r, &["ROW + ROWS <= 4 and COL + COLS <= 3"]);
    // Beside --random, or on a single pixel: refused, not ignored.
    let r = run(
        &["cosim", "--random", "2", "--tile", "0,0,1,1", "--out", out],
        Duration::from_secs(30),
    );
    refused(&r, &["--random", "--tile"]);
    let r = run(
        &[
            "cosim",
            "--tile",
            "0,0,1,1",
            "--frame-pulses",
            "64",
            "--out",
            out,
        ],
        Duration::from_secs(30),
    );
    refused(&r, &["--tile", "[array] configuration only"]);
    // A 128 × 128 array, whole: refused at once, naming the keys and --tile.
    let big = plate(
        tmp.path(),
        "big.toml",
        &[("rows = 4", "rows = 128"), ("cols = 3", "cols = 128")],
    );
    let r = run(
        &["cosim", big.to_str().unwrap(), "--out", out],
        Duration::from_secs(30),
    );
    refused(
        &r,
        &["--tile", "128 × 128", "array.rows × array.cols", "64 × 64"],
    );
    assert!(r.seconds < 5.0, "{} s", r.seconds);
}
