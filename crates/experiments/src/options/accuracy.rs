//! An option's accuracy: the tone error of the bit-true pixel against the float full DFT on
//! the same bins (the tradeoff study's "err vs DFT"), on the scene, over several seeds of
//! the photon source, reported as the mean with its spread. The float DFT sees the same
//! detections, so the difference is what the pixel's arithmetic (ΣΔ signs, prefilter,
//! rounding, the register fraction) costs, not the photon noise.

use rayon::prelude::*;
use serde::Serialize;
use tofprobe_design::{Document, ProbeCache, ResolvedDesign};

use super::catalogue::ArchOption;
use crate::error::ExperimentError;
use crate::level::Level;
use crate::spectrum::setup;
use crate::tradeoff::measure_levels;
use crate::tradeoff::overrides::with_overrides;

/// The tone error over the seeds (µm).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Spread {
    /// Mean over the seeds.
    pub mean: f64,
    /// Smallest.
    pub min: f64,
    /// Largest (what the recommendation holds against the target).
    pub max: f64,
    /// One value per seed, in seed order.
    pub per_seed: Vec<f64>,
}

impl Spread {
    fn of(xs: Vec<f64>) -> Self {
        let n = xs.len().max(1) as f64;
        Spread {
            mean: xs.iter().sum::<f64>() / n,
            min: xs.iter().copied().fold(f64::INFINITY, f64::min),
            max: xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            per_seed: xs,
        }
    }
}

/// An option's resolved pixel and accuracy.
#[derive(Debug, Clone)]
pub struct Accuracy {
    /// The option applied to the scene (first seed), for its pixel and RTL.
    pub design: ResolvedDesign,
    /// |bit-true − float DFT| tone amplitude, µm.
    pub tone_error_um: Spread,
}

/// `options` measured on `config` for every seed: one task per seed (its own probe cache),
/// the options in order within it, so the numbers do not depend on the thread count.
/// A configuration the resolution refuses is that option's error.
pub fn measure(
    config: &Document,
    origin: &str,
    options: &[ArchOption],
    seeds: &[u64],
) -> Vec<Result<Accuracy, ExperimentError>> {
    let per_seed: Vec<Vec<Result<(ResolvedDesign, f64), String>>> = seeds
        .par_iter()
        .map(|&seed| {
            let mut cache = ProbeCache::default();
            options
                .iter()
                .map(|o| one(config, origin, o, seed, &mut cache).map_err(|e| e.to_string()))
                .collect()
        })
        .collect();
    (0..options.len())
        .map(|i| {
            let mut errs = Vec::with_capacity(seeds.len());
            let mut design = None;
            for runs in &per_seed {
                match &runs[i] {
                    Ok((d, e)) => {
                        errs.push(*e);
                        design.get_or_insert_with(|| d.clone());
                    }
                    Err(e) => {
                        return Err(ExperimentError::option(
                            "option",
                            &options[i].name,
                            &format!("a configuration the pixel accepts: {e}"),
                        ));
                    }
                }
            }
            let design = design
                .ok_or_else(|| ExperimentError::option("seeds", "none", "at least one seed"))?;
            Ok(Accuracy {
                design,
                tone_error_um: Spread::of(errs),
            })
        })
        .collect()
}

fn one(
    config: &Document,
    origin: &str,
    o: &ArchOption,
    seed: u64,
    cache: &mut ProbeCache,
) -> Result<(ResolvedDesign, f64), ExperimentError> {
    let seed_s = seed.to_string();
    let mut ov: Vec<(&str, &str)> = o
        .overrides
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    ov.push(("acquisition.seed", &seed_s));
    let label = format!("{origin} with option {} (seed {seed})", o.name);
    let design = with_overrides(config, &label, &ov, cache)?;
    let su = setup(&design)?;
    // Only the level it compares (the float full DFT it is scored against runs too).
    let r = measure_levels(&design, &su, &[Level::BitTrue])?;
    let err = r
        .level(Level::BitTrue)
        .and_then(|l| l.amplitude_err_vs_dft_um)
        .ok_or_else(|| {
            ExperimentError::option(
                "scene",
                origin,
                "a scene with a tone in a bin (the tone error is measured on it)",
            )
        })?;
    Ok((design, err))
}
