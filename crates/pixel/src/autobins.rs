//! Choosing the probed bins from a scene's content (`bins = "auto"`, and the bins of an
//! explicit `bins = B` without `frequencies_hz`): the scene's tones and harmonics that lie
//! inside the ΣΔ band f_s/(2·OSR), strongest first, then bins spread evenly over the rest
//! of the band to estimate the noise floor.
//!
//! Bins are ROM bin indices k (f_k = k·f_s/L). Noise bins keep [`GUARD_BINS`] away from
//! every tone bin: a windowed tone leaks into its neighbours (Blackman's main lobe is ±3
//! bins wide), and a noise bin inside that lobe would read the tone, not the floor. The
//! static depth (DC, tens of mm against µm tones) leaks the same way, so noise bins also
//! keep clear of bins 1..=GUARD_BINS; a scene tone that close to DC keeps its bin (the scene
//! asks for it) but its reading carries the DC leakage (measured in the extremes tests).

use crate::error::PixelError;

/// Noise bins a `bins = "auto"` selection adds to the tone bins.
pub const AUTO_NOISE_BINS: usize = 4;
/// Distance in bins a noise bin keeps from every tone bin (Blackman main lobe ±3, +1).
pub const GUARD_BINS: u64 = 4;

/// The bins the scene needs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BinChoice {
    /// Bin indices of the scene's tones (in band, strongest first, deduplicated).
    pub tones: Vec<u64>,
    /// Bin indices chosen for the noise floor.
    pub noise: Vec<u64>,
}

impl BinChoice {
    /// All bins, tones first then noise.
    pub fn all(&self) -> Vec<u64> {
        self.tones.iter().chain(&self.noise).copied().collect()
    }
}

/// The exclusive upper bin index of the ΣΔ band: k·f_s/L < f_s/(2·OSR) ⇔ k < L/(2·OSR).
pub fn band_limit(depth: u64, osr: f64) -> u64 {
    if !(osr.is_finite() && osr >= 1.0) {
        return 0;
    }
    let edge = depth as f64 / (2.0 * osr);
    // Strictly below the edge: an edge that is an integer is itself out of band.
    let k = edge.ceil() as u64;
    if (k as f64) < edge { k + 1 } else { k }
}

/// Picks bins for `tones` (frequency Hz, amplitude mm): the tone bins in band (strongest
/// first, at most `count`, tones at DC or beyond the band dropped), then noise bins up to
/// `count` in all when `count` is given, else [`AUTO_NOISE_BINS`] of them.
pub fn choose_bins(
    tones: &[(f64, f64)],
    sample_rate_hz: f64,
    depth: u64,
    osr: f64,
    count: Option<usize>,
) -> Result<BinChoice, PixelError> {
    let limit = band_limit(depth, osr);
    if limit < 2 {
        return Err(PixelError::invalid(
            "bins",
            "auto",
            format!(
                "the ΣΔ band f_s/(2·OSR) holds no bin at ROM depth L = {depth} and OSR = {osr}"
            ),
            format!("rom_depth >= {}", (4.0 * osr).ceil()),
        ));
    }
    let in_band = (limit - 1) as usize;
    if let Some(c) = count
        && (c == 0 || c > in_band)
    {
        return Err(PixelError::invalid(
            "bins",
            c,
            format!("the ΣΔ band holds bins 1..{limit} at L = {depth}, OSR = {osr}"),
            c.clamp(1, in_band),
        ));
    }
    let mut sorted: Vec<(f64, f64)> = tones
        .iter()
        .copied()
        .filter(|(f, a)| f.is_finite() && a.is_finite())
        .collect();
    sorted.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut tone_bins: Vec<u64> = Vec::new();
    for (f, _) in sorted {
        let k = (f * depth as f64 / sample_rate_hz).round();
        if k < 1.0 || k >= limit as f64 {
            continue;
        }
        let k = k as u64;
        if !tone_bins.contains(&k) {
            tone_bins.push(k);
        }
    }
    if let Some(c) = count {
        tone_bins.truncate(c);
    }
    let want_noise = match count {
        Some(c) => c - tone_bins.len(),
        None => AUTO_NOISE_BINS.min(in_band - tone_bins.len()),
    };
    let noise = spread_noise_bins(&tone_bins, limit, want_noise);
    Ok(BinChoice {
        tones: tone_bins,
        noise,
    })
}

