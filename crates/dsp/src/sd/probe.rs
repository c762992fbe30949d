//! Probe waveforms and the ROM they fill: for every bin k, window × cos and window × sin
//! at amplitude A_p, modulated to ±1 by the designed ΣΔ modulator, packed 2·B bits per
//! pulse index (register 2k = I, 2k+1 = Q; bit 1 = add).
//!
//! *Windowed* mode: L = N, the window spans the frame, f_k = k·f_s/N; the modulator runs
//! once from rest (the window starts at 0, so there is no start-up transient).
//!
//! *Periodic* mode: depth L, rectangular, f_k = k·f_s/L, a frame is M·L pulses and the
//! pixel reads address n mod L. A bitstream that is simply cut after L samples would wrap
//! with the modulator state at sample L ≠ the state it started from, a discontinuity the
//! chip would replay every period. So the modulator is run over the period repeatedly
//! (its input is bit-identical every period, see `lanes`): after each period from the
//! second on, the wrap mismatch max|x(end) − x(start)| is measured, and the first period
//! whose mismatch is ≤ [`WRAP_TOLERANCE`] is kept (a limit cycle locked to the period).
//! If none of [`MAX_PERIODS`] periods locks, the period with the smallest mismatch is
//! kept; either way the mismatch travels with the ROM (`wrap_mismatch`). Measured: the
//! default order-3 loop does not lock (best mismatch 0.15–0.27 for L = 4096…2^18, states
//! being ≈ 1), so the wrap is "clean" in the sense that it is the least-disturbed of the
//! periods run; the transient it starts decays with the NTF poles within tens of samples,
//! and the test shows one period, wrap included, still reads A_p to < 1%.

use super::config::{ProbeConfig, RomMode};
use super::lanes::{LANES, LaneGroup, LaneProbe};
use super::modulator::{Modulator, SAFETY_MARGIN};
use crate::error::DspError;
use crate::rom::{RomImage, RomManifest};
use crate::window::Window;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// State mismatch at the wrap accepted as clean (quantiser level 1; in-band states are
/// ≈ 0.1–1, so 1e-6 is a wrap indistinguishable from continuing the same trajectory).
pub const WRAP_TOLERANCE: f64 = 1e-6;
/// Periods run at most when looking for a clean wrap.
pub const MAX_PERIODS: usize = 8;

/// A designed probe set: the modulator and its measured amplitude limit, reusable for
/// many ROMs (the stability sweep is the expensive part of the design).
#[derive(Debug, Clone)]
pub struct ProbeDesign {
    pub config: ProbeConfig,
    pub modulator: Modulator,
    /// Measured maximum stable sine amplitude at the frequency it was measured.
    pub max_stable_amplitude: f64,
    /// Normalised frequency of that measurement.
    pub limit_f_norm: f64,
}

impl ProbeDesign {
    /// Validates the config, designs the modulator and checks the probe amplitude against
    /// [`SAFETY_MARGIN`] × the maximum stable amplitude measured at `f_norm` (use the
    /// lowest probe frequency: the limit is lowest towards DC, ≈ 0.77 vs 0.86 at 50 kHz).
    pub fn new(config: &ProbeConfig, f_norm: f64) -> Result<Self, DspError> {
        let modulator = Self::design_modulator(config)?;
        let a_max = modulator.max_stable_amplitude(f_norm);
        Self::checked(config, modulator, a_max, f_norm)
    }

    /// The same design with a stability limit already known (measured by [`Self::new`]
    /// elsewhere): skips the sweep, which takes seconds in a debug build, and still checks
    /// the probe amplitude against the safety margin of that limit.
    pub fn with_known_limit(
        config: &ProbeConfig,
        max_stable_amplitude: f64,
        f_norm: f64,
    ) -> Result<Self, DspError> {
        let modulator = Self::design_modulator(config)?;
        Self::checked(config, modulator, max_stable_amplitude, f_norm)
    }

    fn design_modulator(config: &ProbeConfig) -> Result<Modulator, DspError> {
        config.validate()?;
        Modulator::design(
            config.order,
            config.osr,
            config.optimised_zeros,
            config.h_inf,
        )
    }

    fn checked(
        config: &ProbeConfig,
        modulator: Modulator,
        a_max: f64,
        f_norm: f64,
    ) -> Result<Self, DspError> {
        let limit = SAFETY_MARGIN * a_max;
        if config.amplitude > limit {
            return Err(DspError::out_of_range(
                "probe.amplitude",
                config.amplitude,
                format!("0 < amplitude <= {limit:.4}"),
            )
            .with_hint(format!(
                "the order-{} OSR-{} H_inf-{} modulator is stable up to {a_max:.4} at \
                 f/f_s = {f_norm:.3e}; probes keep a {:.0}% safety margin below it",
                config.order,
                config.osr,
                config.h_inf,
                (1.0 - SAFETY_MARGIN) * 100.0
            )));
        }
        Ok(ProbeDesign {
            config: config.clone(),
            modulator,
            max_stable_amplitude: a_max,
            limit_f_norm: f_norm,
        })
    }
}

