//! The probe ROM image: the packed table of ±1 probe bits the chip replays (2·B bits per
//! pulse index: register 2k = I, 2k+1 = Q; bit 1 = add), generated for every bin k from
//! window × cos and window × sin at amplitude A_p through the designed modulator
//! ([`ProbeDesign`]; a periodic ROM's sequences are the clean cuts the design's `periodic`
//! search chose), with everything a readout needs to be normalised, its manifest and its
//! `$readmemh` file.

use super::{ProbeDesign, WRAP_TOLERANCE, WrapStats, periodic};
use crate::error::DspError;
use crate::rom::{RomImage, RomManifest};
use crate::sd::config::{ProbeConvention, RomMode};
use crate::sd::simd::lanes::{LANES, LaneGroup, LaneProbe};
use crate::sd::wrap::WrapMetric;
use crate::window::Window;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The chip's probe ROM plus everything a readout needs to be normalised. It serialises
/// (serde), so a worker process can receive a ROM instead of building it again.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProbeRom {
    pub image: RomImage,
    /// Bin index k of each probed bin (f_k = k·f_s/L).
    pub bin_indices: Vec<u64>,
    /// Probe frequencies in Hz.
    pub bins: Vec<f64>,
    /// Probe amplitude A_p.
    pub amplitude: f64,
    /// Window actually used (rectangular in periodic mode).
    pub window: Window,
    /// Its coherent gain G = mean(w).
    pub coherent_gain: f64,
    pub mode: RomMode,
    /// Laser pulse rate f_s in Hz.
    pub sample_rate_hz: f64,
    pub order: usize,
    pub osr: f64,
    pub h_inf: f64,
    pub optimised_zeros: bool,
    /// How the probe waveform was written down (docs/probe.md).
    pub convention: ProbeConvention,
    /// Largest state mismatch max|s₀ − s_L| at the wrap of a kept period (0 in windowed mode).
    pub wrap_mismatch: f64,
    /// Worst lane's wrap transient in-band energy over its period's in-band error energy
    /// (0 in windowed mode); clean when ≤ [`WRAP_TOLERANCE`].
    pub wrap_error_ratio: f64,
    /// Periods run after the warm-up to find the kept cuts (0 in windowed mode).
    pub wrap_periods: usize,
}

impl ProbeRom {
    /// ROM depth L.
    pub fn depth(&self) -> usize {
        self.image.depth()
    }

    /// Whether every periodic wrap is clean (always true for a windowed ROM).
    pub fn wrap_clean(&self) -> bool {
        self.wrap_error_ratio <= WRAP_TOLERANCE
    }

    /// One phrase on the wrap for reports and headers (`None` for a windowed ROM), e.g.
    /// "wrap clean (in-band wrap error 1.8e-2 of the quantisation error, 1 period(s)
    /// searched)".
    pub fn wrap_summary(&self) -> Option<String> {
        (self.mode == RomMode::Periodic).then(|| {
            format!(
                "wrap {} (in-band wrap error {:.1e} of the quantisation error, {} period(s) searched)",
                if self.wrap_clean() { "clean" } else { "NOT clean" },
                self.wrap_error_ratio,
                self.wrap_periods
            )
        })
    }

