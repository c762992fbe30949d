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

use crate::error::StudyError;

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
    /// Median over the bins of each bin's closed-form Rayleigh median (µm), the floor the
    /// measured rate and σ imply (see [`ReplayBin::closed_form_um`]).
    pub closed_form_floor_um: Option<f64>,
    /// Median over the bins of amplitude / the bin's closed-form median: ≈ 1 when the
    /// record's depth samples are independent with the measured σ. Bin by bin because the
    /// hold's floor falls as 1/f above its bandwidth (ρ·f_s/2π, a few hundred Hz at
    /// ρ = 10⁻³): a median of amplitudes against a mean of floors differs by the bins'
    /// spread alone (0.46 on the HydraHarp T3 record, which is why this is a ratio of medians).
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
    /// The closed-form Rayleigh median of a noise-only amplitude at this bin (µm):
    /// 0.939·sqrt(π σ² F(ρ, ω)/N_eff), F the 1NN hold's noise factor; `None` without σ.
    pub closed_form_um: Option<f64>,
}

/// A record's decoding error (it names the file, the record index and what was expected).
fn scene_err(_origin: &str) -> impl Fn(SceneError) -> StudyError + '_ {
    StudyError::from
}

/// The record's delay bin (T3) or time unit (T2) in ps, as the replay will use it.
fn unit_ps(path: &Path, req: &ReplayRequest) -> Result<f64, StudyError> {
    let r = tttr::open(path).map_err(scene_err(DEFAULT_ORIGIN))?;
    let s = req
        .resolution_s
        .or(r.header().resolution_s)
        .ok_or_else(|| StudyError::Option {
            option: "resolution-s".into(),
            value: "(none)".into(),
            allowed: format!(
                "the delay bin in seconds: {} does not state it (SPC: TAC range / ADC bins)",
                path.display()
            ),
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
pub fn fit_sensor(path: &Path, req: &ReplayRequest) -> Result<FittedSensor, StudyError> {
    let e = scene_err(DEFAULT_ORIGIN);
    let reader = tttr::open(path).map_err(&e)?;
    let sync_rate_hz = reader
        .header()
        .sync_rate_hz
        .or_else(|| reader.header().global_resolution_s.map(|g| 1.0 / g))
        .filter(|r| r.is_finite() && *r > 0.0)
        .ok_or_else(|| StudyError::Option {
            option: "CONFIG".into(),
            value: path.display().to_string(),
            allowed: "a record whose header gives the sync rate, or a configuration".into(),
        })?;
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
        return Err(StudyError::Option {
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
pub fn fitted_design(fit: &FittedSensor) -> Result<ResolvedDesign, StudyError> {
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
        return Err(StudyError::Option {
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
) -> Result<ReplayOutcome, StudyError> {
    let (fitted, owned);
    let design = match design {
        Some(d) => {
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
        return Err(StudyError::Option {
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
    let closed = closed_form_bins(&rom, sigma, rate, sensor.laser_rate_hz, n);
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
            closed_form_um: closed.as_ref().map(|c| c[k]),
        })
        .collect();
    let closed_floor = closed.as_deref().and_then(median);
    let ratios: Vec<f64> = bins
        .iter()
        .filter_map(|b| b.closed_form_um.map(|c| b.amplitude_um / c))
        .collect();
    let floor_ratio = closed.as_ref().and_then(|_| median(&ratios));
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
        closed_form_floor_um: closed_floor,
        floor_ratio,
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

/// Each ROM bin's closed-form Rayleigh median of a noise-only amplitude (µm):
/// 0.939·sqrt(π σ² F(ρ, ω_k) / N_eff) with the hold's noise factor F at the bin. `None`
/// without σ, with ρ outside (0, 1] or a floor that is not positive and finite.
fn closed_form_bins(
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
    let floors: Vec<f64> = rom
        .bins
        .iter()
        .map(|f| {
            let omega = 2.0 * std::f64::consts::PI * f / fs;
            noise_floor_hold_mm(sigma, rho, omega, n_eff) * RAYLEIGH_MEDIAN_OVER_MEAN * 1000.0
        })
        .collect();
    floors
        .iter()
        .all(|c| c.is_finite() && *c > 0.0)
        .then_some(floors)
}

/// The median (mean of the middle two for an even count); `None` when empty.
fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    Some(if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    })
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