/// `want` bins spread evenly over 1..limit, away from the tone bins by [`GUARD_BINS`] when
/// the band has room (otherwise the nearest free bins).
fn spread_noise_bins(tones: &[u64], limit: u64, want: usize) -> Vec<u64> {
    let mut chosen: Vec<u64> = Vec::with_capacity(want);
    let free = |k: u64, guard: u64, chosen: &[u64]| {
        // DC counts as a tone: the static depth leaks into the lowest bins the same way.
        !chosen.contains(&k) && tones.iter().chain([&0]).all(|&t| t.abs_diff(k) > guard)
    };
    for guard in [GUARD_BINS, 0] {
        let cands: Vec<u64> = (1..limit).filter(|&k| free(k, guard, &chosen)).collect();
        let need = want - chosen.len();
        if need == 0 || cands.is_empty() {
            continue;
        }
        // Evenly spaced picks from the free candidates (centres of `need` equal strata).
        for i in 0..need.min(cands.len()) {
            let idx = ((2 * i + 1) * cands.len()) / (2 * need.min(cands.len()));
            let k = cands[idx.min(cands.len() - 1)];
            if !chosen.contains(&k) {
                chosen.push(k);
            }
        }
        if chosen.len() < want {
            for &k in &cands {
                if chosen.len() == want {
                    break;
                }
                if !chosen.contains(&k) {
                    chosen.push(k);
                }
            }
        }
    }
    chosen.sort_unstable();
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's band: L = 10^7, OSR 32 → f_s/(2·OSR) = 156.25 kHz = bin 156250 (out of
    /// band), so bins 1..=156249.
    #[test]
    fn band_limit_is_exclusive() {
        assert_eq!(band_limit(10_000_000, 32.0), 156_250);
        assert_eq!(band_limit(1000, 32.0), 16); // 15.625 → bins 1..=15
        assert_eq!(band_limit(1024, 32.0), 16); // edge 16 exactly is out of band → 1..=15
    }

    /// Fig. 8: one tone at 4.5 kHz, N = L = 10^7 → bin 4500; auto adds 4 noise bins away
    /// from it, all distinct and in band.
    #[test]
    fn auto_bins_for_one_tone() {
        let c = choose_bins(&[(4500.0, 0.1)], 10e6, 10_000_000, 32.0, None).unwrap();
        assert_eq!(c.tones, vec![4500]);
        assert_eq!(c.noise.len(), AUTO_NOISE_BINS);
        for &k in &c.noise {
            assert!(k.abs_diff(4500) > GUARD_BINS && (1..156_250).contains(&k));
        }
        // A fixed count fills with noise bins; DC and out-of-band tones are dropped.
        let c = choose_bins(
            &[(0.0, 1.0), (200e3, 1.0), (4500.0, 0.1), (1000.0, 0.5)],
            10e6,
            10_000_000,
            32.0,
            Some(16),
        )
        .unwrap();
        assert_eq!(c.tones, vec![1000, 4500]);
        let all = c.all();
        assert_eq!(all.len(), 16);
        let mut d = all.clone();
        d.sort_unstable();
        d.dedup();
        assert_eq!(d.len(), 16);
    }

    /// Too many bins for the band, or a band with no bin, are errors naming what works.
    #[test]
    fn impossible_requests_are_rejected() {
        let e = choose_bins(&[], 10e6, 1000, 32.0, Some(20)).unwrap_err();
        assert!(e.to_string().contains("nearest valid value: 15"), "{e}");
        let e = choose_bins(&[], 10e6, 64, 32.0, None).unwrap_err();
        assert!(e.to_string().contains("rom_depth >= 128"), "{e}");
        // A crowded band still yields distinct bins.
        let c = choose_bins(&[(50e3, 1.0)], 10e6, 1000, 32.0, Some(15)).unwrap();
        let mut all = c.all();
        all.sort_unstable();
        assert_eq!(all, (1..16).collect::<Vec<u64>>());
    }
}