    /// Generates the ROM for bin indices `bins` (f_k = k·f_s/L, L from the config and
    /// `frame_pulses`). Bins must be distinct, ≥ 1 and below f_s/(2·OSR).
    pub fn generate(
        design: &ProbeDesign,
        sample_rate_hz: f64,
        frame_pulses: u64,
        bins: &[u64],
    ) -> Result<Self, DspError> {
        let cfg = &design.config;
        let depth = cfg.depth(frame_pulses);
        if depth < 16 {
            return Err(DspError::out_of_range(
                "frame_pulses",
                frame_pulses,
                ">= 16 for a windowed ROM",
            ));
        }
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(DspError::out_of_range(
                "sensor.laser_rate_hz",
                sample_rate_hz,
                "> 0",
            ));
        }
        if bins.is_empty() {
            return Err(DspError::out_of_range("bins", "[]", "at least one bin"));
        }
        let band = sample_rate_hz / (2.0 * cfg.osr);
        let k_max = ((depth as f64) / (2.0 * cfg.osr)).ceil() as u64; // first k at/above band
        for (i, &k) in bins.iter().enumerate() {
            let f = k as f64 * sample_rate_hz / depth as f64;
            if k == 0 || k >= k_max {
                return Err(DspError::out_of_range(
                    "bins",
                    format!("k = {k} ({f:.1} Hz)"),
                    format!("1 <= k < {k_max}: below f_s/(2·OSR) = {band:.1} Hz with L = {depth}"),
                ));
            }
            if bins[..i].contains(&k) {
                return Err(DspError::out_of_range(
                    "bins",
                    format!("k = {k} ({f:.1} Hz) twice"),
                    "distinct bins (two bins at the same frequency)",
                ));
            }
        }
        let window = match cfg.rom_mode {
            RomMode::Windowed => cfg.window,
            RomMode::Periodic => Window::Rectangular,
        };
        let registers = 2 * bins.len();
        let probes: Vec<LaneProbe> = bins
            .iter()
            .flat_map(|&k| {
                [false, true].map(|q| LaneProbe {
                    bin: k,
                    quadrature: q,
                    amplitude: cfg.amplitude,
                })
            })
            .collect();
        let ss = &design.modulator.ss;
        let order = design.modulator.order;
        let groups: Vec<&[LaneProbe]> = probes.chunks(LANES).collect();
        let metric =
            (cfg.rom_mode == RomMode::Periodic).then(|| WrapMetric::new(ss, depth, cfg.osr));
        let results: Vec<Result<(Vec<u16>, WrapStats), DspError>> = groups
            .par_iter()
            .map(|probes| {
                let mut g = LaneGroup::new(probes, depth as u64, window, order)
                    .with_convention(cfg.convention);
                match &metric {
                    None => {
                        let mut bits = vec![0u16; depth];
                        g.run(ss, 0, &mut bits)?;
                        Ok((bits, WrapStats::default()))
                    }
                    Some(m) => periodic(&mut g, probes, ss, m),
                }
            })
            .collect();
        let mut streams = Vec::with_capacity(results.len());
        let mut wrap = WrapStats::default();
        for r in results {
            let (bits, w) = r?;
            wrap.mismatch = wrap.mismatch.max(w.mismatch);
            wrap.ratio = wrap.ratio.max(w.ratio);
            wrap.periods = wrap.periods.max(w.periods);
            streams.push(bits);
        }
        let image = pack(depth, registers, &streams);
        Ok(ProbeRom {
            image,
            bin_indices: bins.to_vec(),
            bins: bins
                .iter()
                .map(|&k| k as f64 * sample_rate_hz / depth as f64)
                .collect(),
            amplitude: cfg.amplitude,
            window,
            coherent_gain: window.coherent_gain(),
            mode: cfg.rom_mode,
            sample_rate_hz,
            order,
            osr: cfg.osr,
            h_inf: cfg.h_inf,
            optimised_zeros: cfg.optimised_zeros,
            convention: cfg.convention,
            wrap_mismatch: wrap.mismatch,
            // Three significant digits: the ratio goes through an FFT whose last bits
            // depend on the CPU's SIMD path, and it is written into committed files.
            wrap_error_ratio: round_significant(wrap.ratio, 3),
            wrap_periods: wrap.periods,
        })
    }
}

/// The bin index k nearest to `f_hz` for a ROM of depth L (f_k = k·f_s/L).
pub fn nearest_bin(f_hz: f64, sample_rate_hz: f64, depth: usize) -> u64 {
    (f_hz / sample_rate_hz * depth as f64).round().max(0.0) as u64
}

impl ProbeRom {
    /// The manifest describing this ROM (hash, depth and width are filled in on write).
    pub fn manifest(&self) -> RomManifest {
        RomManifest {
            hex_file: String::new(),
            content_hash: format!("{:016x}", self.image.content_hash()),
            depth: self.image.depth(),
            registers: self.image.registers(),
            mode: self.mode.name().to_string(),
            sample_rate_hz: self.sample_rate_hz,
            bin_indices: self.bin_indices.clone(),
            bin_frequencies_hz: self.bins.clone(),
            order: self.order,
            osr: self.osr,
            h_inf: self.h_inf,
            optimised_zeros: self.optimised_zeros,
            // Written only when not the default, so existing manifests keep their text.
            convention: (self.convention != ProbeConvention::Tofprobe)
                .then(|| self.convention.name().to_string()),
            amplitude: self.amplitude,
            window: self.window.name().to_string(),
            coherent_gain: self.coherent_gain,
            wrap_mismatch: self.wrap_mismatch,
            wrap_error_ratio: self.wrap_error_ratio,
            wrap_clean: self.wrap_clean(),
            wrap_periods: self.wrap_periods,
        }
    }

