//! Scaling area to another node and answering "how many bins fit a pixel".
//!
//! First-order assumption, stated in every report: area scales as (node / 130 nm)² from
//! sky130. Real libraries scale worse (wires, flop overhead), so the bin counts are an
//! upper bound of the right order, like the paper's own estimate.

use crate::error::{EdaError, Result};
use serde::{Deserialize, Serialize};

/// A linear area model A(B) = fixed + per_bin·B (µm², at the node it was fitted at).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct AreaModel {
    /// Area that does not grow with B (hold, prefilter, control, adders).
    pub fixed_um2: f64,
    /// Area per bin (two registers and their share of the routing).
    pub per_bin_um2: f64,
}

impl AreaModel {
    /// Least-squares line through (B, area) points; needs two distinct B.
    pub fn fit(points: &[(f64, f64)]) -> Result<Self> {
        let n = points.len() as f64;
        let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
        let my = points.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        if points.len() < 2 || sxx.is_nan() || sxx <= 0.0 {
            return Err(EdaError::OutOfRange {
                field: "area model points",
                value: format!("{} point(s)", points.len()),
                allowed: "at least two distinct bin counts".into(),
            });
        }
        let per_bin = sxy / sxx;
        Ok(Self {
            fixed_um2: my - per_bin * mx,
            per_bin_um2: per_bin,
        })
    }
}

/// (node / 130)²: the area factor from sky130 to `node_nm`.
pub fn node_factor(node_nm: f64) -> f64 {
    (node_nm / 130.0).powi(2)
}

/// One answer to "how many bins fit".
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct BinFit {
    /// Pixel side (µm); the pixel is square.
    pub pixel_side_um: f64,
    /// Target node (nm).
    pub node_nm: f64,
    /// Bins whose digital logic fits the whole pixel area (0 if even the fixed part does not).
    pub bins: u64,
    /// What the paper estimated, where it gave a number.
    pub paper_bins: Option<u64>,
    /// Bins if the pixel held nothing but the register file's flops (2·W smallest flops
    /// per bin, no enable/readout logic, no adders, no control): an upper bound, and the
    /// kind of count the paper's estimate matches (see [`implied_model`]).
    pub flop_only_bins: u64,
}

/// The routed macro's area over its synthesised cells (k = die / cell area) of one
/// technology, read from a layout report (`tofprobe layout`): what turns a synthesis area
/// into a routed one for the bins-per-pitch answer (first order: k is taken to hold for
/// other B and options on the same technology at the same density).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RoutedFactor {
    /// `osu018` or `sky130`: the liberties it applies to.
    pub technology: String,
    /// k = die area / synthesis cell area (> 1).
    pub factor: f64,
    /// Placement density the macro routed at.
    pub density: f64,
    /// The configuration that was laid out (its origin, as the layout report names it).
    pub config: String,
}

impl RoutedFactor {
    /// Whether a liberty (its library name) belongs to this technology.
    pub fn applies_to(&self, library: &str) -> bool {
        library
            .to_ascii_lowercase()
            .contains(&self.technology.to_ascii_lowercase())
    }
}

/// Bins that fit when a bin costs only its 2·W flops of `flop_um2` (sky130 area).
pub fn flop_only_bins(width: u32, flop_um2: f64, side_um: f64, node_nm: f64) -> u64 {
    let per_bin = 2.0 * f64::from(width) * flop_um2 * node_factor(node_nm);
    if per_bin > 0.0 && side_um.is_finite() {
        (side_um * side_um / per_bin).floor() as u64
    } else {
        0
    }
}

/// The sky130 (130 nm) area model two (pixel side, bins) estimates imply at `node_nm`:
/// side₁² = s·(F + n₁·b), side₂² = s·(F + n₂·b). None unless exactly two distinct counts.
pub fn implied_model(estimates: &[(f64, u64)], node_nm: f64) -> Option<AreaModel> {
    let [(s1, n1), (s2, n2)] = estimates else {
        return None;
    };
    if n1 == n2 {
        return None;
    }
    let f = node_factor(node_nm);
    let per_bin = (s2 * s2 - s1 * s1) / (*n2 as f64 - *n1 as f64) / f;
    Some(AreaModel {
        fixed_um2: s1 * s1 / f - *n1 as f64 * per_bin,
        per_bin_um2: per_bin,
    })
}

