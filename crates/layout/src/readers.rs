//! Reading a layout report back (`tofprobe size --layout-report`, `size --options`): the
//! routed factor k and the post-route corners, each refused unless the report is of
//! [`SCHEMA`] and its macro clean (DRC 0, LVS match).

use serde::{Deserialize, Serialize};

use tofprobe_eda::scaling::RoutedFactor;

use crate::error::{LayoutError, Result};
use crate::report::{CornerRow, SCHEMA};

/// What the options study reads of a layout report: a partial view, so any report of
/// [`SCHEMA`] reads (fields it does not need are ignored).
#[derive(Debug, Deserialize)]
struct AreaView {
    tech: String,
    config: String,
    attempts: Vec<DensityView>,
    bins_per_pitch: Option<FactorView>,
}

/// An attempt's density.
#[derive(Debug, Deserialize)]
struct DensityView {
    density: f64,
}

/// The routed factor of the bins per pitch.
#[derive(Debug, Deserialize)]
struct FactorView {
    routed_factor: f64,
}

/// The routed factor k of the layout report at `path` (`layout-report.json` of `tofprobe
/// layout`), refused unless the report is of this schema, its macro is clean (DRC 0, LVS
/// match: a dirty macro's area is not an answer) and it carries bins per pitch, and k is a
/// finite number ≥ 1.
pub fn read_routed_factor(path: &std::path::Path) -> Result<RoutedFactor> {
    let v: AreaView = read_clean(path)?;
    let refuse = |what: String| refusal(path, what);
    let k = v
        .bins_per_pitch
        .as_ref()
        .map(|b| b.routed_factor)
        .ok_or_else(|| refuse("`bins_per_pitch` (null: the layout had no area model)".into()))?;
    if !(k.is_finite() && k >= 1.0) {
        return Err(refuse(format!(
            "`bins_per_pitch.routed_factor` ≥ 1 (die area over cell area), got {k}"
        )));
    }
    Ok(RoutedFactor {
        technology: v.tech,
        factor: k,
        density: v.attempts.last().map_or(0.0, |a| a.density),
        config: v.config,
    })
}

/// A routed macro's post-route timing, as `tofprobe size --layout-report` shows it beside
/// its own synthesis corners.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PostRouteTable {
    /// The layout report read.
    pub report: String,
    /// Its technology.
    pub tech: String,
    /// The configuration it was laid out from.
    pub config: String,
    /// Its corners (synthesis and post-route, the same routed wires on each).
    pub corners: Vec<CornerRow>,
}

/// What every reader of a layout report checks first: its schema and a clean macro.
#[derive(Debug, Deserialize)]
struct CleanHead {
    schema: String,
    drc_errors: u64,
    lvs_match: bool,
}

/// The refusal of the layout report at `path`: it is not `what`.
fn refusal(path: &std::path::Path, what: String) -> LayoutError {
    LayoutError::Parse {
        tool: "tofprobe layout",
        what,
        path: path.to_path_buf(),
    }
}

/// The layout report at `path` read as `T` (a partial view), refused unless it is of
/// [`SCHEMA`] and its macro is clean (DRC 0, LVS match: a dirty macro's figures are not an
/// answer).
fn read_clean<T: serde::de::DeserializeOwned>(path: &std::path::Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| LayoutError::io("reading", path, e))?;
    let parse_error = |e: serde_json::Error| refusal(path, format!("a layout report ({e})"));
    let head: CleanHead = serde_json::from_str(&text).map_err(parse_error)?;
    if head.schema != SCHEMA {
        return Err(refusal(
            path,
            format!(
                "a report of schema {SCHEMA} (`schema` is {:?})",
                head.schema
            ),
        ));
    }
    if head.drc_errors != 0 || !head.lvs_match {
        return Err(refusal(
            path,
            format!(
                "a clean macro (`drc_errors` = {}, `lvs_match` = {}; DRC 0 and LVS match are needed)",
                head.drc_errors, head.lvs_match
            ),
        ));
    }
    serde_json::from_str(&text).map_err(parse_error)
}

/// What the post-route table reads of a layout report.
#[derive(Debug, Deserialize)]
struct CornersView {
    tech: String,
    config: String,
    #[serde(default)]
    bins: Option<u64>,
    #[serde(default)]
    width: Option<u32>,
    #[serde(default)]
    corners: Vec<CornerRow>,
}

/// The post-route corners of the layout report at `path` when it is of the pixel with
/// `bins` bins of `width`-bit registers (`Ok(None)` when it is another pixel's: its k may
/// still serve `size --options`), refused unless the macro is clean (DRC 0, LVS match) and
/// of this schema.
pub fn read_post_route(
    path: &std::path::Path,
    bins: u64,
    width: u32,
) -> Result<Option<PostRouteTable>> {
    let v: CornersView = read_clean(path)?;
    if v.bins != Some(bins) || v.width != Some(width) || v.corners.is_empty() {
        return Ok(None);
    }
    Ok(Some(PostRouteTable {
        report: path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        tech: v.tech,
        config: v.config,
        corners: v.corners,
    }))
}
