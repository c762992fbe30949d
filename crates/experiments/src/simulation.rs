//! One simulation of a resolved design, as `tofprobe simulate` reports it: the photon/TDC
//! record's summary (pulses, detections, background wins, mean and σ of the measured
//! depth), then one frame through the bit-true pixel — its spectrum at the configured bins
//! (Fourier) or its transient analysis (Haar). Returned as data; the CLI prints it.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::spectrum::BitTrueSpectrum;
use tofprobe_scene::{FillCounts, PhotonSource};

use crate::ExperimentError;
use crate::spectrum::{run_spectrum, setup, write_svg};
use crate::transients::{HaarAnalysis, bit_true_haar};

/// Pulses per streamed chunk (a multiple of the source's block, so nothing is regenerated).
const CHUNK: usize = 1 << 18;

/// One bin of the bit-true spectrum.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BinOut {
    /// Probe frequency, Hz.
    pub frequency_hz: f64,
    /// Amplitude, µm; `null` when the frame has no detections (an empty record has no
    /// spectrum, and 0 would read as a measured amplitude).
    pub amplitude_um: Option<f64>,
    /// Phase, degrees; `null` when the frame has no detections.
    pub phase_deg: Option<f64>,
}

/// The bit-true part of the output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BitTrueOut {
    /// Register width W used.
    pub width_bits: u32,
    /// Pulses in the frame.
    pub frame_pulses: u64,
    /// One entry per bin, ROM order.
    pub bins: Vec<BinOut>,
    /// The paper's noise statistic: the mean amplitude over the bins away from the scene's
    /// tones (more than 1.5 ROM bins f_s/L from each), µm; over all bins when every bin
    /// holds a tone. `null` when the frame has no detections.
    pub noise_estimate_um: Option<f64>,
    /// Bins the noise estimate averages.
    pub noise_bins: usize,
    /// Median amplitude over all the bins, tones included, µm; `null` without detections.
    pub median_amplitude_um: Option<f64>,
    /// Wall time of ROM generation (s).
    pub rom_seconds: f64,
    /// ROM organisation: "windowed" or "periodic".
    pub rom_mode: String,
    /// ROM depth L.
    pub rom_depth: usize,
    /// Periodic ROM: worst stream's in-band wrap error over its in-band quantisation
    /// error (0 for windowed; clean at ≤ 0.05).
    pub rom_wrap_error_ratio: f64,
    /// Whether the wrap is clean (always true for windowed).
    pub rom_wrap_clean: bool,
    /// The ROM's wrap phrase for the text output (`ProbeRom::wrap_summary`).
    #[serde(skip)]
    pub rom_wrap_summary: Option<String>,
    /// Wall time of the transaction-model frame (s).
    pub model_seconds: f64,
}

/// One simulation (`simulate --json`'s object): the record summary plus the bit-true
/// spectrum (Fourier) or the transient analysis (Haar).
#[derive(Debug, Clone, Serialize)]
pub struct Simulation {
    #[serde(flatten)]
    pub summary: Summary,
    /// "fourier" or "haar", and why when `pixel.mode = "auto"` picked it.
    pub mode: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode_reason: Option<String>,
    pub notes: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bit_true: Option<BitTrueOut>,
    /// Haar mode: the frame's transient analysis (scalogram, thresholds, events).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub haar: Option<HaarOut>,
    /// The Fourier frame's spectrum (for the plot).
    #[serde(skip)]
    pub spectrum: Option<BitTrueSpectrum>,
}

/// The Haar part of the output.
#[derive(Debug, Clone, Serialize)]
pub struct HaarOut {
    pub width_bits: u32,
    pub frame_pulses: u64,
    pub model_seconds: f64,
    #[serde(flatten)]
    pub analysis: HaarAnalysis,
}

/// The summary of one simulated record.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Pulses simulated.
    pub pulses: u64,
    /// Pulses with a detection.
    pub detections: u64,
    /// Detections won by a background photon.
    pub background_wins: u64,
    /// Detections / pulses.
    pub detection_rate: f64,
    /// Mean measured depth over detections (mm; code-bin centres); `null` without
    /// detections (an empty record has no mean, and 0 would read as a depth).
    pub mean_depth_mm: Option<f64>,
    /// Standard deviation of the measured depth (mm); `null` with fewer than two detections.
    pub sigma_depth_mm: Option<f64>,
    /// Wall-clock time of the simulation (s).
    pub seconds: f64,
}

