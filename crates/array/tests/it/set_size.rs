//! The output set's size, known before any work (`set_plan::array_set`, `tile_set`): every
//! file of a written set is within its bound, the `.npy` files and `vibration.uff` exactly
//! (their layouts are fixed-width), the SVGs from their per-cell bounds; the files and their
//! order are the set's. A set larger than `--max-out-gib` is refused before the model runs,
//! naming the option, the estimate and what fits, and writes nothing.

use std::collections::BTreeMap;
use std::path::Path;

use tofprobe_array::output::{SetLimits, run_and_write};
use tofprobe_array::set_plan::{self, MARKER};
use tofprobe_array::shard::{self, Shard};

use crate::common::{design, haar_design, plate};

fn sizes(dir: &Path) -> BTreeMap<String, u64> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                e.metadata().unwrap().len(),
            )
        })
        .collect()
}

/// Checks the written `dir` against the `planned` files: the same names (and the marker),
/// each within its bound, the exact ones exact; returns (written, planned) totals.
fn check(dir: &Path, planned: &[set_plan::SetFile]) -> (u64, u64) {
    let got = sizes(dir);
    let mut names: Vec<&str> = planned.iter().map(|f| f.name.as_str()).collect();
    names.push(MARKER);
    names.sort();
    assert_eq!(got.keys().map(String::as_str).collect::<Vec<_>>(), names);
    for f in planned {
        let g = got[&f.name];
        assert!(
            g <= f.bytes,
            "{}: {g} bytes written, bound {}",
            f.name,
            f.bytes
        );
        if f.name.ends_with(".npy") || f.name.ends_with(".uff") {
            assert_eq!(g, f.bytes, "{} is sized exactly", f.name);
        }
    }
    let written = planned.iter().map(|f| got[&f.name]).sum();
    (written, set_plan::total_bytes(planned))
}

#[test]
fn written_sets_are_within_their_estimates() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "fourier 12 x 10",
            design(
                &plate(2, 1),
                20_000,
                "rows = 12\ncols = 10\npitch_um = 30.0\nmm_per_pixel = 8.0",
            ),
        ),
        (
            "haar 5 x 7",
            haar_design(
                &plate(1, 1),
                4096,
                "rows = 5\ncols = 7\npitch_um = 30.0\nmm_per_pixel = 8.0",
            ),
        ),
        (
            "superpixel 8 x 8 SPADs",
            design(
                &plate(1, 1),
                20_000,
                "rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 8.0\nsuperpixel = 2",
            ),
        ),
    ];
    for (what, d) in cases {
        let dir = tmp.path().join(what.replace(' ', "-"));
        let planned = set_plan::array_set(&d).unwrap();
        run_and_write(&d, &dir, SetLimits::default()).unwrap();
        let (written, bound) = check(&dir, &planned);
        eprintln!("{what}: {written} bytes written, {bound} estimated");
        // The SVG frames are bounded at 48 KiB each (a few kB drawn): small arrays are
        // over-estimated, but never by more than the frames' slack and 2×.
        assert!(
            bound <= 2 * written + 48 * 1024 * 16,
            "{what}: {bound} vs {written}"
        );
        // A tile set: its three planned files (and the maps), each within its bound.
        let a = d.array.as_ref().unwrap();
        let t = tmp.path().join(format!("{}-tile", what.replace(' ', "-")));
        let m = shard::run_shard(&d, Shard { index: 1, count: 2 }, &t).unwrap();
        let got = sizes(&t);
        for f in set_plan::tile_set(&d, m.rows.len(), m.cols.len()) {
            assert!(
                got[&f.name] <= f.bytes,
                "{what} tile {}: {} > {}",
                f.name,
                got[&f.name],
                f.bytes
            );
        }
        assert!(a.pixels() > 0);
    }
}

#[test]
fn a_set_above_its_cap_is_refused_before_the_model_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let d = design(
        &plate(2, 1),
        20_000,
        "rows = 64\ncols = 64\npitch_um = 30.0\nmm_per_pixel = 2.0",
    );
    let dir = tmp.path().join("out");
    let total = set_plan::total_bytes(&set_plan::array_set(&d).unwrap());
    let limits = SetLimits {
        max_set_bytes: total - 1,
    };
    let t0 = std::time::Instant::now();
    let e = run_and_write(&d, &dir, limits).unwrap_err().to_string();
    assert!(
        t0.elapsed().as_secs_f64() < 1.0,
        "refused after the model ran"
    );
    assert!(
        e.contains("--max-out-gib")
            && e.contains("would take")
            && e.contains("vibration.uff")
            && e.contains("array.rows = array.cols = 63 SPADs fits"),
        "{e}"
    );
    assert!(!dir.exists(), "a refused set wrote {dir:?}");
    // At the estimate itself it is written.
    run_and_write(
        &d,
        &dir,
        SetLimits {
            max_set_bytes: total,
        },
    )
    .unwrap();
}
