//! The bit-true spectrum of a scene: the pixel's readout normalised into per-bin phasors
//! (amplitude in µm, phase), for `tofprobe simulate` to print beside the float results.
//!
//! The registers hold Σ ±x with x in units of 2^−F TDC codes; dividing by 2^F gives the
//! same raw (I, Q) sums as the float ΣΔ probing of crates/dsp, so the dsp normalisation
//! (2/N, coherent gain, probe amplitude, prefilter response) applies unchanged.

use tofprobe_dsp::sd::{ProbeRom, normalise, prefilter_response};
use tofprobe_scene::PhotonSource;

use crate::driver::FrameDriver;
use crate::error::PixelError;
use crate::params::{Mode, PixelParams};
use crate::readout::Readout;

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

/// One probed bin of a Fourier readout: the register sums and what they normalise to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinPhasor {
    /// Probe frequency, Hz.
    pub frequency_hz: f64,
    /// I and Q register sums in TDC codes (the words / 2^G).
    pub i_codes: f64,
    /// See [`BinPhasor::i_codes`].
    pub q_codes: f64,
    /// |H_pre(f_k)| of the prefilter α = 2^−S at the bin, divided out of the amplitude.
    pub prefilter_gain: f64,
    /// Amplitude of the depth motion at this frequency, µm (0 where not finite).
    pub amplitude_um: f64,
    /// Phase of cos(2π f t + φ), degrees (0 where not finite).
    pub phase_deg: f64,
}

/// The register words of a Fourier readout (sign-extended, register 2k = I and 2k + 1 = Q
/// of bin k) as (I, Q) sums in TDC codes: the words count operands of G fraction bits
/// (x >>> (F − G)), so one code is 2^G.
pub fn register_sums(params: &PixelParams, words: &[i64]) -> Vec<(f64, f64)> {
    let scale = f64::from(1u32 << params.register_frac_bits());
    words
        .chunks_exact(2)
        .map(|c| (c[0] as f64 / scale, c[1] as f64 / scale))
        .collect()
}

/// THE readout → phasor function (every command, report and study normalises a Fourier
/// readout here): (I − jQ) · 2/N / (G · A_p · H_pre(f_k)) in codes, times the LSB, with the
/// ROM's design (bins, window gain, probe amplitude), the prefilter α = 2^−S and the
/// registers' 2^G scale. `words` are the sign-extended register words of a frame of
/// `pulses` pulses; `lsb_mm` is the TDC code size.
pub fn phasors(
    params: &PixelParams,
    rom: &ProbeRom,
    words: &[i64],
    pulses: u64,
    lsb_mm: f64,
) -> Result<Vec<BinPhasor>, PixelError> {
    if params.mode != Mode::Fourier {
        return Err(PixelError::mismatch(
            "spectrum mode",
            params.mode,
            "fourier",
        ));
    }
    if words.len() != 2 * rom.bins.len() || rom.bins.len() != params.bins {
        return Err(PixelError::mismatch(
            "readout words",
            words.len(),
            format!("2 per ROM bin ({} bins)", rom.bins.len()),
        ));
    }
    let sums = register_sums(params, words);
    let alpha = 1.0 / f64::from(1u32 << params.shift);
    let normalised = normalise(rom, &sums, pulses, Some(alpha));
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    Ok(normalised
        .iter()
        .zip(&sums)
        .zip(&rom.bins)
        .map(|((y, &(i, q)), &f)| BinPhasor {
            frequency_hz: f,
            i_codes: i,
            q_codes: q,
            prefilter_gain: prefilter_response(alpha, f / rom.sample_rate_hz).norm(),
            // normalise works in the sums' unit (TDC codes); µm = codes · LSB (mm) · 1000.
            amplitude_um: finite(y.norm() * lsb_mm * 1000.0),
            phase_deg: finite(y.arg().to_degrees()),
        })
        .collect())
}

