//! Sharding: the partition of an R × C array into n tiles (every pixel exactly once, in
//! order, deterministic), the shares of a soak, `i/n` parsing, and tile sets written by
//! `run_shard` merging into the very set `run_and_write` writes, with every refusal
//! naming the offending set.

use std::path::{Path, PathBuf};

use tofprobe_array::shard::{self, Shard};

use crate::common::{design, plate};

#[test]
fn tiles_cover_every_pixel_once_in_order() {
    for (rows, cols) in [(1, 1), (4, 3), (3, 7), (16, 5)] {
        for n in 1..=rows * cols {
            let t = shard::tiles(rows, cols, n).unwrap();
            assert_eq!(t.len(), n, "{rows}×{cols} n={n}");
            let mut seen = vec![0u32; rows * cols];
            for (rs, cs) in &t {
                assert!(
                    !rs.is_empty() && !cs.is_empty(),
                    "{rows}×{cols} n={n}: empty tile"
                );
                for r in rs.clone() {
                    for c in cs.clone() {
                        seen[r * cols + c] += 1;
                    }
                }
            }
            assert!(
                seen.iter().all(|&s| s == 1),
                "{rows}×{cols} n={n}: {seen:?}"
            );
            // Balanced: pixels per tile differ by at most a factor (row bands within one
            // row, pieces within one column of each other).
            let sizes: Vec<usize> = t.iter().map(|(r, c)| r.len() * c.len()).collect();
            let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
            assert!(hi - lo <= cols.max(2), "{rows}×{cols} n={n}: {sizes:?}");
            assert_eq!(t, shard::tiles(rows, cols, n).unwrap(), "deterministic");
        }
        assert!(shard::tiles(rows, cols, 0).is_err());
        let e = shard::tiles(rows, cols, rows * cols + 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("1 ..= {}", rows * cols)), "{e}");
    }
    // 4 × 3 in 5: three row bands would be too few, so rows are cut: 1+1+1+2 pieces.
    let t = shard::tiles(4, 3, 5).unwrap();
    assert_eq!(
        t,
        vec![
            (0..1, 0..3),
            (1..2, 0..3),
            (2..3, 0..3),
            (3..4, 0..1),
            (3..4, 1..3)
        ]
    );
}

#[test]
fn shares_cover_a_soak_exactly_once() {
    for total in [0u64, 1, 7, 100, 100_001] {
        for count in 1..=9u64 {
            let mut next = 0;
            for index in 0..count {
                let r = shard::share(total, Shard { index, count });
                assert_eq!(r.start, next);
                assert!(r.end - r.start <= total / count + 1);
                next = r.end;
            }
            assert_eq!(next, total);
        }
    }
    assert_eq!(shard::share(10, Shard { index: 1, count: 3 }), 3..6);
}

#[test]
fn shard_parses_i_of_n_and_names_a_bad_one() {
    assert_eq!(Shard::parse("2/5"), Ok(Shard { index: 2, count: 5 }));
    assert_eq!(Shard::parse("0/1").unwrap().to_string(), "0/1");
    for bad in ["5/5", "1/0", "3", "-1/4", "a/b", "1/2/3", ""] {
        let e = Shard::parse(bad).unwrap_err();
        assert!(
            e.contains(&format!("`{bad}`")) && e.contains("0 ≤ i < n"),
            "{bad}: {e}"
        );
    }
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// summary.json without its timing figures (they differ between any two runs).
fn timeless(bytes: &[u8]) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(bytes).unwrap();
    let o = v.as_object_mut().unwrap();
    assert!(o.remove("model_seconds").is_some() && o.remove("pixel_pulses_per_s").is_some());
    v
}

fn sets(root: &Path, d: &tofprobe_design::ResolvedDesign, n: u64) -> Vec<PathBuf> {
    (0..n)
        .map(|index| {
            let dir = root.join(format!("tile-{index}-of-{n}"));
            let m = shard::run_shard(d, Shard { index, count: n }, &dir).unwrap();
            assert_eq!(m.seed, d.document.acquisition.seed);
            dir
        })
        .collect()
}

#[test]
fn tile_sets_merge_into_the_single_runs_set_byte_for_byte() {
    let arr = "rows = 4\ncols = 3\npitch_um = 30.0\nmm_per_pixel = 20.0";
    merges_into_the_whole(&design(&plate(2, 1), 40_000, arr));
}