    /// Writes `<dir>/<stem>.hex` (`$readmemh`) and `<dir>/<stem>.toml` atomically;
    /// returns the manifest's path.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<PathBuf, DspError> {
        self.manifest().write(&self.image, dir, stem)
    }
}

/// `v` rounded to `digits` significant decimal digits (0 stays 0).
fn round_significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// Packs per-group streams (bit l of word n = register LANES·group + l at address n).
fn pack(depth: usize, registers: usize, streams: &[Vec<u16>]) -> RomImage {
    let wpe = registers.div_ceil(64).max(1);
    let mut data = vec![0u64; depth * wpe];
    let valid_mask = |g: usize| -> u16 {
        let live = registers.saturating_sub(LANES * g).min(LANES);
        if live == LANES {
            u16::MAX
        } else {
            (1u16 << live) - 1
        }
    };
    data.par_chunks_mut(wpe * 4096)
        .enumerate()
        .for_each(|(ci, chunk)| {
            let a0 = ci * 4096;
            for (g, s) in streams.iter().enumerate() {
                let per_word = 64 / LANES;
                let (w, shift, m) = (g / per_word, LANES * (g % per_word), valid_mask(g));
                for (i, entry) in chunk.chunks_mut(wpe).enumerate() {
                    entry[w] |= ((s[a0 + i] & m) as u64) << shift;
                }
            }
        });
    RomImage::from_words(depth, registers, data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sd::ProbeConfig;

    fn design(cfg: &ProbeConfig) -> ProbeDesign {
        ProbeDesign::new(cfg, 1e-4).unwrap()
    }

    #[test]
    fn rom_bits_follow_the_probe_and_are_deterministic() {
        let cfg = ProbeConfig::default();
        let d = design(&cfg);
        let n = 1u64 << 14;
        let rom = ProbeRom::generate(&d, 10e6, n, &[5, 40, 77]).unwrap();
        assert_eq!(rom.image.registers(), 6);
        assert_eq!(rom.image.depth(), n as usize);
        // Correlating the ±1 stream with the ideal probe recovers A_p·Σw²cos² ≈ A_p·N·P/2
        // (unity STF; the shaped noise is out of band and contributes ~1e-3 relative).
        for (b, &k) in rom.bin_indices.iter().enumerate() {
            for q in 0..2 {
                let mut acc = 0.0;
                let mut ref_energy = 0.0;
                for a in 0..n as usize {
                    let th = 2.0 * std::f64::consts::PI * (k as f64) * a as f64 / n as f64;
                    let p = Window::Blackman.value(a, n as usize)
                        * if q == 0 { th.cos() } else { th.sin() };
                    let s = if rom.image.bit(a, 2 * b + q) {
                        1.0
                    } else {
                        -1.0
                    };
                    acc += s * p;
                    ref_energy += p * p;
                }
                let a_est = acc / ref_energy;
                assert!((a_est - 0.5).abs() < 0.005, "bin {k} q {q}: {a_est}");
            }
        }
        // Run to run: identical image and byte-identical files.
        let again = ProbeRom::generate(&d, 10e6, n, &[5, 40, 77]).unwrap();
        assert_eq!(again, rom);
        let dir = std::env::temp_dir().join(format!("tofprobe-probe-{}", std::process::id()));
        let m = rom.write(&dir, "a").unwrap();
        again.write(&dir, "b").unwrap();
        let a = std::fs::read(dir.join("a.hex")).unwrap();
        assert_eq!(a, std::fs::read(dir.join("b.hex")).unwrap());
        assert_eq!(a.len(), (n as usize) * 3); // 6 registers: 2 hex digits + newline
        let (man, img) = RomManifest::read(&m).unwrap();
        assert_eq!(img, rom.image);
        assert_eq!(man.bin_indices, vec![5, 40, 77]);
        assert_eq!(man.window, "blackman");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bad_bins_are_rejected_with_ranges() {
        let d = design(&ProbeConfig::default());
        // L = 2^14, OSR 32: k < 256.
        let e = ProbeRom::generate(&d, 10e6, 1 << 14, &[256])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("1 <= k < 256") && e.contains("156250.0 Hz"),
            "{e}"
        );
        let e = ProbeRom::generate(&d, 10e6, 1 << 14, &[3, 3])
            .unwrap_err()
            .to_string();
        assert!(e.contains("same frequency"), "{e}");
    }
}
