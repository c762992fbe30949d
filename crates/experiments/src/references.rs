//! Float references of one frame of a caller's own detections (TDC codes, `None` = no
//! detection), at the design's probe bins, composed from the one implementation of each:
//! the depth of a code (`PhotonSource::code_to_depth_mm`), the float front end's hold
//! ([`crate::records::held_record`]), the selected-bin DFT (`dsp::selected_bins::SelectedBins`) at
//! the ROM's bins as N-point DFT indices ([`dft_bins`]) with the ROM's
//! window, float ΣΔ probing (`dsp::sd::probe_detections` + `normalise`, α = 2^−S: the
//! pixel's float twin), and the closed-form noise floor (eq. 12 with the 1NN-hold and
//! first-arrival extensions, `dsp::closed_form`). The Python package's `Design.dft`,
//! `float_sd` and `noise_floor` are these functions.

use rustfft::num_complex::Complex64;
use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_dsp::closed_form::{MixtureParams, noise_floor_hold_mm};
use tofprobe_dsp::sd::{ProbeRom, normalise, probe_detections};
use tofprobe_dsp::selected_bins::SelectedBins;

use crate::error::ExperimentError;
use crate::records::held_record;

/// One reading per probe bin, in ROM order: the phasor (mm; A·e^{jφ} for a tone
/// A·cos(ω_k n + φ)).
pub type Phasors = Vec<Complex64>;

/// The ROM's bins k·f_s/L as indices of the N-point DFT (equal in windowed mode, the
/// nearest bin in periodic mode when L does not divide N).
pub fn dft_bins(rom_bins: &[u64], n: u64, rom_depth: usize) -> Vec<usize> {
    rom_bins
        .iter()
        .map(|&k| (k as f64 * n as f64 / rom_depth as f64).round() as usize)
        .collect()
}

fn dsp_err(design: &ResolvedDesign) -> impl Fn(tofprobe_dsp::DspError) -> ExperimentError + '_ {
    move |source| ExperimentError::from(DesignError::probe(&design.origin, source))
}

/// The windowed DFT (the ROM's window, 2/(N·G) normalisation) of the held depth record of
/// `detections` at the ROM's bins; N = `detections.len()`.
pub fn dft(
    design: &ResolvedDesign,
    rom: &ProbeRom,
    detections: &[Option<u32>],
) -> Result<Phasors, ExperimentError> {
    let source = design.photon_source()?;
    let held = held_record(&source, detections, 0.0)?;
    let n = held.len() as u64;
    let bins = dft_bins(&rom.bin_indices, n, rom.depth());
    let err = dsp_err(design);
    let mut sel = SelectedBins::new(n, &bins, rom.window).map_err(&err)?;
    for chunk in held.chunks(1 << 16) {
        sel.push(chunk).map_err(&err)?;
    }
    let sums = sel.finish().map_err(&err)?;
    Ok(sums
        .iter()
        .zip(&bins)
        .map(|(x, &k)| x * tofprobe_dsp::dft::amplitude_scale(k, n as usize, rom.window))
        .collect())
}

/// Float ΣΔ probing of `detections` (the pixel's float twin: the same ROM, hold, priming
/// and prefilter α = 2^−S), normalised to phasors in mm.
pub fn float_sd(
    design: &ResolvedDesign,
    rom: &ProbeRom,
    detections: &[Option<u32>],
) -> Result<Phasors, ExperimentError> {
    let source = design.photon_source()?;
    let alpha = 1.0 / f64::from(1u32 << design.pixel.shift.min(31));
    let depths = detections
        .iter()
        .map(|c| c.map(|c| source.code_to_depth_mm(c)));
    let sums = probe_detections(rom, depths, Some(alpha));
    Ok(normalise(rom, &sums, detections.len() as u64, Some(alpha)))
}

/// What the closed forms read of a design's detected depth: the first-arrival mixture of
/// signal and background, the depth's σ (the mixture's variance plus the TDC's a²/12) and
/// the valid rate ρ_v the 1NN hold sees. A scene without photons has no mixture: nothing
/// is detected (ρ_v = 0). One computation for [`noise_floor_um`] and the trade-off's
/// closed-form level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectionNoise {
    pub mixture: MixtureParams,
    pub sigma_mm: f64,
    pub valid_rate: f64,
}

/// [`DetectionNoise`] of the design's scene and sensor.
pub fn detection_noise(design: &ResolvedDesign) -> Result<DetectionNoise, tofprobe_dsp::DspError> {
    let s = &design.document.sensor;
    let mixture = MixtureParams {
        signal_rate: s.signal_rate,
        background_rate: s.background_rate,
        signal_depth_mm: design.document.scene.depth_mm - s.window_start_mm(),
        jitter_mm: s.jitter_mm(),
        window_mm: s.window_end_mm() - s.window_start_mm(),
    };
    let arrival = tofprobe_dsp::closed_form::detected(&mixture)?;
    let lsb_mm = design.sensor().tdc_lsb_mm();
    Ok(DetectionNoise {
        mixture,
        sigma_mm: (arrival.variance_mm2 + lsb_mm * lsb_mm / 12.0).sqrt(),
        valid_rate: arrival.valid_rate.min(1.0),
    })
}

/// The closed-form noise floor E|Y| (µm) at each probe bin for a frame of `pulses` pulses
/// of the design's scene: σ² of the first-arrival mixture plus the TDC's a²/12, the 1NN
/// hold at the valid rate ρ_v, N_eff = N·G²/P of the ROM's window (eq. 12 and its
/// extensions, `dsp::closed_form`; the same terms as the trade-off's closed-form level).
/// Without photons nothing is detected (ρ_v = 0) and the floor is 0.
pub fn noise_floor_um(
    design: &ResolvedDesign,
    rom: &ProbeRom,
    pulses: u64,
) -> Result<Vec<f64>, ExperimentError> {
    let noise = detection_noise(design).map_err(dsp_err(design))?;
    let (sigma, rho) = (noise.sigma_mm, noise.valid_rate);
    let n_eff = pulses as f64 * rom.window.effective_length_factor();
    let fs = design.sensor().laser_rate_hz;
    Ok(rom
        .bins
        .iter()
        .map(|&f| {
            // ρ = 1 holds nothing: the factor is 1 and this is eq. 12 itself.
            let omega = 2.0 * std::f64::consts::PI * f / fs;
            noise_floor_hold_mm(sigma, rho, omega, n_eff) * 1000.0
        })
        .collect())
}