/// The same at `level = "auto"` on a plate moving one half of the array (the level map
/// mixes bit-true and statistical pixels; both merge byte for byte, the map with them).
#[test]
fn auto_tile_sets_merge_into_the_single_runs_set_byte_for_byte() {
    let arr = "rows = 4\ncols = 3\npitch_um = 30.0\nmm_per_pixel = 20.0\nlevel = \"auto\"";
    let d = design(&crate::auto::half_plate(40.0, 40.0, 80.0), 40_000, arr);
    let map = tofprobe_array::statistical::auto::level_map(&d).unwrap();
    assert!(map.iter().any(|l| l.is_bit_true()) && !map.iter().all(|l| l.is_bit_true()));
    merges_into_the_whole(&d);
}

fn merges_into_the_whole(d: &tofprobe_design::ResolvedDesign) {
    let d = d.clone();
    let tmp = tempfile::tempdir().unwrap();
    let whole = tmp.path().join("whole");
    tofprobe_array::output::run_and_write(&d, &whole, Default::default()).unwrap();
    let want = files(&whole);
    for n in [1u64, 2, 5, 12] {
        let mut dirs = sets(tmp.path(), &d, n);
        dirs.reverse(); // any order
        let out = tmp.path().join(format!("merged-{n}"));
        let s = shard::merge_sets(&dirs, &out, Default::default()).unwrap();
        assert_eq!(s.rows * s.cols, 12);
        let got = files(&out);
        assert_eq!(got.len(), want.len());
        for ((gn, gb), (wn, wb)) in got.iter().zip(&want) {
            assert_eq!(gn, wn);
            if gn == "summary.json" {
                assert_eq!(timeless(gb), timeless(wb), "n = {n}");
            } else if gn == tofprobe_io::SET_MARKER {
                // The same files with the same hashes, the summary's aside (its timing).
                let listed = |b: &[u8]| {
                    let mut f =
                        tofprobe_io::marker::marker_files(std::str::from_utf8(b).unwrap()).unwrap();
                    assert!(f.remove("summary.json").is_some());
                    f
                };
                assert_eq!(listed(gb), listed(wb), "n = {n}");
            } else {
                assert!(gb == wb, "{gn} differs after merging {n} tile sets");
            }
        }
    }
}

#[test]
fn merge_refuses_sets_of_another_run_naming_them() {
    let tmp = tempfile::tempdir().unwrap();
    let arr = "rows = 2\ncols = 2\npitch_um = 30.0\nmm_per_pixel = 20.0";
    let d = design(&plate(1, 1), 40_000, arr);
    let dirs = sets(tmp.path(), &d, 2);
    let out = tmp.path().join("out");
    let err = |dirs: &[PathBuf]| {
        shard::merge_sets(dirs, &out, Default::default())
            .unwrap_err()
            .to_string()
    };

    // Another seed.
    let mut reseeded = d.clone();
    reseeded.document.acquisition.seed = 9;
    let other = tmp.path().join("seed9");
    shard::run_shard(&reseeded, Shard { index: 1, count: 2 }, &other).unwrap();
    let e = err(&[dirs[0].clone(), other.clone()]);
    assert!(
        e.contains("seed9") && e.contains("seed 9") && e.contains("seed 1"),
        "{e}"
    );
    // Another configuration (a different motion), same shape.
    let d2 = design(&plate(2, 2), 40_000, arr);
    let cfg = tmp.path().join("otherconfig");
    shard::run_shard(&d2, Shard { index: 1, count: 2 }, &cfg).unwrap();
    let e = err(&[dirs[0].clone(), cfg]);
    assert!(
        e.contains("otherconfig") && e.contains("different design"),
        "{e}"
    );
    // Overlap: the same tile twice, and a tile of another partition.
    let e = err(&[dirs[0].clone(), dirs[1].clone(), dirs[1].clone()]);
    assert!(e.contains("overlaps") && e.contains("tile-1-of-2"), "{e}");
    let thirds = tmp.path().join("third");
    shard::run_shard(&d, Shard { index: 0, count: 4 }, &thirds).unwrap();
    let e = err(&[dirs[0].clone(), dirs[1].clone(), thirds]);
    assert!(
        e.contains("tile set") && e.contains("third:") && e.contains("overlaps"),
        "{e}"
    );
    // Missing: one share left out.
    let e = err(&[dirs[0].clone()]);
    assert!(
        e.contains("uncovered") && e.contains("pixel (1, 0)") && e.contains("1/2"),
        "{e}"
    );
    // Not a (finished) tile set.
    let e = err(&[dirs[0].clone(), tmp.path().join("nothing")]);
    assert!(
        e.contains("nothing") && e.contains("not a directory"),
        "{e}"
    );
    // Nothing was written by any refusal.
    assert!(!out.exists());
    // A single-pixel design has no shards.
    let single = tofprobe_design::load(None).unwrap();
    let e = shard::run_shard(&single, Shard { index: 0, count: 1 }, &tmp.path().join("x"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("[array]"), "{e}");
}
