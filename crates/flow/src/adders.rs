//! The timing oracle of `adders = "auto"` (`tofprobe_design::adders` decides; this measures):
//! each candidate pixel is rendered, synthesised with the delay-driven script for its clock
//! and timed with OpenSTA (`tofprobe_eda::analysis`, cached by the RTL's hash, as the size
//! report's points are), and judged with the size report's verdict so `size` and
//! `adders = "auto"` agree on slack. The fastest f_max measured per liberty is kept in the
//! synthesis cache (`adders-fmax.json`), the bound that lets the choice skip hopeless
//! candidates without synthesis.
//!
//! [`load`] is the hardware commands' resolution: the one resolution with this oracle.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tofprobe_design::adders::{AdderTiming, CandidateTiming};
use tofprobe_design::{Document, ProbeCache, ResolvedDesign};
use tofprobe_eda::analysis::analyse_point;
use tofprobe_eda::corners::{CornerTiming, MARGIN_PERCENT};
use tofprobe_eda::fsutil::{synth_cache_dir, write_atomic};
use tofprobe_eda::generated::GeneratedPixel;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::signoff::OSU018_LIBERTY;
use tofprobe_pixel::{PixelError, PixelParams};

use crate::error::FlowError;

/// Reads `path` (or the embedded default) and resolves it for the hardware: `adders =
/// "auto"` is decided by synthesis and static timing (cached).
pub fn load(path: Option<&Path>) -> Result<ResolvedDesign, FlowError> {
    let (document, origin) = Document::read(path)?;
    resolve(document, &origin, &mut ProbeCache::default())
}

/// [`load`] for a document in hand.
pub fn resolve(
    document: Document,
    origin: &str,
    cache: &mut ProbeCache,
) -> Result<ResolvedDesign, FlowError> {
    let needs_timing = matches!(
        document.pixel.adders,
        tofprobe_pixel::config::Choice::Auto(_)
    );
    if !needs_timing {
        return Ok(tofprobe_design::resolve_with(document, origin, cache)?);
    }
    let oracle = SynthesisTiming::new(document.pixel.timing_liberty.as_deref())
        .map_err(|e| tofprobe_design::DesignError::pixel(origin, e))?;
    Ok(tofprobe_design::resolve_timed(
        document,
        origin,
        cache,
        Some(&oracle),
    )?)
}

/// A resolved design whose open `adders = "auto"` choice is decided (a design resolved with
/// an explicit A, or already decided, is returned as it is).
pub fn decide(design: ResolvedDesign) -> Result<ResolvedDesign, FlowError> {
    if !matches!(design.adders, tofprobe_design::AdderStatus::Open { .. }) {
        return Ok(design);
    }
    resolve(design.document, &design.origin, &mut ProbeCache::default())
}

/// An error naming `timing_liberty`: its value is echoed clipped, in the reason too (a
/// liberty error repeats the path: a megabyte value made a two-megabyte message).
fn key_error(value: &str, reason: impl ToString) -> PixelError {
    let shown = tofprobe_io::text::clip(value, 60);
    let reason = reason.to_string().replace(value, &shown);
    PixelError::invalid(
        "timing_liberty",
        format!("\"{shown}\""),
        tofprobe_io::text::clip(&reason, 4 * tofprobe_io::text::MAX_TEXT),
        "\"osu018\", \"sky130\" (tt), \"sky130:ss\", \"sky130:ff\" or the path of a liberty with timing",
    )
}

