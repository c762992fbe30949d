//! One architecture option on one liberty: the configured pixel and a quarter-B variant
//! synthesised with the delay-driven flow (cached by RTL hash, as `tofprobe size`), the
//! linear area model A(B) = fixed + per_bin·B through them, the timing verdict at
//! C·f_laser, and the bins that fit a pixel pitch at the target node.

use std::path::Path;

use serde::Serialize;
use tofprobe_eda::analysis::analyse_points;
use tofprobe_eda::corners::CornerTiming;
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::scaling::{AreaModel, BinFit, RoutedFactor, bins_that_fit, flop_only_bins};
use tofprobe_pixel::PixelParams;

use crate::error::ExperimentError;

/// The node a library was characterised at (nm), from its name: osu018 180 nm (TSMC 0.18 µm
/// rules), sky130 130 nm; any other library is taken as 130 nm and the assumption says so.
pub fn library_node_nm(library: &str) -> f64 {
    let l = library.to_ascii_lowercase();
    if l.contains("osu018") || l.contains("osu_018") {
        180.0
    } else {
        130.0
    }
}

/// An option's area and timing on one library.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct LibraryArea {
    /// `library (NAME)`.
    pub library: String,
    /// The node the library was characterised at (nm), the base of the scaling.
    pub library_node_nm: f64,
    /// Area of the configured pixel (µm², at the library's node).
    pub total_area_um2: f64,
    /// Its register file (µm²): flops, their enables or clock gates; or latches, their
    /// gates and the enable and word flops.
    pub register_file_um2: f64,
    /// Cells counted at their LEF outline (µm² each) because the liberty gives them area 0
    /// (osu018's `LATCH`); empty when none is used.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub area_from_lef: std::collections::BTreeMap<String, f64>,
    /// Fixed area and area per bin (µm², library node) through the configured B and B/4.
    pub model: AreaModel,
    /// The timing verdict at C·f_laser, when the library carries timing.
    pub timing: Option<CornerTiming>,
    /// Bins that fit each pitch at the target node, area scaled by (node / library node)².
    pub fits: Vec<BinFit>,
    /// The same from layout: the area model times the routed factor k of a layout report
    /// of this library's technology (`size --options --layout-report`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layout_fits: Option<Vec<BinFit>>,
}

/// What [`measure`] needs besides the pixel.
#[derive(Debug)]
pub struct AreaRequest<'a> {
    /// The library.
    pub lib: &'a Liberty,
    /// Synthesis cache.
    pub cache: &'a Path,
    /// Laser pulse rate (Hz).
    pub laser_rate_hz: f64,
    /// Node for the bins-per-pitch answer (nm).
    pub node_nm: f64,
    /// Pitches (µm) with the paper's estimate where it gave one.
    pub pixel_sides_um: &'a [(f64, Option<u64>)],
    /// The B sweep of the area model (see [`model_bins`]).
    pub sweep_bins: &'a [u64],
    /// A routed factor k: bins per pitch from layout too, when it applies to the library.
    pub routed: Option<&'a RoutedFactor>,
}

/// The B points of the area model: the configured B and the sweep's points up to it; when
/// that is one point, ⌈B/4⌉ beside it (none for B = 1).
pub fn model_bins(bins: u64, sweep: &[u64]) -> Vec<u64> {
    let mut v: Vec<u64> = sweep
        .iter()
        .copied()
        .filter(|&b| b >= 1 && b <= bins)
        .collect();
    v.push(bins);
    if v.iter().all(|&b| b == bins) {
        v.push(bins.div_ceil(4).max(1));
    }
    v.sort_unstable();
    v.dedup();
    v.reverse();
    v
}

