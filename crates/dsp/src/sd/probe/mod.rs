//! The ΣΔ probe design: the modulator a probe set is modulated by, its measured stability
//! limit and the amplitude checked against it ([`ProbeDesign`]), and the choice of the
//! sequence a periodic ROM stores — the cut of the running modulator whose wrap is clean
//! (`periodic`). The ROM image those sequences are packed into, with its manifest and
//! files, is [`rom`] ([`ProbeRom`], re-exported here, so `sd::probe::ProbeRom` is its path).
//!
//! *Windowed* mode: L = N, the window spans the frame, f_k = k·f_s/N; the modulator runs
//! once from rest (the window starts at 0, so there is no start-up transient).
//!
//! *Periodic* mode: depth L, rectangular, f_k = k·f_s/L, a frame is M·L pulses and the
//! pixel reads address n mod L. A period cut from a running modulator wraps with the state
//! at its end (s_L) ≠ the state it started from (s₀): the chip replays that discontinuity
//! every period. How much it matters is measured by [`WrapMetric`]: the in-band energy of
//! the transient the mismatch δ = s₀ − s_L starts, exactly δᵀQδ (see `wrap`). The two-level
//! loop never locks onto the period (δ stays ≈ 0.01–0.6), so the construction *chooses* the
//! cut: after a warm-up period from rest, every period p = 1, 2, … is run, and every window
//! [pL + s, pL + s + L) with s on a grid of at most [`WRAP_CANDIDATES`] starts is a
//! candidate — its bits, stored at address n mod L, are one period of the probe (the input
//! is an exact function of n mod L, see `lanes`), and its only discontinuity is the
//! mismatch x(pL + s) − x((p+1)L + s). Each lane keeps its best candidate, and periods are
//! run until every lane's wrap energy is at most [`WRAP_TOLERANCE`] (5%) of the in-band
//! error of an aligned period, at most [`MAX_PERIODS`]. The wrap is *clean* when that
//! holds for the kept period's own in-band error (`wrap_error_ratio`, recorded in the
//! manifest and the RTL header with the state mismatch and the periods run). Measured on
//! the default's 32 streams (order 3, OSR 32, A_p 0.5, L = 20,000): the I streams' wraps
//! cost 10⁻⁷–10⁻⁴ of the in-band error, the Q streams' up to 2% (the sine's quadrature
//! leaves a residue in the second integrator that no cut removes; 32 periods do no better
//! than 8). A higher order, OSR or a short L (few in-band bins) can stay above 5%
//! (order 5: ≈ 6%; L = 4096 at OSR 64: ≈ 50%), and the ROM says so.

use super::config::ProbeConfig;
use super::modulator::{Modulator, SAFETY_MARGIN};
use super::simd::lanes::{LANES, LaneGroup, LaneProbe};
use super::wrap::{WrapMetric, inband_error_energy};
use crate::error::DspError;

pub mod rom;

pub use rom::{ProbeRom, nearest_bin};

/// A wrap is clean when its transient's in-band energy is at most this share of the
/// period's in-band error: 5% (0.2 dB of in-band SNR) is well inside the ±20% by which the
/// in-band quantisation error of one period varies from period to period anyway (measured
/// 25–40 around 30 for the default's 4.5 kHz stream), so a clean wrap is not
/// distinguishable from the noise it sits in.
pub const WRAP_TOLERANCE: f64 = 0.05;
/// Periods after the warm-up searched at most for a clean wrap.
pub const MAX_PERIODS: usize = 8;
/// Cut positions tried per period at most (every sample for L ≤ 2^16, else a grid).
pub const WRAP_CANDIDATES: usize = 1 << 16;

/// A designed probe set: the modulator and its measured amplitude limit, reusable for
/// many ROMs (the stability sweep is the expensive part of the design). It serialises as
/// its configuration and measured limit; deserialising designs the modulator again
/// (deterministic and fast) but skips the stability sweep, and re-checks the amplitude.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(into = "ProbeDesignRecord", try_from = "ProbeDesignRecord")]
pub struct ProbeDesign {
    pub config: ProbeConfig,
    pub modulator: Modulator,
    /// Measured maximum stable sine amplitude at the frequency it was measured.
    pub max_stable_amplitude: f64,
    /// Normalised frequency of that measurement.
    pub limit_f_norm: f64,
}

