//! ΣΔ probe designs already made, passed explicitly to [`crate::resolve_with`]: the
//! design's stability sweep is the expensive part of a resolution and depends only on
//! `[probe]` and the lowest normalised bin, which most knob settings (W, F, S, B) leave
//! alone. No global state: the caller owns the cache and its lifetime.

use tofprobe_dsp::DspError;
use tofprobe_dsp::sd::{ProbeConfig, ProbeDesign};

/// Designs keyed by the `[probe]` section and the lowest bin's f/f_s.
#[derive(Debug, Default)]
pub struct ProbeCache {
    designs: Vec<(String, u64, ProbeDesign)>,
}

impl ProbeCache {
    /// The design for `probe` checked at `f_norm`, made on first use.
    pub fn design(&mut self, probe: &ProbeConfig, f_norm: f64) -> Result<ProbeDesign, DspError> {
        let key = format!("{probe:?}");
        let hit = self
            .designs
            .iter()
            .find(|(k, f, _)| *k == key && *f == f_norm.to_bits());
        if let Some((_, _, d)) = hit {
            return Ok(d.clone());
        }
        let d = ProbeDesign::new(probe, f_norm)?;
        self.designs.push((key, f_norm.to_bits(), d.clone()));
        Ok(d)
    }

    /// Number of distinct designs made so far.
    pub fn len(&self) -> usize {
        self.designs.len()
    }

    /// Whether no design has been made yet.
    pub fn is_empty(&self) -> bool {
        self.designs.is_empty()
    }
}