/// Synthesises `pixel` at the [`model_bins`] on `req.lib` and answers for it.
pub fn measure(pixel: &PixelParams, req: &AreaRequest<'_>) -> Result<LibraryArea, ExperimentError> {
    let provider = GeneratedPixel {
        base: pixel.clone(),
    };
    let b = pixel.bins as u64;
    // The configured B first: `results[0]` is the pixel itself.
    let points: Vec<(u64, u32)> = model_bins(b, req.sweep_bins)
        .into_iter()
        .map(|x| (x, pixel.width))
        .collect();
    let clock_mhz = pixel.cycles_per_pulse as f64 * req.laser_rate_hz / 1e6;
    let results = analyse_points(
        &provider,
        &points,
        req.lib,
        true,
        "clk",
        req.cache,
        Some(1e6 / clock_mhz),
    )?;
    let main = &results[0];
    let xy: Vec<(f64, f64)> = results
        .iter()
        .map(|r| (r.bins as f64, r.synthesis.total_area_um2))
        .collect();
    // One point (B = 1): everything is "per bin", nothing fixed.
    let model = AreaModel::fit(&xy).unwrap_or(AreaModel {
        fixed_um2: 0.0,
        per_bin_um2: main.synthesis.total_area_um2 / b.max(1) as f64,
    });
    let lib_node = library_node_nm(&req.lib.name);
    // bins_that_fit scales from sky130's 130 nm: re-base the model to 130 nm first.
    let to130 = (130.0 / lib_node).powi(2);
    let rebased = AreaModel {
        fixed_um2: model.fixed_um2 * to130,
        per_bin_um2: model.per_bin_um2 * to130,
    };
    let flop = req.lib.smallest_flop().map_or(0.0, |f| f.1) * to130;
    // The routed area is k × the cells (`tofprobe layout`'s bins per pitch, the same
    // scaling): the flop-only bound stays the synthesis one.
    let fits_at = |k: f64| -> Result<Vec<BinFit>, ExperimentError> {
        let model = AreaModel {
            fixed_um2: rebased.fixed_um2 * k,
            per_bin_um2: rebased.per_bin_um2 * k,
        };
        let mut fits = Vec::new();
        for &(side, paper) in req.pixel_sides_um {
            fits.push(BinFit {
                pixel_side_um: side,
                node_nm: req.node_nm,
                bins: bins_that_fit(&model, side, req.node_nm)?,
                paper_bins: paper,
                flop_only_bins: flop_only_bins(pixel.width, flop, side, req.node_nm),
            });
        }
        Ok(fits)
    };
    let fits = fits_at(1.0)?;
    let layout_fits = match req.routed {
        Some(k) if k.applies_to(&req.lib.name) => Some(fits_at(k.factor)?),
        _ => None,
    };
    let corner = if req.lib.name.contains("sky130") {
        "tt_025C_1v80"
    } else {
        "typical"
    };
    Ok(LibraryArea {
        library: req.lib.name.clone(),
        library_node_nm: lib_node,
        total_area_um2: main.synthesis.total_area_um2,
        register_file_um2: main.split.register_file.area_um2,
        area_from_lef: main.synthesis.area_from_lef.clone(),
        model,
        timing: main.timing.as_ref().map(|t| {
            CornerTiming::new(
                &req.lib.name,
                corner,
                &req.lib.path,
                t,
                clock_mhz,
                req.laser_rate_hz,
            )
        }),
        fits,
        layout_fits,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_points() {
        assert_eq!(model_bins(16, &[4, 8, 16]), [16, 8, 4]);
        assert_eq!(model_bins(16, &[16]), [16, 4]);
        assert_eq!(model_bins(2, &[2]), [2, 1]);
        assert_eq!(model_bins(1, &[1]), [1]);
        assert_eq!(model_bins(8, &[32, 4]), [8, 4]);
    }

    #[test]
    fn nodes_from_library_names() {
        assert_eq!(library_node_nm("osu018_stdcells"), 180.0);
        assert_eq!(library_node_nm("sky130_fd_sc_hd__tt_025C_1v80"), 130.0);
    }
}
