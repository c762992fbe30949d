//! Vibration maps of a Fourier array frame: each pixel's readout through THE readout →
//! phasor function (`tofprobe_pixel::spectrum::phasors`), arranged as [B, R, C] maps of
//! amplitude (µm) and phase (degrees); the dominant bin (largest mean amplitude over the
//! array), each pixel's strongest bin, the complex deflection shape at a bin, and the modal
//! assurance criterion that compares two shapes.

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_pixel::spectrum::phasors;

use crate::error::ArrayError;
use crate::model::ArrayFrame;

/// The maps of one frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VibrationMaps {
    pub rows: usize,
    pub cols: usize,
    /// Probe frequency of each bin (Hz), ROM order.
    pub frequencies_hz: Vec<f64>,
    /// [B, R, C] amplitude, µm.
    pub amplitude_um: Vec<f64>,
    /// [B, R, C] phase of cos(2πft + φ), degrees.
    pub phase_deg: Vec<f64>,
    /// The bin with the largest mean amplitude over the array.
    pub dominant_bin: usize,
    /// [R, C] each pixel's strongest bin.
    pub strongest_bin: Vec<usize>,
}

impl VibrationMaps {
    /// Number of bins.
    pub fn bins(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// Bin `b`'s amplitude map, [R, C] µm.
    pub fn amplitude(&self, b: usize) -> &[f64] {
        let n = self.rows * self.cols;
        &self.amplitude_um[b * n..(b + 1) * n]
    }

    /// Bin `b`'s phase map, [R, C] degrees.
    pub fn phase(&self, b: usize) -> &[f64] {
        let n = self.rows * self.cols;
        &self.phase_deg[b * n..(b + 1) * n]
    }

    /// The complex deflection shape at bin `b`: (re, im) µm per pixel, row-major.
    pub fn deflection(&self, b: usize) -> Vec<(f64, f64)> {
        self.amplitude(b)
            .iter()
            .zip(self.phase(b))
            .map(|(&a, &p)| {
                let (s, c) = p.to_radians().sin_cos();
                (a * c, a * s)
            })
            .collect()
    }

    /// Mean amplitude of bin `b` over the array, µm.
    pub fn mean_amplitude(&self, b: usize) -> f64 {
        let m = self.amplitude(b);
        m.iter().sum::<f64>() / m.len().max(1) as f64
    }
}

/// The maps of a Fourier frame read with the chip's probe ROM `rom`.
pub fn fourier_maps(
    design: &ResolvedDesign,
    rom: &ProbeRom,
    frame: &ArrayFrame,
) -> Result<VibrationMaps, ArrayError> {
    let (rows, cols) = (frame.rows, frame.cols);
    let n = rows * cols;
    let b = rom.bins.len();
    let lsb_mm = design.sensor().tdc_lsb_mm();
    let mut amplitude_um = vec![0.0; b * n];
    let mut phase_deg = vec![0.0; b * n];
    let mut strongest_bin = vec![0; n];
    for p in 0..n {
        let words = frame.pixel(p / cols, p % cols);
        let ph = phasors(&design.pixel, rom, words, design.pixel.frame_pulses, lsb_mm).map_err(
            |source| ArrayError::Pixel {
                row: p / cols,
                col: p % cols,
                source,
            },
        )?;
        let mut best = (0, f64::NEG_INFINITY);
        for (k, bin) in ph.iter().enumerate() {
            amplitude_um[k * n + p] = bin.amplitude_um;
            phase_deg[k * n + p] = bin.phase_deg;
            if bin.amplitude_um > best.1 {
                best = (k, bin.amplitude_um);
            }
        }
        strongest_bin[p] = best.0;
    }
    let mut maps = VibrationMaps {
        rows,
        cols,
        frequencies_hz: rom.bins.clone(),
        amplitude_um,
        phase_deg,
        dominant_bin: 0,
        strongest_bin,
    };
    maps.dominant_bin = (0..b)
        .max_by(|&x, &y| maps.mean_amplitude(x).total_cmp(&maps.mean_amplitude(y)))
        .unwrap_or(0);
    Ok(maps)
}

/// The modal assurance criterion of two complex shapes:
/// |Σ conj(a)·b|² / (Σ|a|² · Σ|b|²), 1 for shapes equal up to a complex scale, 0 for
/// orthogonal ones.
pub fn mac(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let (mut re, mut im, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0);
    for (&(ar, ai), &(br, bi)) in a.iter().zip(b) {
        re += ar * br + ai * bi;
        im += ar * bi - ai * br;
        na += ar * ar + ai * ai;
        nb += br * br + bi * bi;
    }
    if na == 0.0 || nb == 0.0 {
        return 0.0;
    }
    (re * re + im * im) / (na * nb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mac_of_scaled_and_orthogonal_shapes() {
        let a = [(1.0, 0.0), (-2.0, 0.5), (0.3, -1.0)];
        // (2 − 3j)·a: the same shape.
        let b: Vec<(f64, f64)> = a
            .iter()
            .map(|&(r, i)| (2.0 * r + 3.0 * i, 2.0 * i - 3.0 * r))
            .collect();
        assert!((mac(&a, &b) - 1.0).abs() < 1e-12);
        assert!(mac(&[(1.0, 0.0), (0.0, 0.0)], &[(0.0, 0.0), (1.0, 0.0)]).abs() < 1e-15);
    }
}