/// Bins that fit a `side`×`side` µm pixel at `node_nm`, for a sky130 area model.
pub fn bins_that_fit(model: &AreaModel, side_um: f64, node_nm: f64) -> Result<u64> {
    if !(side_um.is_finite() && side_um > 0.0 && node_nm.is_finite() && node_nm > 0.0) {
        return Err(EdaError::OutOfRange {
            field: "pixel side / node",
            value: format!("{side_um} µm / {node_nm} nm"),
            allowed: "finite, > 0".into(),
        });
    }
    if model.per_bin_um2.is_nan() || model.per_bin_um2 <= 0.0 {
        return Err(EdaError::OutOfRange {
            field: "per_bin_um2",
            value: model.per_bin_um2.to_string(),
            allowed: "> 0 (area must grow with B)".into(),
        });
    }
    let s = node_factor(node_nm);
    let room = side_um * side_um - model.fixed_um2.max(0.0) * s;
    Ok(if room <= 0.0 {
        0
    } else {
        (room / (model.per_bin_um2 * s)).floor() as u64
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_line() {
        let m = AreaModel::fit(&[(2.0, 1300.0), (4.0, 2300.0), (8.0, 4300.0)]).unwrap();
        assert!((m.per_bin_um2 - 500.0).abs() < 1e-9 && (m.fixed_um2 - 300.0).abs() < 1e-9);
        assert!(AreaModel::fit(&[(2.0, 1.0), (2.0, 3.0)]).is_err());
    }

    #[test]
    fn paper_estimates_imply_a_flop_only_bin() {
        // 6 bins in 30² and 13 in 40² µm at 40 nm: b = 700/7 = 100 µm², F = 300 µm² at
        // 40 nm; at 130 nm ÷ (40/130)²: b = 1056.25 µm², F = 3168.75 µm².
        let m = implied_model(&[(30.0, 6), (40.0, 13)], 40.0).unwrap();
        assert!((m.per_bin_um2 - 1056.25).abs() < 1e-9, "{m:?}");
        assert!((m.fixed_um2 - 3168.75).abs() < 1e-9, "{m:?}");
        // ≈ 2 × 26 bits of sky130 dfxtp_1 (20.0192 µm²) = 1041 µm²: flops alone.
        assert!((m.per_bin_um2 / (2.0 * 26.0 * 20.0192) - 1.0).abs() < 0.015);
        // Flop-only bound at W = 26: 1041 × 0.0947 = 98.6 µm²/bin → 9 in 900, 16 in 1600.
        assert_eq!(flop_only_bins(26, 20.0192, 30.0, 40.0), 9);
        assert_eq!(flop_only_bins(26, 20.0192, 40.0, 40.0), 16);
        assert!(implied_model(&[(30.0, 6)], 40.0).is_none());
    }

    #[test]
    fn bins_scale_with_node_squared() {
        assert!((node_factor(40.0) - (40.0f64 / 130.0).powi(2)).abs() < 1e-15);
        // 1000 µm²/bin and 500 fixed at 130 nm; at 40 nm ×0.09467: 94.67/bin, 47.3 fixed.
        // 900 µm²: (900 − 47.34)/94.67 = 9.006 → 9 bins; 1600: 16.4 → 16.
        let m = AreaModel {
            fixed_um2: 500.0,
            per_bin_um2: 1000.0,
        };
        assert_eq!(bins_that_fit(&m, 30.0, 40.0).unwrap(), 9);
        assert_eq!(bins_that_fit(&m, 40.0, 40.0).unwrap(), 16);
        assert_eq!(bins_that_fit(&m, 1.0, 130.0).unwrap(), 0);
    }
}
