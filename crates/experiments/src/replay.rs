//! Replay of a real time-tagged record (PicoQuant PTU, Becker & Hickl SPC) through the same
//! path as a simulated one: the record's pulses as per-pulse detections
//! ([`tofprobe_scene::tttr::PulseStream`]), the bit-true pixel (transaction model) and its
//! float twin (the one float front end and float ΣΔ probing of the same ROM), the spectrum,
//! and the closed-form noise floor that the record's own detection rate and depth spread
//! imply, compared with the floor the pixel reads.
//!
//! Without a configuration the sensor is fitted to the record in a first streaming pass:
//! the delay histogram over the whole sync period locates the return peak; its full width
//! at half maximum gives σ; the timing window is the peak ± [`WINDOW_SIGMAS`] σ with
//! [`AUTO_CODES`] codes (the default's 80-code TDC); the laser rate is the sync rate; the
//! frame is the largest whole number of probe-ROM periods the record holds. The rest is
//! the embedded default (the periodic ΣΔ probe, the pixel). With a configuration, its
//! window, LSB and frame are used as given.

use std::path::Path;

use serde::Serialize;
use tofprobe_design::{DEFAULT_ORIGIN, DEFAULT_TOML, DesignError, Document, ResolvedDesign};
use tofprobe_dsp::closed_form::noise_floor_hold_mm;
use tofprobe_dsp::sd::{ProbeAccumulator, ProbeRom, amplitudes_um};
use tofprobe_pixel::TransactionModel;
use tofprobe_pixel::spectrum::{BitTrueSpectrum, spectrum_from_readout};
use tofprobe_scene::SceneError;
use tofprobe_scene::tttr::{
    self, PulseStream, ReplayCounts, ReplayOptions, TdcWindow, TttrSummary,
};

use crate::error::ExperimentError;
use crate::record_bounds;

/// Half-width of the fitted window in units of the fitted σ.
pub const WINDOW_SIGMAS: f64 = 8.0;
/// Codes of the fitted TDC (as the default's 400 ps / 5 ps).
pub const AUTO_CODES: f64 = 80.0;
/// Round-trip depth per picosecond of flight time (mm/ps).
const MM_PER_PS: f64 = 0.15;
/// Pulses per streamed chunk.
const CHUNK: usize = 1 << 16;
/// Most delay-histogram bins of the fitting pass.
const HIST_CODES: f64 = 65_536.0;
/// Median over mean of a Rayleigh magnitude: sqrt(2 ln 2) / sqrt(π/2).
const RAYLEIGH_MEDIAN_OVER_MEAN: f64 = 0.939_437_278_699_651_3;

/// What to replay and how to read it.
#[derive(Debug, Clone, Default)]
pub struct ReplayRequest {
    /// T2: the sync channel (see [`ReplayOptions::sync_channel`]).
    pub sync_channel: Option<u8>,
    /// Only this photon channel.
    pub photon_channel: Option<u8>,
    /// The delay bin / time-tag unit in seconds instead of the header's (needed for SPC).
    pub resolution_s: Option<f64>,
}

/// The sensor fitted to a record (first pass).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FittedSensor {
    /// Sync (laser) rate, Hz.
    pub sync_rate_hz: f64,
    /// Pulses (sync periods) in the record.
    pub pulses: u64,
    /// Delay of the histogram's peak after the sync, ps.
    pub peak_ps: f64,
    /// σ of the return peak from its full width at half maximum (FWHM / 2.3548), ps.
    pub sigma_ps: f64,
    /// Pulses with a photon anywhere in the sync period / pulses.
    pub detection_rate_any: f64,
}