/// The timed sky130 PDK's liberty at `corner` (`tt`, `ss`, `ff`, or a whole corner name)
/// for the `timing_liberty` value `name`; errors name the key and the corners there are.
fn sky130_corner(name: &str, corner: &str, cache: &std::path::Path) -> Result<PathBuf, PixelError> {
    let pdk = Sky130Pdk::discover(None)
        .map_err(|e| key_error(name, e))?
        .ok_or_else(|| {
            key_error(
                name,
                format!(
                    "no timed sky130_fd_sc_hd PDK found ($TOFPROBE_SKY130_PDK, then {})",
                    tofprobe_eda::pdk::search_path()
                        .iter()
                        .map(|d| d.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
    pdk.corner(corner, cache)
        .map_err(|e| key_error(name, e))?
        .ok_or_else(|| {
            key_error(
                name,
                format!(
                    "the sky130 PDK has no corner `{corner}`: \"sky130:tt\", \"sky130:ss\" or \"sky130:ff\" (corners {})",
                    pdk.corner_names().join(", ")
                ),
            )
        })
}

/// Synthesis + OpenSTA timing on the liberty `pixel.timing_liberty` names.
#[derive(Debug)]
pub struct SynthesisTiming {
    lib: Liberty,
    cache: PathBuf,
}

impl SynthesisTiming {
    /// The oracle for `timing_liberty` (`"osu018"` when `None`, `"sky130"` = the timed
    /// PDK's tt corner, `"sky130:ss"` / `"sky130:ff"` / `"sky130:tt"` a corner of it — the
    /// slowest, `ss`, is where sign-off judges —, or a path); errors name `timing_liberty`.
    pub fn new(timing_liberty: Option<&str>) -> Result<Self, PixelError> {
        let cache = synth_cache_dir(None);
        let name = timing_liberty.unwrap_or("osu018");
        let path = match name {
            "osu018" => PathBuf::from(OSU018_LIBERTY),
            "sky130" => sky130_corner(name, "tt", &cache)?,
            _ if name.starts_with("sky130:") => sky130_corner(name, &name[7..], &cache)?,
            path => PathBuf::from(path),
        };
        let lib = Liberty::load(&path).map_err(|e| key_error(name, e))?;
        if !lib.has_timing {
            return Err(key_error(
                name,
                format!(
                    "{} has no timing groups: f_max cannot be measured on it",
                    path.display()
                ),
            ));
        }
        Ok(SynthesisTiming { lib, cache })
    }

    fn index_path(&self) -> PathBuf {
        self.cache.join("adders-fmax.json")
    }

    fn index(&self) -> BTreeMap<String, f64> {
        std::fs::read_to_string(self.index_path())
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default()
    }

    fn key(&self) -> String {
        self.lib.path.display().to_string()
    }

    fn remember(&self, f_max_mhz: f64) {
        let mut index = self.index();
        let best = index.entry(self.key()).or_insert(f_max_mhz);
        if f_max_mhz >= *best {
            *best = f_max_mhz;
            // A cache, not an output: failing to write it only costs a later synthesis.
            if let Ok(text) = serde_json::to_vec_pretty(&index) {
                let _ = std::fs::create_dir_all(&self.cache);
                let _ = write_atomic(&self.index_path(), &text);
            }
        }
    }
}

impl AdderTiming for SynthesisTiming {
    fn liberty_name(&self) -> String {
        self.lib.path.file_name().map_or_else(
            || self.lib.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }

    fn margin_percent(&self) -> f64 {
        MARGIN_PERCENT
    }

    fn fastest_known_f_max_mhz(&self) -> Option<f64> {
        self.index().get(&self.key()).copied()
    }

    fn time(&self, candidate: &PixelParams, clock_mhz: f64) -> Result<CandidateTiming, String> {
        let provider = GeneratedPixel {
            base: candidate.clone(),
        };
        let point = analyse_point(
            &provider,
            candidate.bins as u64,
            candidate.width,
            &self.lib,
            true,
            "clk",
            &self.cache,
            Some(1e6 / clock_mhz),
        )
        .map_err(|e| e.to_string())?;
        let timing = point
            .timing
            .ok_or_else(|| "the liberty has no timing".to_string())?;
        // The size report's verdict, so `size` and `adders = "auto"` judge slack alike.
        let verdict = CornerTiming::new(
            &self.lib.name,
            "typical",
            &self.lib.path,
            &timing,
            clock_mhz,
            clock_mhz * 1e6,
        );
        self.remember(timing.f_max_mhz);
        Ok(CandidateTiming {
            f_max_mhz: timing.f_max_mhz,
            slack_percent: verdict.slack_percent,
            meets: verdict.meets_margin,
        })
    }
}
