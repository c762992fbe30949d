//! `[array] level = "auto"`: its level map against the scene (a plate moving one half of
//! an 8 × 8 array, the other half static: exactly the moving half bit-true), a motion far
//! below the noise floor run statistical (which a threshold of 0 — a deliberately wrong
//! rule — runs bit-true, so the test fails it), the auto frame's pixels against the
//! bit-true and the statistical frames on the same seeds (bit for bit: per-pixel seeds),
//! and tiles on pools of 1 and 2 threads merging into the whole auto frame.

use tofprobe_array::model::run_array;
use tofprobe_array::statistical::auto::level_map;
use tofprobe_array::statistical::shared_model;
use tofprobe_design::array::AUTO_THRESHOLD;
use tofprobe_design::{ArrayLevel, ResolvedDesign};

use crate::common::design;

/// A (1, 1) plate mode of `lx` × `ly` mm from x = `x0` mm, 1 mm at 1.5 kHz: pixels whose
/// centre is left of `x0` see a static scene.
pub fn half_plate(x0: f64, lx: f64, ly: f64) -> String {
    format!(
        "[[scene.motion]]\nkind = \"plate_mode\"\nm = 1\nn = 1\nlength_x_mm = {lx}\n\
         length_y_mm = {ly}\nx0_mm = {x0}\namplitude_mm = {a}\nfrequency_hz = 1500.0\n",
        a = 1.0
    )
}

fn array(level: &str) -> String {
    format!("rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 10.0\nlevel = \"{level}\"")
}

/// The 8 × 8 array at `level` with the plate on its right half (cols 4..8, x ≥ 40 mm).
fn half(level: &str) -> ResolvedDesign {
    design(&half_plate(40.0, 40.0, 80.0), 40_000, &array(level))
}

#[test]
fn the_moving_half_runs_bit_true_and_only_it() {
    let d = half("auto");
    let map = level_map(&d).unwrap();
    for r in 0..8 {
        for c in 0..8 {
            let want = if c >= 4 {
                ArrayLevel::BitTrue
            } else {
                ArrayLevel::Statistical
            };
            assert_eq!(map[r * 8 + c], want, "pixel ({r}, {c})");
        }
    }
    // A rule that never runs a pixel bit-true (an infinite threshold) fails the map.
    let model = shared_model(&d, ArrayLevel::Statistical).unwrap();
    let never = model.auto_levels(&d, 0..8, 0..8, f64::INFINITY).unwrap();
    assert!(
        never.iter().all(|m| !m),
        "an infinite threshold moved a pixel"
    );
    // The summary counts the levels.
    let (_, _, s) = tofprobe_array::output::simulate(&d).unwrap();
    assert_eq!(s.level_pixels["bit-true"], 32);
    assert_eq!(s.level_pixels["statistical"], 32);
    assert_eq!(s.level_pixels["closed-form"] + s.level_pixels["auto"], 0);
}

/// A 10 µm plate: its response is 1 % of the 1 mm plate's, far below the noise floor, so
/// auto runs every pixel statistical; a threshold of 0 would run the moving ones bit-true.
/// The margins: the 1 mm plate's weakest moving pixel still moves at 2K, the 10 µm
/// plate's strongest stays still at K/2 (the rule is not balanced on its threshold).
#[test]
fn a_motion_far_below_the_noise_floor_runs_statistical() {
    let tiny = half_plate(40.0, 40.0, 80.0).replace("amplitude_mm = 1", "amplitude_mm = 0.01");
    let d = design(&tiny, 40_000, &array("auto"));
    let map = level_map(&d).unwrap();
    assert!(map.iter().all(|l| *l == ArrayLevel::Statistical), "{map:?}");
    let model = shared_model(&d, ArrayLevel::Statistical).unwrap();
    let zero = model.auto_levels(&d, 0..8, 0..8, 0.0).unwrap();
    assert_eq!(
        zero.iter().filter(|m| **m).count(),
        32,
        "a threshold of 0 runs every moving pixel bit-true"
    );
    // The margin: the largest threshold at which the 1 mm plate's weakest moving pixel
    // still moves, against the tiny plate's strongest.
    let big = half("auto");
    let big_model = shared_model(&big, ArrayLevel::Statistical).unwrap();
    let moves_at = |d: &ResolvedDesign, m: &tofprobe_array::statistical::StatisticalModel, k| {
        m.auto_levels(d, 0..8, 4..8, k).unwrap()
    };
    assert!(
        moves_at(&big, &big_model, 2.0 * AUTO_THRESHOLD)
            .iter()
            .all(|m| *m)
    );
    assert!(
        moves_at(&d, &model, AUTO_THRESHOLD / 2.0)
            .iter()
            .all(|m| !m)
    );
}

