//! The bit-true spectrum of a scene: the pixel's readout normalised into per-bin phasors
//! (amplitude in µm, phase), for `tofprobe simulate` to print beside the float results.
//!
//! The registers hold Σ ±x with x in units of 2^−F TDC codes; dividing by 2^F gives the
//! same raw (I, Q) sums as the float ΣΔ probing of crates/dsp, so the dsp normalisation
//! (2/N, coherent gain, probe amplitude, prefilter response) applies unchanged.

use tofprobe_dsp::sd::{ProbeRom, normalise};
use tofprobe_scene::PhotonSource;

use crate::error::PixelError;
use crate::params::{Mode, PixelParams};
use crate::readout::Readout;
use crate::transaction::TransactionModel;

/// Pulses per chunk streamed from the photon source.
const CHUNK: usize = 1 << 16;

/// One probed bin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinEstimate {
    /// Probe frequency, Hz.
    pub frequency_hz: f64,
    /// Amplitude of the depth motion at this frequency, µm.
    pub amplitude_um: f64,
    /// Phase of cos(2π f t + φ), degrees.
    pub phase_deg: f64,
}

/// The bit-true spectrum of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BitTrueSpectrum {
    /// One estimate per ROM bin, in ROM order.
    pub bins: Vec<BinEstimate>,
    /// Median amplitude over the bins, µm: a noise estimate when most bins hold no tone.
    pub median_amplitude_um: f64,
    /// Refused pulses reported by the status word (0 in a transaction-level run).
    pub refused: u64,
}

/// Normalises a Fourier readout of `pulses` pulses with the ROM's design (bins, window
/// gain, probe amplitude) and the prefilter α = 2^−S; `lsb_mm` is the TDC code size.
pub fn spectrum_from_readout(
    params: &PixelParams,
    rom: &ProbeRom,
    readout: &Readout,
    pulses: u64,
    lsb_mm: f64,
) -> Result<BitTrueSpectrum, PixelError> {
    if params.mode != Mode::Fourier {
        return Err(PixelError::mismatch(
            "spectrum mode",
            params.mode,
            "fourier",
        ));
    }
    if readout.words.len() != 2 * rom.bins.len() || rom.bins.len() != params.bins {
        return Err(PixelError::mismatch(
            "readout words",
            readout.words.len(),
            format!("2 per ROM bin ({} bins)", rom.bins.len()),
        ));
    }
    // Register words count operands of G fraction bits (x >>> (F − G)).
    let scale = f64::from(1u32 << params.register_frac_bits());
    let sums: Vec<(f64, f64)> = readout
        .words
        .chunks(2)
        .map(|c| (c[0] as f64 / scale, c[1] as f64 / scale))
        .collect();
    let alpha = 1.0 / f64::from(1u32 << params.shift);
    let phasors = normalise(rom, &sums, pulses, Some(alpha));
    let bins: Vec<BinEstimate> = phasors
        .iter()
        .zip(&rom.bins)
        .map(|(y, &f)| BinEstimate {
            frequency_hz: f,
            amplitude_um: y.norm() * lsb_mm * 1000.0,
            phase_deg: y.arg().to_degrees(),
        })
        .collect();
    let mut amps: Vec<f64> = bins.iter().map(|b| b.amplitude_um).collect();
    amps.sort_by(f64::total_cmp);
    let median_amplitude_um = match amps.len() {
        0 => 0.0,
        m if m % 2 == 1 => amps[m / 2],
        m => 0.5 * (amps[m / 2 - 1] + amps[m / 2]),
    };
    Ok(BitTrueSpectrum {
        bins,
        median_amplitude_um,
        refused: readout.refused,
    })
}

/// Runs one frame of N = `params.frame_pulses` pulses of `source` through the transaction
/// model (streamed, never holding the record) and returns its spectrum. For `tofprobe
/// simulate`: `lsb_mm` is the sensor's `tdc_lsb_mm()`.
pub fn bit_true_spectrum(
    params: &PixelParams,
    rom: &ProbeRom,
    source: &PhotonSource,
    lsb_mm: f64,
) -> Result<BitTrueSpectrum, PixelError> {
    let mut tm = TransactionModel::new(params)?;
    let mut result = Ok(());
    source.for_each_chunk(params.frame_pulses, CHUNK, |first, chunk| {
        if result.is_ok() {
            result = tm.run(chunk, Some(&rom.image), first);
        }
    });
    result?;
    let readout = tm.readout();
    spectrum_from_readout(params, rom, &readout, params.frame_pulses, lsb_mm)
}
