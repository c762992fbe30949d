//! Bins per pitch from the routed macro.
//!
//! The synthesis answer (`tofprobe size`) fits A(B) = fixed + per_bin·B to the cell area of
//! two or more syntheses and gives the whole pixel to it. Layout adds placement density,
//! routing and the power grid: the routed macro's die is k = die area / cell area times
//! the cells (k = 1/utilisation of the die). The layout answer scales the same model by
//! the routed k of the configured pixel (the one routed: k is taken to hold for the other
//! B, a first-order assumption stated in the report), then to the target node by
//! (node / node of the technology)², as the synthesis answer does from sky130.

use serde::{Deserialize, Serialize};
use tofprobe_eda::scaling::{AreaModel, bins_that_fit, node_factor};

use crate::error::Result;

/// One pitch's answer.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct PitchBins {
    /// Pixel side (µm).
    pub side_um: f64,
    /// Bins from the routed macro's area.
    pub layout_bins: u64,
    /// Bins from the synthesis area (the same model without k).
    pub synthesis_bins: u64,
    /// The paper's estimate, where it gave one.
    pub paper_bins: Option<u64>,
}

/// The layout's bins per pitch.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct BinsPerPitch {
    /// Technology node the areas are in (nm).
    pub tech_node_nm: f64,
    /// Node the answer is scaled to (nm).
    pub target_node_nm: f64,
    /// Area scale from the technology to the target, (target / tech)².
    pub area_factor: f64,
    /// The synthesis model (µm² at the technology's node).
    pub synthesis_model: AreaModel,
    /// die area / synthesis cell area of the routed pixel.
    pub routed_factor: f64,
    /// Per pitch.
    pub pitches: Vec<PitchBins>,
    /// The side of a square pitch the routed macro itself needs at the target node (µm):
    /// √(die area · area factor).
    pub routed_side_um: f64,
}

/// Bins per pitch for `model` (synthesis, at `tech_node_nm`) inflated by `routed_factor`;
/// `die_area_um2` is the routed macro's.
pub fn bins_per_pitch(
    model: AreaModel,
    routed_factor: f64,
    die_area_um2: f64,
    tech_node_nm: f64,
    target_node_nm: f64,
    pitches: &[(f64, Option<u64>)],
) -> Result<BinsPerPitch> {
    // bins_that_fit scales by (node / 130)²: express the model in sky130-equivalent µm²
    // so that the scale is (target / tech)².
    let to130 = node_factor(130.0) / node_factor(tech_node_nm);
    let scaled = |k: f64| AreaModel {
        fixed_um2: model.fixed_um2 * k * to130,
        per_bin_um2: model.per_bin_um2 * k * to130,
    };
    let mut out = Vec::new();
    for &(side, paper) in pitches {
        out.push(PitchBins {
            side_um: side,
            layout_bins: bins_that_fit(&scaled(routed_factor), side, target_node_nm)?,
            synthesis_bins: bins_that_fit(&scaled(1.0), side, target_node_nm)?,
            paper_bins: paper,
        });
    }
    Ok(BinsPerPitch {
        tech_node_nm,
        target_node_nm,
        area_factor: (target_node_nm / tech_node_nm).powi(2),
        routed_side_um: (die_area_um2 * (target_node_nm / tech_node_nm).powi(2)).sqrt(),
        synthesis_model: model,
        routed_factor,
        pitches: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_routed_factor_shrinks_the_count_by_its_inverse() {
        // At the technology's own node: side² = k·(F + n·b) → n = (side²/k − F)/b.
        let m = AreaModel {
            fixed_um2: 100.0,
            per_bin_um2: 50.0,
        };
        let r = bins_per_pitch(m, 2.0, 900.0, 180.0, 180.0, &[(40.0, Some(13))]).unwrap();
        assert!((r.routed_side_um - 30.0).abs() < 1e-12);
        // 1600/2 = 800 → (800 − 100)/50 = 14; without k: (1600 − 100)/50 = 30.
        assert_eq!(r.pitches[0].layout_bins, 14);
        assert_eq!(r.pitches[0].synthesis_bins, 30);
        // At 90 nm from 180 nm the area is a quarter: 6400/2 = 3200 → 62.
        let r = bins_per_pitch(m, 2.0, 900.0, 180.0, 90.0, &[(40.0, None)]).unwrap();
        assert!((r.routed_side_um - 15.0).abs() < 1e-12);
        assert_eq!(r.pitches[0].layout_bins, 62);
        assert!((r.area_factor - 0.25).abs() < 1e-15);
        // A model that does not grow with B is refused.
        let flat = AreaModel {
            fixed_um2: 1.0,
            per_bin_um2: 0.0,
        };
        assert!(bins_per_pitch(flat, 2.0, 900.0, 180.0, 90.0, &[(40.0, None)]).is_err());
    }
}