/// The outcome of a replay.
#[derive(Debug, Clone, Serialize)]
pub struct ReplayOutcome {
    /// The decoder's summary of the whole record.
    pub record: TttrSummary,
    /// Where the configuration came from (a file, or the fit to the record).
    pub configuration: String,
    /// The first-pass fit (without a configuration).
    pub fitted: Option<FittedSensor>,
    /// The window and TDC the record was quantised by.
    pub window: TdcWindow,
    /// Pulses in the frame replayed through the pixel.
    pub frame_pulses: u64,
    /// The replay's counts over the frame.
    pub counts: ReplayCounts,
    /// Detections inside the window / frame pulses.
    pub detection_rate: f64,
    /// Mean depth of the detections (mm, code-bin centres), `None` without detections.
    pub mean_depth_mm: Option<f64>,
    /// Standard deviation of the detected depth (mm), `None` with fewer than two.
    pub sigma_depth_mm: Option<f64>,
    /// The bit-true spectrum at the design's bins.
    pub bins: Vec<ReplayBin>,
    /// Median bit-true amplitude over the bins (µm): the measured noise floor.
    pub measured_floor_um: f64,
    /// Median over the bins of the closed-form floors the measured rate and σ imply (µm):
    /// at each bin the Rayleigh median with the 1NN hold's noise factor F(ρ, ω_k)
    /// ([`ReplayBin::closed_form_floor_um`]).
    pub closed_form_floor_um: Option<f64>,
    /// Median over the bins of amplitude / closed-form floor, bin by bin ([`floor_ratio`]):
    /// 1 when the record's detections are the closed form's independent per-pulse draws
    /// and the bins hold no signal.
    pub floor_ratio: Option<f64>,
}

/// One bin of the replayed spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReplayBin {
    /// Probe frequency, Hz.
    pub frequency_hz: f64,
    /// Bit-true amplitude, µm.
    pub amplitude_um: f64,
    /// Float twin's amplitude (float ΣΔ of the same detections), µm.
    pub float_amplitude_um: f64,
    /// Bit-true phase, degrees.
    pub phase_deg: f64,
    /// The closed-form floor at this bin (Rayleigh median, µm), `None` without a σ.
    pub closed_form_floor_um: Option<f64>,
}

/// A record's decoding error (it names the file, the record index and what was expected).
fn scene_err(_origin: &str) -> impl Fn(SceneError) -> ExperimentError + '_ {
    ExperimentError::from
}

/// What the record may ask of a replay, checked before a pulse is streamed
/// ([`crate::record_bounds`]): the pulses it spans, its resolution.
fn check_record(path: &Path, req: &ReplayRequest) -> Result<(), ExperimentError> {
    let r = tttr::open(path)?;
    record_bounds::resolution_s(path, r.header(), req.resolution_s)?;
    record_bounds::check_span(path)?;
    Ok(())
}

/// The record's delay bin (T3) or time unit (T2) in ps, as the replay will use it.
fn unit_ps(path: &Path, req: &ReplayRequest) -> Result<f64, ExperimentError> {
    let r = tttr::open(path).map_err(scene_err(DEFAULT_ORIGIN))?;
    let s = record_bounds::resolution_s(path, r.header(), req.resolution_s)?.ok_or_else(|| {
        ExperimentError::Option {
            option: "resolution-s".into(),
            value: "(none)".into(),
            allowed: format!(
                "the delay bin in seconds: {} does not state it (SPC: TAC range / ADC bins)",
                path.display()
            ),
        }
    })?;
    Ok(s * 1e12)
}

fn options(window: TdcWindow, req: &ReplayRequest) -> ReplayOptions {
    ReplayOptions {
        window,
        sync_channel: req.sync_channel,
        photon_channel: req.photon_channel,
        resolution_s: req.resolution_s,
    }
}