/// What a [`ProbeDesign`] serialises to: the configuration and the measured limit.
#[derive(serde::Serialize, serde::Deserialize)]
struct ProbeDesignRecord {
    config: ProbeConfig,
    max_stable_amplitude: f64,
    limit_f_norm: f64,
}

impl From<ProbeDesign> for ProbeDesignRecord {
    fn from(d: ProbeDesign) -> Self {
        ProbeDesignRecord {
            config: d.config,
            max_stable_amplitude: d.max_stable_amplitude,
            limit_f_norm: d.limit_f_norm,
        }
    }
}

impl TryFrom<ProbeDesignRecord> for ProbeDesign {
    type Error = String;

    fn try_from(r: ProbeDesignRecord) -> Result<Self, String> {
        ProbeDesign::with_known_limit(&r.config, r.max_stable_amplitude, r.limit_f_norm)
            .map_err(|e| e.to_string())
    }
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
        // A modulator stable at no usable amplitude is the design's fault, not the
        // amplitude's: name the out-of-band gain (the knob that makes it unstable).
        if limit.is_nan() || limit < super::config::MIN_AMPLITUDE {
            return Err(DspError::out_of_range(
                "probe.h_inf",
                config.h_inf,
                format!(
                    "an h_inf whose order-{} OSR-{} modulator is stable at a probe amplitude of at least {} \
                     (this one is stable only up to {a_max:.2e} at f/f_s = {f_norm:.3e})",
                    config.order,
                    config.osr,
                    super::config::MIN_AMPLITUDE / SAFETY_MARGIN
                ),
            )
            .with_hint("h_inf = 1.5 (the Lee criterion for a two-level quantiser)"));
        }
        if config.amplitude > limit {
            return Err(DspError::out_of_range(
                "probe.amplitude",
                config.amplitude,
                // Rounded down: the printed bound is a value that works (0.69975 printed
                // as 0.6998 was itself refused).
                format!(
                    "{} <= amplitude <= {:.4}",
                    super::config::MIN_AMPLITUDE,
                    (limit * 1e4).floor() / 1e4
                ),
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

/// What the periodic search kept for a group (zeros for a windowed ROM).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WrapStats {
    pub(crate) mismatch: f64,
    pub(crate) ratio: f64,
    pub(crate) periods: usize,
}

/// Runs a periodic group until every lane has a clean cut (see the module docs) and
/// returns one period per lane, each lane's bits from its own best cut.
pub(crate) fn periodic(
    g: &mut LaneGroup,
    probes: &[LaneProbe],
    ss: &super::realize::StateSpace,
    metric: &WrapMetric,
) -> Result<(Vec<u16>, WrapStats), DspError> {
    let l = metric.period;
    let live = probes.len().min(LANES);
    let stride = l.div_ceil(WRAP_CANDIDATES).max(1);
    let cuts: Vec<usize> = (0..l).step_by(stride).collect();
    // Runs period p, recording the state before each cut position.
    let run_period = |g: &mut LaneGroup,
                      p: usize,
                      bits: &mut [u16],
                      states: &mut Vec<Vec<[f64; LANES]>>|
     -> Result<(), DspError> {
        states.clear();
        for (i, &c) in cuts.iter().enumerate() {
            states.push(g.states.clone());
            let end = cuts.get(i + 1).copied().unwrap_or(l);
            g.run(ss, (p * l + c) as u64, &mut bits[c..end])?;
        }
        Ok(())
    };
    let energy_of = |bits: &[u16], lane: usize| {
        let p = &probes[lane];
        inband_error_energy(
            bits.iter().map(|w| (w >> lane) & 1 == 1),
            l,
            metric.band_bins,
            p.bin,
            p.quadrature,
            p.amplitude,
        )
    };
    let mut prev = vec![0u16; l];
    let mut cur = vec![0u16; l];
    let (mut prev_states, mut cur_states) = (Vec::new(), Vec::new());
    g.run(ss, 0, &mut prev)?; // warm-up: the start-up transient from rest
    run_period(g, 1, &mut prev, &mut prev_states)?;
    // The search's yardstick: each lane's in-band error over an aligned period.
    let reference: Vec<f64> = (0..live).map(|lane| energy_of(&prev, lane)).collect();
    let mut chosen = prev.clone();
    let mut best = vec![(f64::INFINITY, 0.0f64); live]; // (wrap energy, max |δ|)
    let mut periods = 0;
    let mut delta = vec![0.0; ss.order];
    for p in 2..=MAX_PERIODS + 1 {
        run_period(g, p, &mut cur, &mut cur_states)?;
        periods += 1;
        for lane in 0..live {
            let mut cand = (f64::INFINITY, 0.0, 0usize);
            for (i, &s) in cuts.iter().enumerate() {
                for (r, d) in delta.iter_mut().enumerate() {
                    *d = prev_states[i][r][lane] - cur_states[i][r][lane];
                }
                let e = metric.energy(&delta);
                if e < cand.0 {
                    let worst = delta.iter().fold(0.0f64, |m, d| m.max(d.abs()));
                    cand = (e, worst, s);
                }
            }
            if cand.0 < best[lane].0 {
                best[lane] = (cand.0, cand.1);
                // Window [(p−1)L + s, pL + s): addresses ≥ s from period p − 1.
                let mask = 1u16 << lane;
                for (a, w) in chosen.iter_mut().enumerate() {
                    let src = if a >= cand.2 { prev[a] } else { cur[a] };
                    *w = (*w & !mask) | (src & mask);
                }
            }
        }
        if (0..live).all(|lane| best[lane].0 <= WRAP_TOLERANCE * reference[lane]) {
            break;
        }
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut prev_states, &mut cur_states);
    }
    let mut stats = WrapStats {
        periods,
        ..WrapStats::default()
    };
    for (lane, &(e, worst)) in best.iter().enumerate() {
        let total = energy_of(&chosen, lane);
        stats.ratio = stats.ratio.max(if total > 0.0 { e / total } else { 0.0 });
        stats.mismatch = stats.mismatch.max(worst);
    }
    Ok((chosen, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sd::RomMode;
    use crate::window::Window;

    #[test]
    fn an_amplitude_above_the_stable_limit_is_rejected_with_its_range() {
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
    /// included, carries the probe and nothing the modulator would not leave anyway.
    /// Judged against a scalar reference run: every kept stream must be a genuine window
    /// of the uninterrupted modulator (found by search in the reference's bits), its cut's
    /// wrap energy, from the reference's own states, within [`WRAP_TOLERANCE`] of the
    /// stream's in-band error; and one period must read A_p (correlation with cos/sin over
    /// the period: the in-band noise leaves ≈ 1e-3) and ≈ 0 at a bin it does not probe.
    #[test]
    fn periodic_rom_keeps_a_clean_cut_of_the_running_modulator() {
        let l = 20_000usize;
        let cfg = ProbeConfig {
            rom_mode: RomMode::Periodic,
            rom_depth: l,
            ..ProbeConfig::default()
        };
        let d = ProbeDesign::with_known_limit(&cfg, 0.77, 1e-4).unwrap();
        let bins = [9u64, 100, 311];
        let rom = ProbeRom::generate(&d, 10e6, 10_000_000, &bins).unwrap();
        assert_eq!(rom.depth(), l);
        assert_eq!(rom.window, Window::Rectangular);
        assert!((rom.bins[0] - 4500.0).abs() < 1e-9);
        assert_eq!(nearest_bin(rom.bins[1], 10e6, l), 100);
        assert!(rom.wrap_clean(), "ratio {}", rom.wrap_error_ratio);
        assert!((1..=MAX_PERIODS).contains(&rom.wrap_periods));
        let man = rom.manifest();
        assert!(man.wrap_clean && man.wrap_error_ratio == rom.wrap_error_ratio);

        let metric = WrapMetric::new(&d.modulator.ss, l, cfg.osr);
        let span = (MAX_PERIODS + 2) * l;
        for (b, &k) in bins.iter().enumerate() {
            for q in 0..2 {
                let reg = 2 * b + q;
                let probe = LaneProbe {
                    bin: k,
                    quadrature: q == 1,
                    amplitude: cfg.amplitude,
                };
                // The reference: the scalar modulator on the generator's own input.
                let g = LaneGroup::new(&[probe], l as u64, Window::Rectangular, 3);
                let mut u = vec![[0.0; LANES]; crate::sd::simd::lanes::ANCHOR];
                let mut x = d.modulator.zero_state();
                let mut states = Vec::with_capacity(span + 1);
                let mut v = vec![0.0; span];
                let mut one = [0.0];
                for n0 in (0..span).step_by(u.len()) {
                    let m = (span - n0).min(u.len());
                    g.inputs(n0 as u64, &mut u[..m]);
                    for (t, row) in u[..m].iter().enumerate() {
                        states.push(x.clone());
                        d.modulator
                            .run(&[row[0]], &mut x, &mut one, 0.5, 0)
                            .unwrap();
                        v[n0 + t] = one[0];
                    }
                }
                states.push(x.clone());
                let rom_bit = |a: usize| rom.image.bit(a, reg);
                // Windows [t, t + L) stored at address n mod L: cuts a few samples apart
                // give the same ROM when the bits between them repeat, so every match
                // counts and the best one is the cut.
                let matches: Vec<usize> = (l..span - l)
                    .filter(|&t| (0..l).all(|i| rom_bit((t + i) % l) == (v[t + i] > 0.0)))
                    .collect();
                assert!(
                    !matches.is_empty(),
                    "register {reg} is no window of the modulator"
                );
                let total = inband_error_energy(
                    (0..l).map(rom_bit),
                    l,
                    metric.band_bins,
                    k,
                    q == 1,
                    cfg.amplitude,
                );
                let ratio = matches
                    .iter()
                    .map(|&t| {
                        let delta: Vec<f64> = states[t]
                            .iter()
                            .zip(&states[t + l])
                            .map(|(a, b)| a - b)
                            .collect();
                        metric.energy(&delta) / total
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(ratio <= WRAP_TOLERANCE, "register {reg}: ratio {ratio}");
                // The ROM's figure is the worst stream's, to 3 significant digits (≤ 0.5%).
                assert!(
                    ratio <= rom.wrap_error_ratio * (1.0 + 5e-3),
                    "register {reg}"
                );
                let corr = |kk: u64| {
                    (0..l)
                        .map(|a| {
                            let th = 2.0 * std::f64::consts::PI * (kk * a as u64) as f64 / l as f64;
                            let p = if q == 0 { th.cos() } else { th.sin() };
                            if rom_bit(a) { p } else { -p }
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

    /// The criterion can fail, and the ROM says so: at L = 4096 and OSR 64 the band holds
    /// 32 bins, its quantisation noise is tiny, and no cut of eight periods gets the wrap
    /// below 5% of it (measured ≈ 50% for the worst stream).
    #[test]
    fn a_wrap_that_cannot_be_made_clean_is_reported() {
        let cfg = ProbeConfig {
            rom_mode: RomMode::Periodic,
            rom_depth: 4096,
            osr: 64.0,
            ..ProbeConfig::default()
        };
        let d = ProbeDesign::with_known_limit(&cfg, 0.77, 1e-4).unwrap();
        let rom = ProbeRom::generate(&d, 10e6, 1 << 20, &[1, 2, 9]).unwrap();
        assert!(!rom.wrap_clean(), "ratio {}", rom.wrap_error_ratio);
        assert!(rom.wrap_error_ratio > WRAP_TOLERANCE && rom.wrap_error_ratio.is_finite());
        assert_eq!(rom.wrap_periods, MAX_PERIODS);
        assert!(!rom.manifest().wrap_clean);
    }
}