/// The spectrum of a Fourier readout of `pulses` pulses ([`phasors`], with the median
/// amplitude and the refused count).
pub fn spectrum_from_readout(
    params: &PixelParams,
    rom: &ProbeRom,
    readout: &Readout,
    pulses: u64,
    lsb_mm: f64,
) -> Result<BitTrueSpectrum, PixelError> {
    let bins: Vec<BinEstimate> = phasors(params, rom, &readout.words, pulses, lsb_mm)?
        .iter()
        .map(|b| BinEstimate {
            frequency_hz: b.frequency_hz,
            amplitude_um: b.amplitude_um,
            phase_deg: b.phase_deg,
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
/// level ([`FrameDriver`]: the folded driver when it pays; streamed, never holding the
/// record) and returns its spectrum. For `tofprobe
/// simulate`: `lsb_mm` is the sensor's `tdc_lsb_mm()`.
pub fn bit_true_spectrum(
    params: &PixelParams,
    rom: &ProbeRom,
    source: &PhotonSource,
    lsb_mm: f64,
) -> Result<BitTrueSpectrum, PixelError> {
    let mut tm = FrameDriver::new(params, Some(&rom.image))?;
    let mut result = Ok(());
    source.for_each_chunk(params.frame_pulses, CHUNK, |first, chunk| {
        if result.is_ok() {
            result = tm.run(chunk, first);
        }
    });
    result?;
    let readout = tm.readout();
    spectrum_from_readout(params, rom, &readout, params.frame_pulses, lsb_mm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tofprobe_dsp::sd::{ProbeConfig, ProbeDesign};

    /// The one normalisation against a naive float pixel: a 3-code cosine through the
    /// prefilter x[n] = x[n−1] + α(d[n−1] − x[n−1]), summed with the ROM's ±1 bits into
    /// W-bit words with F fraction bits, must read back 3 codes · LSB at its bin and ≈ 0 at
    /// another. Tolerance 1 %: the ΣΔ probe reads A_p to < 0.5 % (crates/dsp probe tests),
    /// the word rounding is 2^−F/N relative, and Blackman leakage from bin 100 to bin 40
    /// is below −90 dB.
    #[test]
    fn readout_normalises_to_the_tone_amplitude() {
        let n = 8192usize;
        let cfg = ProbeConfig::default();
        let design = ProbeDesign::new(&cfg, 40.0 / n as f64).unwrap();
        let rom = ProbeRom::generate(&design, 10e6, n as u64, &[40, 100]).unwrap();
        let p = PixelParams {
            bins: 2,
            frame_pulses: n as u64,
            rom_depth: n,
            frac_bits: 8,
            shift: 5,
            width: 40,
            ..PixelParams::default()
        };
        let alpha = 1.0 / 32.0;
        let (amp, phase) = (3.0, 0.3f64);
        let d: Vec<f64> = (0..n)
            .map(|i| amp * (2.0 * std::f64::consts::PI * 40.0 * i as f64 / n as f64 + phase).cos())
            .collect();
        let mut x = d[0];
        let mut sums = [0.0f64; 4];
        for i in 1..n {
            x += alpha * (d[i - 1] - x);
            for (r, s) in sums.iter_mut().enumerate() {
                *s += if rom.image.bit(i, r) { x } else { -x };
            }
        }
        let words =
            |frac: f64| -> Vec<i64> { sums.iter().map(|s| (s * frac).round() as i64).collect() };
        let lsb_mm = 0.75;
        let b = phasors(&p, &rom, &words(256.0), n as u64, lsb_mm).unwrap();
        let want_um = amp * lsb_mm * 1000.0;
        // Registers keeping G = 2 of the F = 8 fraction bits count in 2^−2 codes: the same
        // sums as G-bit words must read back the same amplitude (the word rounding, 2^−2/N
        // relative, is far below the 1 %), and read as F-bit words they would be 2^6 low.
        let pg = PixelParams {
            register_frac_bits: Some(2),
            ..p.clone()
        };
        let bg = phasors(&pg, &rom, &words(4.0), n as u64, lsb_mm).unwrap();
        assert!(
            (bg[0].amplitude_um / want_um - 1.0).abs() < 0.01,
            "G = 2: {} vs {want_um}",
            bg[0].amplitude_um
        );
        let wrong = phasors(&p, &rom, &words(4.0), n as u64, lsb_mm).unwrap();
        assert!(wrong[0].amplitude_um < 0.02 * want_um);
        assert!(
            (b[0].amplitude_um / want_um - 1.0).abs() < 0.01,
            "{} vs {want_um}",
            b[0].amplitude_um
        );
        assert!(b[1].amplitude_um < 0.01 * want_um, "{}", b[1].amplitude_um);
        // The prefilter's delay and gain are divided out: the phase is the tone's.
        assert!(
            (b[0].phase_deg - phase.to_degrees()).abs() < 1.0,
            "{}",
            b[0].phase_deg
        );
        let h = prefilter_response(alpha, 40.0 / n as f64).norm();
        assert!((b[0].prefilter_gain - h).abs() < 1e-12);
    }
}