/// Streams the record through a running sum; `progress(pulses_done)` is called after each
/// chunk.
pub fn summarise(source: &PhotonSource, pulses: u64, mut progress: impl FnMut(u64)) -> Summary {
    let start = Instant::now();
    let mut counts = FillCounts::default();
    // Sums of code and code², exact in integers; depth is affine in the code.
    let (mut s1, mut s2) = (0u128, 0u128);
    let mut buf = vec![None; CHUNK];
    let mut first = 0u64;
    while first < pulses {
        let n = (pulses - first).min(CHUNK as u64) as usize;
        counts += source.fill_counted(first, &mut buf[..n]);
        for c in buf[..n].iter().flatten() {
            s1 += u128::from(*c);
            s2 += u128::from(*c) * u128::from(*c);
        }
        first += n as u64;
        progress(first);
    }
    let d = counts.detections;
    let (mean_code, var_code) = if d == 0 {
        (0.0, 0.0)
    } else {
        let m = s1 as f64 / d as f64;
        let v = if d > 1 {
            // Integer form of the sum of squared deviations, then one division.
            let num = (d as u128 * s2 - s1 * s1) as f64;
            num / (d as f64 * (d - 1) as f64)
        } else {
            0.0
        };
        (m, v.max(0.0))
    };
    let lsb_mm = source.code_to_depth_mm(1) - source.code_to_depth_mm(0);
    Summary {
        pulses,
        detections: d,
        background_wins: counts.background_wins,
        detection_rate: d as f64 / pulses.max(1) as f64,
        mean_depth_mm: (d > 0).then(|| source.code_to_depth_mm(0) + mean_code * lsb_mm),
        sigma_depth_mm: (d > 1).then(|| var_code.sqrt() * lsb_mm),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Simulates the design's record and its first frame; `progress(pulses_done)` follows the
/// record's Monte Carlo.
pub fn simulate(
    design: &ResolvedDesign,
    progress: impl FnMut(u64),
) -> Result<Simulation, ExperimentError> {
    let source = design.photon_source()?;
    let pulses = design.pulses();
    let s = summarise(&source, pulses, progress);
    // The bit-true frame is the record's first N pulses (the same source and seed): a
    // record without detections leaves it empty too.
    let empty_frame = s.detections == 0 && design.pixel.frame_pulses <= s.pulses;
    let bit_true = bit_true(design, &source, empty_frame)?;
    let haar = if design.pixel.mode == tofprobe_pixel::Mode::Haar {
        let (analysis, model_seconds) = bit_true_haar(design)?;
        Some(HaarOut {
            width_bits: design.pixel.width,
            frame_pulses: design.pixel.frame_pulses,
            model_seconds,
            analysis,
        })
    } else {
        None
    };
    let (bit_true, spectrum) = bit_true.unzip();
    Ok(Simulation {
        summary: s,
        mode: design.pixel.mode.to_string(),
        mode_reason: design.mode.auto.as_ref().map(|c| c.reason.clone()),
        notes: design.notes.clone(),
        bit_true,
        haar,
        spectrum,
    })
}

/// Writes the simulation's plot: the Haar scalogram with its events, or the Fourier
/// spectrum.
pub fn write_plot(
    sim: &Simulation,
    design: &ResolvedDesign,
    path: &Path,
) -> Result<(), ExperimentError> {
    if let Some(h) = &sim.haar {
        crate::scalogram::write_scalogram_svg(
            &h.analysis.scalogram,
            &format!("bit-true Haar scalogram: {}", design.origin),
            Some(&h.analysis.events),
            path,
        )?;
        Ok(())
    } else if let Some(spectrum) = &sim.spectrum {
        write_svg(
            path,
            &format!("bit-true spectrum: {}", design.origin),
            spectrum,
        )
    } else {
        Err(ExperimentError::Output {
            path: path.to_path_buf(),
            message: "the spectrum plot needs pixel.mode = \"fourier\"".into(),
        })
    }
}

/// Runs the bit-true pixel over one frame (Fourier mode; `None` in Haar mode);
/// The paper's noise statistic over a spectrum: the mean amplitude of the bins more than
/// 1.5 bin widths from every tone, and how many bins that is (all bins when none is away).
pub fn noise_away_from_tones(
    frequencies_hz: &[f64],
    amplitudes: &[f64],
    tones: &[(f64, f64)],
    bin_hz: f64,
) -> (f64, usize) {
    let away: Vec<f64> = frequencies_hz
        .iter()
        .zip(amplitudes)
        .filter(|(f, _)| tones.iter().all(|(t, _)| (*f - t).abs() > 1.5 * bin_hz))
        .map(|(_, &a)| a)
        .collect();
    let used = if away.is_empty() {
        amplitudes
    } else {
        &away[..]
    };
    (
        used.iter().sum::<f64>() / used.len().max(1) as f64,
        used.len(),
    )
}

/// `empty_frame`: the frame has no detections, and its figures are absent, not 0.
fn bit_true(
    design: &ResolvedDesign,
    source: &PhotonSource,
    empty_frame: bool,
) -> Result<Option<(BitTrueOut, BitTrueSpectrum)>, ExperimentError> {
    if design.pixel.mode != tofprobe_pixel::Mode::Fourier {
        return Ok(None);
    }
    let t0 = Instant::now();
    let setup = setup(design)?;
    let rom_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let lsb_mm = design.sensor().tdc_lsb_mm();
    let spectrum = run_spectrum(&setup, source, lsb_mm, &design.origin)?;
    let model_seconds = t1.elapsed().as_secs_f64();
    let bin_hz = design.sensor().laser_rate_hz / setup.params.rom_depth as f64;
    let amplitudes: Vec<f64> = spectrum.bins.iter().map(|b| b.amplitude_um).collect();
    let frequencies: Vec<f64> = spectrum.bins.iter().map(|b| b.frequency_hz).collect();
    let noise = noise_away_from_tones(&frequencies, &amplitudes, design.tones(), bin_hz);
    let out = BitTrueOut {
        width_bits: setup.params.width,
        frame_pulses: setup.params.frame_pulses,
        bins: spectrum
            .bins
            .iter()
            .map(|b| BinOut {
                frequency_hz: b.frequency_hz,
                amplitude_um: (!empty_frame).then_some(b.amplitude_um),
                phase_deg: (!empty_frame).then_some(b.phase_deg),
            })
            .collect(),
        noise_estimate_um: (!empty_frame).then_some(noise.0),
        noise_bins: noise.1,
        median_amplitude_um: (!empty_frame).then_some(spectrum.median_amplitude_um),
        rom_seconds,
        rom_mode: setup.rom.mode.name().to_string(),
        rom_depth: setup.rom.depth(),
        rom_wrap_error_ratio: setup.rom.wrap_error_ratio,
        rom_wrap_clean: setup.rom.wrap_clean(),
        rom_wrap_summary: setup.rom.wrap_summary(),
        model_seconds,
    };
    Ok(Some((out, spectrum)))
}