/// First pass: the delay histogram over the whole sync period, its peak and FWHM.
pub fn fit_sensor(path: &Path, req: &ReplayRequest) -> Result<FittedSensor, ExperimentError> {
    let e = scene_err(DEFAULT_ORIGIN);
    check_record(path, req)?;
    let reader = tttr::open(path).map_err(&e)?;
    let sync_rate_hz = record_bounds::sync_rate_hz(path, reader.header())?;
    let period_ps = 1e12 / sync_rate_hz;
    let unit = unit_ps(path, req)?;
    let lsb = unit.max(period_ps / HIST_CODES);
    let window = TdcWindow {
        tdc_lsb_ps: lsb,
        window_start_ps: 0.0,
        window_length_ps: (period_ps / lsb).floor().max(1.0) * lsb,
    };
    let mut stream = PulseStream::new(reader, &options(window, req)).map_err(&e)?;
    let mut hist = vec![0u64; window.tdc_codes() as usize];
    let pulses = stream
        .for_each_chunk(CHUNK, |_, d| {
            for c in d.iter().flatten() {
                hist[*c as usize] += 1;
            }
        })
        .map_err(&e)?;
    let detections: u64 = hist.iter().sum();
    if detections == 0 || pulses == 0 {
        return Err(ExperimentError::Option {
            option: "FILE".into(),
            value: path.display().to_string(),
            allowed: "a record with at least one photon after a sync".into(),
        });
    }
    let (peak, &top) = hist
        .iter()
        .enumerate()
        .max_by_key(|(i, c)| (**c, std::cmp::Reverse(*i)))
        .unwrap_or((0, &0));
    // The half-maximum crossings either side of the peak (a floor of background counts
    // is subtracted: the median bin).
    let mut sorted = hist.clone();
    sorted.sort_unstable();
    let floor = sorted[sorted.len() / 2] as f64;
    let half = floor + (top as f64 - floor) / 2.0;
    let lo = (0..peak)
        .rev()
        .find(|&i| (hist[i] as f64) < half)
        .map_or(0, |i| i + 1);
    let hi = (peak + 1..hist.len())
        .find(|&i| (hist[i] as f64) < half)
        .unwrap_or(hist.len());
    let fwhm_ps = ((hi - lo) as f64 * lsb).max(lsb);
    Ok(FittedSensor {
        sync_rate_hz,
        pulses,
        peak_ps: (peak as f64 + 0.5) * lsb,
        sigma_ps: fwhm_ps / (8.0 * std::f64::consts::LN_2).sqrt(),
        detection_rate_any: detections as f64 / pulses as f64,
    })
}

/// The configuration fitted to a record: the embedded default with the record's sync
/// rate, a window of ±[`WINDOW_SIGMAS`] σ around the peak in [`AUTO_CODES`] codes, the
/// measured rates, and a frame of whole ROM periods.
pub fn fitted_design(fit: &FittedSensor) -> Result<ResolvedDesign, ExperimentError> {
    let mut doc = Document::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN)?;
    let half = WINDOW_SIGMAS * fit.sigma_ps;
    let start = (fit.peak_ps - half).max(0.0);
    let lsb = (2.0 * half / AUTO_CODES).max(1e-3);
    let s = &mut doc.sensor;
    s.laser_rate_hz = fit.sync_rate_hz;
    s.jitter_ps = fit.sigma_ps;
    s.tdc_lsb_ps = lsb;
    s.window_start_ps = start;
    s.window_length_ps = lsb * AUTO_CODES;
    s.signal_rate = fit.detection_rate_any.clamp(1e-6, 1.0);
    s.background_rate = 0.0;
    doc.scene.depth_mm = fit.peak_ps * MM_PER_PS;
    // Bins are chosen for the scene's tones: a small reference tone at 4.5 kHz (the
    // default's) keeps the default's bin layout; the record decides what it holds.
    for m in &mut doc.scene.motions {
        if let tofprobe_scene::MotionConfig::Sine { amplitude_mm, .. } = m {
            *amplitude_mm = amplitude_mm.min(half * MM_PER_PS / 4.0);
        }
    }
    let l = doc.probe.depth(fit.pulses);
    let whole = (fit.pulses / l as u64) * l as u64;
    if whole == 0 {
        return Err(ExperimentError::Option {
            option: "FILE".into(),
            value: format!("{} pulses", fit.pulses),
            allowed: format!("a record of at least one probe-ROM period ({l} pulses)"),
        });
    }
    doc.acquisition.pulses = Some(whole);
    doc.acquisition.duration_s = None;
    let origin = format!(
        "fitted to the record ({:.0} ps peak, σ {:.1} ps)",
        fit.peak_ps, fit.sigma_ps
    );
    Ok(tofprobe_design::resolve(doc, &origin)?)
}

