//! The rule of `[array] level = "auto"` (docs/tradeoff.md "Array levels"): a pixel runs
//! bit-true where its motion shows in its registers, at the statistical level where its
//! scene is static or its motion is far below its noise floor. Decided per pixel from the
//! scene and the closed forms alone (no pulse is drawn to decide), so the map depends on
//! nothing but the design: not the seed, the tiling, the threads or the process.
//!
//! The rule: pixel (r, c) moves when, for some register i, the motion's noise-free
//! response |Δμ_i| (the statistical model's mean with the pixel's sines minus its mean
//! without them, through the twin and the 1NN hold's H(ρ_v, ω)) exceeds K·σ_i, σ_i the
//! register's closed-form noise sd (the row norm of the covariance's Cholesky factor).
//! A pixel without sines has Δμ = 0 and never moves; nor does a pixel without detections.
//!
//! The threshold K is `[array] auto_threshold`, by default
//! [`tofprobe_design::array::AUTO_THRESHOLD`] = 0.5. Where a pixel runs statistical its motion
//! moves no register by more than K·σ_i: even if the statistical level got that motion
//! entirely wrong (it models it linearly, through the hold; what it leaves out — the
//! quantisation and the window's wrap of a moving code, the hold of a moving signal — is a
//! fraction of it), the error added to a register is below K·σ_i, so the register's
//! spread against the bit-true one is at most √(1 + K²) = 1.12 × the bit-true spread,
//! inside the 1.2× bar (K ≤ 0.66 meets it; 0.5 leaves room for the statistical
//! level's own 1.03× noise ratio).

use tofprobe_design::{ArrayLevel, ResolvedDesign};

use super::StatisticalModel;
use super::pixel::{CodeStats, PixelScene};
use crate::error::ArrayError;

/// Whether a pixel of scene `px`, code statistics `stats` and noise Cholesky factor `chol`
/// (R × R, lower, row-major) runs bit-true under threshold `threshold` (the rule above).
pub fn moves(
    model: &StatisticalModel,
    px: &PixelScene,
    stats: &CodeStats,
    chol: &[f64],
    threshold: f64,
) -> bool {
    if px.sines.is_empty() {
        return false;
    }
    let still = PixelScene {
        key: px.key,
        sines: Vec::new(),
    };
    let (m, m0) = (model.mean(px, stats), model.mean(&still, stats));
    let r = m.len();
    (0..r).any(|i| {
        let sd = chol[i * r..(i + 1) * r]
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt();
        (m[i] - m0[i]).abs() > threshold * sd
    })
}

/// The level each pixel of `design`'s array runs at, row-major [R, C]: `[array] level`
/// everywhere, or under `"auto"` bit-true where the pixel moves ([`moves`] with
/// K = `[array] auto_threshold`) and statistical elsewhere. A function of the design alone, so the
/// output set's level map (`level.npy`) is the same from one run, tiles or shards.
pub fn level_map(design: &ResolvedDesign) -> Result<Vec<ArrayLevel>, ArrayError> {
    let a = design
        .array
        .as_ref()
        .ok_or_else(|| ArrayError::Shape(format!("`{}` has no [array]", design.origin)))?;
    if a.level != ArrayLevel::Auto {
        return Ok(vec![a.level; a.rows * a.cols]);
    }
    let model = super::shared_model(design, ArrayLevel::Statistical)?;
    let moving = model.auto_levels(design, 0..a.rows, 0..a.cols, a.auto_threshold)?;
    Ok(moving
        .into_iter()
        .map(|m| {
            if m {
                ArrayLevel::BitTrue
            } else {
                ArrayLevel::Statistical
            }
        })
        .collect())
}

/// The code of `level` in `level.npy`: its index in [`ArrayLevel::ALL`] (0 bit-true,
/// 1 statistical, 2 closed-form).
pub fn level_code(level: ArrayLevel) -> i64 {
    ArrayLevel::ALL
        .iter()
        .position(|&l| l == level)
        .unwrap_or(0) as i64
}