/// The chip's probe ROM plus everything a readout needs to be normalised.
#[derive(Debug, Clone, PartialEq)]
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
    /// Largest state mismatch at the wrap (0 in windowed mode).
    pub wrap_mismatch: f64,
}

impl ProbeRom {
    /// ROM depth L.
    pub fn depth(&self) -> usize {
        self.image.depth()
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
        let results: Vec<Result<(Vec<u16>, f64), DspError>> = groups
            .par_iter()
            .map(|probes| {
                let mut g = LaneGroup::new(probes, depth as u64, window, order);
                let mut bits = vec![0u16; depth];
                match cfg.rom_mode {
                    RomMode::Windowed => {
                        g.run(ss, 0, &mut bits)?;
                        Ok((bits, 0.0))
                    }
                    RomMode::Periodic => periodic(&mut g, ss, bits),
                }
            })
            .collect();
        let mut streams = Vec::with_capacity(results.len());
        let mut wrap_mismatch = 0.0f64;
        for r in results {
            let (bits, mismatch) = r?;
            wrap_mismatch = wrap_mismatch.max(mismatch);
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
            wrap_mismatch,
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
            amplitude: self.amplitude,
            window: self.window.name().to_string(),
            coherent_gain: self.coherent_gain,
            wrap_mismatch: self.wrap_mismatch,
        }
    }

    /// Writes `<dir>/<stem>.hex` (`$readmemh`) and `<dir>/<stem>.toml` atomically;
    /// returns the manifest's path.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<PathBuf, DspError> {
        self.manifest().write(&self.image, dir, stem)
    }
}

/// Runs a periodic group until its wrap is clean (see the module docs).
fn periodic(
    g: &mut LaneGroup,
    ss: &super::realize::StateSpace,
    mut bits: Vec<u16>,
) -> Result<(Vec<u16>, f64), DspError> {
    let depth = bits.len() as u64;
    let mut best: Option<(Vec<u16>, f64)> = None;
    for p in 0..MAX_PERIODS {
        let start = g.states.clone();
        g.run(ss, p as u64 * depth, &mut bits)?;
        if p == 0 {
            continue; // the first period carries the start-up transient from rest
        }
        let mismatch = start
            .iter()
            .zip(&g.states)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0, f64::max);
        if mismatch <= WRAP_TOLERANCE {
            return Ok((bits, mismatch));
        }
        if best.as_ref().is_none_or(|(_, m)| mismatch < *m) {
            best = Some((bits.clone(), mismatch));
        }
    }
    Ok(best.unwrap_or((bits, f64::INFINITY)))
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
    fn bad_bins_and_amplitudes_are_rejected_with_ranges() {
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
        let cfg = ProbeConfig {
            amplitude: 0.75,
            ..ProbeConfig::default()
        };
        let e = ProbeDesign::new(&cfg, 1e-4).unwrap_err().to_string();
        // 0.9 × ≈ 0.77 ≈ 0.69: the message gives the limit and the stable maximum.
        assert!(
            e.contains("probe.amplitude = 0.75") && e.contains("<= 0.69"),
            "{e}"
        );
    }

    /// A periodic ROM is replayed M times; what matters is that one period, wrap
    /// included, still carries the probe: correlating the ±1 stream of each register with
    /// the ideal cos/sin over the period must give A_p (in-band quantisation noise and the
    /// wrap's transient leave ≈ 1e-3), and a bin it does not probe must read ≈ 0.
    #[test]
    fn periodic_rom_wraps_cleanly_or_reports_the_mismatch() {
        let l = 4096usize;
        let cfg = ProbeConfig {
            rom_mode: RomMode::Periodic,
            rom_depth: l,
            ..ProbeConfig::default()
        };
        let d = design(&cfg);
        let rom = ProbeRom::generate(&d, 10e6, 1 << 20, &[7, 50]).unwrap();
        assert_eq!(rom.depth(), l);
        assert_eq!(rom.window, Window::Rectangular);
        assert!((rom.bins[0] - 7.0 * 10e6 / 4096.0).abs() < 1e-9);
        assert_eq!(nearest_bin(rom.bins[1], 10e6, l), 50);
        // The two-level loop does not lock onto the period (see the module docs): the
        // kept period's mismatch is recorded, and finite.
        assert!(rom.wrap_mismatch.is_finite() && rom.wrap_mismatch < 1.0);
        for (b, &k) in rom.bin_indices.iter().enumerate() {
            for q in 0..2 {
                let corr = |kk: u64| {
                    (0..l)
                        .map(|a| {
                            let th = 2.0 * std::f64::consts::PI * (kk * a as u64) as f64 / l as f64;
                            let p = if q == 0 { th.cos() } else { th.sin() };
                            if rom.image.bit(a, 2 * b + q) { p } else { -p }
                        })
                        .sum::<f64>()
                        * 2.0
                        / l as f64
                };
                let a = corr(k);
                assert!((a - 0.5).abs() < 0.005, "bin {k} q {q}: {a}");
                assert!(corr(k + 3).abs() < 0.005, "leak at bin {}", k + 3);
            }
        }
    }
}