/// Replays `path` through the pixel of `design` (or of the design fitted to the record).
pub fn replay(
    path: &Path,
    design: Option<&ResolvedDesign>,
    req: &ReplayRequest,
) -> Result<ReplayOutcome, ExperimentError> {
    let (fitted, owned);
    let design = match design {
        Some(d) => {
            check_record(path, req)?;
            fitted = None;
            d
        }
        None => {
            let f = fit_sensor(path, req)?;
            fitted = Some(f);
            owned = fitted_design(&f)?;
            &owned
        }
    };
    let e = scene_err(&design.origin);
    let sensor = &design.document.sensor;
    let window = TdcWindow::from_sensor(sensor);
    let Some(rom) = design.probe_rom()? else {
        return Err(DesignError::pixel(
            &design.origin,
            tofprobe_pixel::PixelError::mismatch("replay mode", design.pixel.mode, "fourier"),
        )
        .into());
    };
    let p = &design.pixel;
    let n = p.frame_pulses;
    let lsb_mm = sensor.tdc_lsb_ps * MM_PER_PS;
    let mut stream =
        PulseStream::new(tttr::open(path).map_err(&e)?, &options(window, req)).map_err(&e)?;
    let mut tm = TransactionModel::new(p).map_err(|x| DesignError::pixel(&design.origin, x))?;
    let alpha = 1.0 / f64::from(1u32 << p.shift);
    let mut float = ProbeAccumulator::new(&rom, Some(alpha));
    let (mut d, mut s1, mut s2) = (0u64, 0u128, 0u128);
    let mut model = Ok(());
    let mut depths = Vec::with_capacity(CHUNK);
    let streamed = stream
        .for_each_chunk(CHUNK, |first, chunk| {
            if first >= n || model.is_err() {
                return;
            }
            let chunk = &chunk[..chunk.len().min((n - first) as usize)];
            model = tm.run(chunk, Some(&rom.image), first);
            depths.clear();
            depths.extend(
                chunk
                    .iter()
                    .map(|c| c.map(|c| (f64::from(c) + 0.5) * lsb_mm)),
            );
            float.push_detections(&depths);
            for c in chunk.iter().flatten() {
                d += 1;
                s1 += u128::from(*c);
                s2 += u128::from(*c) * u128::from(*c);
            }
        })
        .map_err(&e)?;
    model.map_err(|x| DesignError::pixel(&design.origin, x))?;
    if streamed < n {
        return Err(ExperimentError::Option {
            option: "acquisition.pulses".into(),
            value: n.to_string(),
            allowed: format!(
                "at most the record's {streamed} pulses ({}); in whole ROM periods: {}",
                path.display(),
                (streamed / rom.depth() as u64) * rom.depth() as u64
            ),
        });
    }
    let spectrum: BitTrueSpectrum = spectrum_from_readout(p, &rom, &tm.readout(), n, lsb_mm)
        .map_err(|x| DesignError::pixel(&design.origin, x))?;
    let float_um = amplitudes_um(&float.readout());
    let (mean, sigma) = moments(d, s1, s2, lsb_mm, sensor.window_start_ps * MM_PER_PS);
    let rate = d as f64 / n as f64;
    let closed = closed_form_floors(&rom, sigma, rate, sensor.laser_rate_hz, n);
    let bins: Vec<ReplayBin> = spectrum
        .bins
        .iter()
        .zip(&float_um)
        .enumerate()
        .map(|(k, (b, &f))| ReplayBin {
            frequency_hz: b.frequency_hz,
            amplitude_um: b.amplitude_um,
            float_amplitude_um: f,
            phase_deg: b.phase_deg,
            closed_form_floor_um: closed.as_ref().and_then(|c| c.get(k).copied()),
        })
        .collect();
    let amps: Vec<f64> = bins.iter().map(|b| b.amplitude_um).collect();
    let ratio = closed.as_deref().and_then(|c| floor_ratio(&amps, c));
    let mut counts = stream.counts();
    counts.pulses = n;
    counts.detections = d;
    Ok(ReplayOutcome {
        record: stream.reader().summary(),
        configuration: design.origin.clone(),
        fitted,
        window,
        frame_pulses: n,
        counts,
        detection_rate: rate,
        mean_depth_mm: mean,
        sigma_depth_mm: sigma,
        bins,
        measured_floor_um: spectrum.median_amplitude_um,
        closed_form_floor_um: closed.map(median),
        floor_ratio: ratio,
    })
}

/// Mean and sd of the detected depth (code-bin centres, mm), from integer code sums.
fn moments(d: u64, s1: u128, s2: u128, lsb_mm: f64, start_mm: f64) -> (Option<f64>, Option<f64>) {
    if d == 0 {
        return (None, None);
    }
    let m = s1 as f64 / d as f64;
    let mean = Some(start_mm + (m + 0.5) * lsb_mm);
    if d < 2 {
        return (mean, None);
    }
    let num = (d as u128 * s2 - s1 * s1) as f64;
    let var = (num / (d as f64 * (d - 1) as f64)).max(0.0);
    (mean, Some(var.sqrt() * lsb_mm))
}

