//! The statistical and closed-form levels against the bit-true array on the same scene
//! and seeds (a 8 × 8 plate, 2 ROM periods per frame, several seeds).
//!
//! Noise: each level's per-pixel register variance is estimated from the spread across
//! S seeds (the sample variance about each pixel's own mean, so no model of the mean
//! enters), pooled over the P pixels and R registers: P·R·(S − 1) degrees of freedom each.
//! The log of a ratio of two such pooled variances has sd ≈ sqrt(2/ν₁ + 2/ν₂) (the
//! χ² approximation, for Gaussian sums over N pulses); with ν = 64·8·3 = 1536 that is
//! 0.051, so ±5 sd accepts ratios in [0.77, 1.29] and a model whose noise is scaled by 2
//! (ratio 4) fails by far.
//!
//! Mean: the bit-true registers averaged over S seeds against the closed-form level's
//! registers, each difference in units of its standard error (the bit-true sd of that
//! register pooled over the 64 pixels, whose noise is alike, / √S): for an unbiased mean
//! z² averages 1 with sd ≈ sqrt(2/512) = 0.063 over the 512 registers, so 1.35 (5.5 sd)
//! bounds it; a mean off by the spread (z² + 1) fails.

use tofprobe_array::model::run_array;
use tofprobe_array::statistical::StatisticalModel;
use tofprobe_design::ResolvedDesign;

use crate::common::{design, plate};

const SEEDS: u64 = 4;

fn array(level: &str) -> String {
    format!("rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 10.0\nlevel = \"{level}\"")
}

fn with_seed(d: &ResolvedDesign, seed: u64) -> ResolvedDesign {
    let mut doc = d.document.clone();
    doc.acquisition.seed = seed;
    tofprobe_design::resolve(doc, &d.origin).unwrap()
}

/// The frames (registers per pixel, as f64) of `seeds` seeds at `level`, optionally with a
/// statistical model whose noise is scaled.
fn frames(level: &str, noise_scale: Option<f64>) -> Vec<Vec<f64>> {
    let base = design(&plate(2, 1), 40_000, &array(level));
    (1..=SEEDS)
        .map(|s| {
            let d = with_seed(&base, s);
            let rom = d.probe_rom().unwrap().unwrap();
            let regs = match noise_scale {
                Some(k) => {
                    let m = StatisticalModel::new(&d, &rom).unwrap().with_noise_scale(k);
                    m.run_tile(&d, 0..8, 0..8, &Default::default())
                        .unwrap()
                        .registers
                }
                None => run_array(&d, Some(&rom.image)).unwrap().registers,
            };
            regs.iter().map(|&w| w as f64).collect()
        })
        .collect()
}

/// Pooled within-pixel variance across seeds and its degrees of freedom.
fn pooled_variance(f: &[Vec<f64>]) -> (f64, f64) {
    let (s, m) = (f.len() as f64, f[0].len());
    let mut ss = 0.0;
    for i in 0..m {
        let mean = f.iter().map(|x| x[i]).sum::<f64>() / s;
        ss += f.iter().map(|x| (x[i] - mean).powi(2)).sum::<f64>();
    }
    let dof = m as f64 * (s - 1.0);
    (ss / dof, dof)
}

#[test]
fn statistical_noise_matches_the_bit_true_spread_and_a_doubled_noise_fails() {
    let bt = frames("bit-true", None);
    let (v_bt, nu_bt) = pooled_variance(&bt);
    let (v_st, nu_st) = pooled_variance(&frames("statistical", None));
    let (v_2, _) = pooled_variance(&frames("statistical", Some(2.0)));
    let sd = (2.0 / nu_bt + 2.0 / nu_st).sqrt();
    let r = (v_st / v_bt).ln();
    eprintln!(
        "variance ratio statistical/bit-true {:.3} (sd of its log {sd:.3}); doubled {:.3}",
        v_st / v_bt,
        v_2 / v_bt
    );
    assert!(
        r.abs() < 5.0 * sd,
        "statistical/bit-true variance {:.3}",
        v_st / v_bt
    );
    assert!(
        (v_2 / v_bt).ln().abs() > 5.0 * sd,
        "a doubled noise passed: {:.3}",
        v_2 / v_bt
    );
}

#[test]
fn closed_form_is_the_bit_true_mean_within_its_spread() {
    let bt = frames("bit-true", None);
    let base = design(&plate(2, 1), 40_000, &array("closed-form"));
    let rom = base.probe_rom().unwrap().unwrap();
    let cf: Vec<f64> = run_array(&base, Some(&rom.image))
        .unwrap()
        .registers
        .iter()
        .map(|&w| w as f64)
        .collect();
    let s = SEEDS as f64;
    let k = 8; // registers per pixel
    let mean = |i: usize| bt.iter().map(|x| x[i]).sum::<f64>() / s;
    let var: Vec<f64> = (0..k)
        .map(|r| {
            let idx: Vec<usize> = (r..cf.len()).step_by(k).collect();
            let ss: f64 = idx
                .iter()
                .map(|&i| bt.iter().map(|x| (x[i] - mean(i)).powi(2)).sum::<f64>())
                .sum();
            ss / (idx.len() as f64 * (s - 1.0))
        })
        .collect();
    let z2: Vec<f64> = (0..cf.len())
        .map(|i| (mean(i) - cf[i]).powi(2) / (var[i % k] / s))
        .collect();
    let m = z2.iter().sum::<f64>() / z2.len() as f64;
    eprintln!("mean z² {m:.3}");
    assert!(
        m < 1.35,
        "closed-form mean off the bit-true mean: mean z² = {m}"
    );
}

/// Tiles on pools of 1 and 2 threads merge into the whole array's statistical frame
/// byte for byte (per-pixel seeds).
#[test]
fn statistical_tiles_merge_into_the_whole_frame() {
    let d = design(&plate(2, 1), 40_000, &array("statistical"));
    crate::common::assert_tiles_merge(&d, &[(0..3, 0..8, 1), (3..8, 0..8, 2)]);
}

/// A level that does not exist lists the allowed names; a Haar pixel at the statistical
/// level is refused naming the key and the level that runs it.
#[test]
fn bad_levels_are_refused_with_the_way_out() {
    let text = crate::common::text(&plate(2, 1), 40_000, &array("fast"));
    let e = tofprobe_design::Document::from_toml_str(&text, "t.toml")
        .map(|d| tofprobe_design::resolve(d, "t.toml").map(|_| ()))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    for want in ["level", "bit-true", "statistical", "closed-form", "auto"] {
        assert!(e.contains(want), "{e}");
    }
    let t = crate::common::text(&plate(2, 1), 1 << 15, &array("statistical"));
    let head = t.split("[probe]").next().unwrap();
    let tail = &t[t.find("[array]").unwrap()..];
    let t = format!("{head}{tail}").replacen(
        "mode = \"fourier\"",
        "mode = \"haar\"\nhaar_scales = 4",
        1,
    );
    // Auto runs pixels at the statistical level: refused the same way, naming itself.
    for level in ["statistical", "auto"] {
        let t = t.replacen(
            "level = \"statistical\"",
            &format!("level = \"{level}\""),
            1,
        );
        let d = tofprobe_design::Document::from_toml_str(&t, "t.toml").unwrap();
        let e = tofprobe_design::resolve(d, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("array.level = \"{level}\"")) && e.contains("\"bit-true\""),
            "{e}"
        );
    }
}