/// `[array] auto_threshold` reaches the rule: the map at K written in the configuration is
/// the model's map at that K (K = 0: the 32 moving pixels bit-true, also for the 10 µm
/// plate the default runs statistical; K = 10: fewer of the 1 mm plate's than K = 0.5).
#[test]
fn the_configured_threshold_is_the_rules() {
    let at = |amp: &str, k: f64| {
        let plate = half_plate(40.0, 40.0, 80.0).replace("amplitude_mm = 1", amp);
        let cfg = format!(
            "{}
auto_threshold = {k}",
            array("auto")
        );
        let d = design(&plate, 40_000, &cfg);
        assert_eq!(d.array.as_ref().unwrap().auto_threshold, k);
        let map = level_map(&d).unwrap();
        let model = shared_model(&d, ArrayLevel::Statistical).unwrap();
        let want = model.auto_levels(&d, 0..8, 0..8, k).unwrap();
        for (i, (l, m)) in map.iter().zip(&want).enumerate() {
            assert_eq!(*l == ArrayLevel::BitTrue, *m, "pixel {i} at K = {k}");
        }
        map.iter().filter(|l| **l == ArrayLevel::BitTrue).count()
    };
    assert_eq!(at("amplitude_mm = 0.01", 0.0), 32);
    assert_eq!(at("amplitude_mm = 0.01", AUTO_THRESHOLD), 0);
    // K = 10: only the plate's strongest pixels (near its antinode) still move.
    let strong = at("amplitude_mm = 1", 10.0);
    assert!(
        strong > 0 && strong < at("amplitude_mm = 1", AUTO_THRESHOLD),
        "{strong}"
    );
}

/// The auto frame's bit-true pixels are the bit-true frame's, its statistical pixels the
/// statistical frame's, bit for bit (same seed).
#[test]
fn auto_pixels_are_the_bit_true_and_statistical_runs_pixels() {
    let run = |level: &str| {
        let d = half(level);
        let rom = d.probe_rom().unwrap().unwrap();
        run_array(&d, Some(&rom.image)).unwrap()
    };
    let (auto, bt, st) = (run("auto"), run("bit-true"), run("statistical"));
    let map = level_map(&half("auto")).unwrap();
    for r in 0..8 {
        for c in 0..8 {
            let want = match map[r * 8 + c] {
                ArrayLevel::BitTrue => &bt,
                _ => &st,
            };
            assert_eq!(auto.pixel(r, c), want.pixel(r, c), "pixel ({r}, {c})");
            let i = r * 8 + c;
            assert_eq!(auto.detections[i], want.detections[i], "pixel ({r}, {c})");
        }
    }
    // The two levels differ at a moving pixel, so the comparison can fail.
    assert_ne!(bt.pixel(0, 5), st.pixel(0, 5));
}

/// Tiles on pools of 1 and 2 threads, cut across the static/moving boundary, merge into
/// the whole auto frame byte for byte.
#[test]
fn auto_tiles_merge_into_the_whole_frame() {
    crate::common::assert_tiles_merge(
        &half("auto"),
        &[(0..3, 0..8, 1), (3..8, 0..5, 2), (3..8, 5..8, 1)],
    );
}