/// The closed-form noise floor at each of the ROM's bins (µm): the Rayleigh median of
/// |Y(ω_k)|, sqrt(π σ² F(ρ, ω_k)/N_eff)·(median/mean), with the hold's noise factor F.
/// F falls as 1/ω² above the hold's bandwidth (ρ·f_s/2π, ≈ 600 Hz for the HydraHarp T3
/// sample), so the floors of one spectrum differ bin to bin (×17 over the default's
/// 4.5–76 kHz there) and are compared bin by bin ([`floor_ratio`]).
fn closed_form_floors(
    rom: &ProbeRom,
    sigma_mm: Option<f64>,
    rho: f64,
    fs: f64,
    n: u64,
) -> Option<Vec<f64>> {
    let sigma = sigma_mm?;
    if !(rho > 0.0 && rho <= 1.0) || rom.bins.is_empty() {
        return None;
    }
    let n_eff = n as f64 * rom.window.effective_length_factor();
    Some(
        rom.bins
            .iter()
            .map(|f| {
                let omega = 2.0 * std::f64::consts::PI * f / fs;
                noise_floor_hold_mm(sigma, rho, omega, n_eff) * RAYLEIGH_MEDIAN_OVER_MEAN * 1000.0
            })
            .collect(),
    )
}

/// The median of `v` (the mean of the middle two for an even count, as the spectrum's
/// median amplitude); 0 for none.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        m if m % 2 == 1 => v[m / 2],
        m => 0.5 * (v[m / 2 - 1] + v[m / 2]),
    }
}

/// Measured against closed form, bin by bin: the median over bins of amplitude_k / floor_k.
/// Each ratio is a Rayleigh draw over its own median, so the median of them is ≈ 1 (sd
/// ≈ 0.18 for 16 bins) however much the floors differ between bins. The ratio of the median
/// amplitude to the mean floor is not: with floors ∝ 1/f over the default's bins it is
/// ≈ 0.49 even for amplitudes exactly at their floors (the tests below), the 0.46 that
/// replay reported before. `None` if a floor is not positive or the lengths differ.
pub fn floor_ratio(amplitudes_um: &[f64], floors_um: &[f64]) -> Option<f64> {
    if amplitudes_um.len() != floors_um.len()
        || floors_um.is_empty()
        || floors_um.iter().any(|f| !(*f > 0.0 && f.is_finite()))
    {
        return None;
    }
    Some(median(
        amplitudes_um
            .iter()
            .zip(floors_um)
            .map(|(a, f)| a / f)
            .collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default's 16 bins (Hz, as replay prints them for the HydraHarp T3 sample).
    const BINS: [f64; 16] = [
        4500.0, 5750.0, 10750.0, 15750.0, 20750.0, 25750.0, 30750.0, 35750.0, 40750.0, 45750.0,
        50750.0, 55750.0, 60750.0, 65750.0, 70750.0, 75750.0,
    ];

    /// Amplitudes exactly at floors ∝ 1/f (the hold's floors far above its bandwidth): the
    /// bin-by-bin ratio is 1; the old statistic (median amplitude over mean floor) reads
    /// ≈ 0.49, the bias behind replay's former 0.46.
    #[test]
    fn bin_by_bin_ratio_is_one_at_the_floors_where_median_over_mean_is_not() {
        let floors: Vec<f64> = BINS.iter().map(|f| 1e6 / f).collect();
        let r = floor_ratio(&floors, &floors).expect("ratio");
        assert!((r - 1.0).abs() < 1e-12, "{r}");
        let old = median(floors.clone()) / (floors.iter().sum::<f64>() / floors.len() as f64);
        assert!((0.45..0.52).contains(&old), "median/mean = {old}");
        // The check can fail: amplitudes twice their floors read 2.
        let doubled: Vec<f64> = floors.iter().map(|f| 2.0 * f).collect();
        assert!((floor_ratio(&doubled, &floors).expect("ratio") - 2.0).abs() < 1e-12);
    }

    #[test]
    fn ratio_needs_matching_positive_floors() {
        assert_eq!(floor_ratio(&[1.0], &[1.0, 2.0]), None);
        assert_eq!(floor_ratio(&[1.0], &[0.0]), None);
        assert_eq!(floor_ratio(&[], &[]), None);
        assert_eq!(median(vec![3.0, 1.0, 2.0, 10.0]), 2.5);
    }
}
