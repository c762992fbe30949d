//! The probe ROM the RTL commands (`vectors`, `cosim`, `flow`) render and replay: the
//! configuration's ΣΔ probe ROM (`[probe]` design, windowed or periodic, bins from
//! `frequencies_hz` or the scene via `autobins`) whenever that ROM can exist for the frame
//! actually simulated, else the sign-of-cosine probe of `stimulus::sign_probe_rom` with
//! the reason stated. The ΣΔ ROM needs its bins inside the band f_s/(2·OSR), i.e. a depth
//! of a few hundred pulses at least (a windowed ROM of a 64-pulse frame has none; the
//! default's periodic ROM keeps its 20,000 entries however short the frame), and a
//! windowed ROM is N entries deep, so frames beyond [`MAX_SD_ROM_DEPTH`] keep the short
//! periodic sign probe rather than a ROM file of more than 2^24 lines. `tofprobe rtl`
//! itself renders the same ROM (the committed `rtl/` holds the default's): see
//! testbench/README.md.

use tofprobe_dsp::sd::{ProbeDesign, ProbeRom};
use tofprobe_pixel::autobins::band_limit;
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::stimulus::sign_probe_rom;

use crate::config::Config;
use crate::error::CliError;

/// Deepest ΣΔ ROM the RTL commands generate (2^24 entries; the default 1 s frame, 10^7
/// entries, is a 90 MB `$readmemh` file, generated in seconds and loaded by Verilator in
/// about one; the whole frame co-simulates in ~35 s).
pub const MAX_SD_ROM_DEPTH: usize = 1 << 24;

/// The ROM chosen for a simulation.
#[derive(Debug, Clone)]
pub struct RtlRom {
    /// Image to render: L × ceil(R/64) words (empty in Haar mode).
    pub words: Vec<u64>,
    /// The ΣΔ ROM and its design (bins, window gain, amplitude) when it is the ΣΔ ROM.
    pub sd: Option<ProbeRom>,
    /// One line saying which ROM this is (and why, for the fallback).
    pub note: String,
}

/// ROM bin indices for depth `depth`: `frequencies_hz` rounded to k·f_s/L, else the
/// scene's in-band tones then noise bins, B in all (as `tofprobe simulate` chooses them).
pub fn sd_bins(config: &Config, bins: usize, depth: usize) -> Result<Vec<u64>, String> {
    super::spectrum_svg::bin_indices(config, bins, depth as u64).map_err(|e| e.to_string())
}

/// Chooses the ROM for `p` (the frame actually simulated) and sets `p.rom_depth` to its
/// depth. Errors only when the ΣΔ ROM should exist but the `[probe]` design rejects it
/// (e.g. an unstable amplitude); an impossible ΣΔ ROM falls back with a note.
pub fn rtl_rom(config: &Config, origin: &str, p: &mut PixelParams) -> Result<RtlRom, CliError> {
    if p.mode == Mode::Haar {
        return Ok(RtlRom {
            words: Vec::new(),
            sd: None,
            note: "Haar mode: no probe ROM".into(),
        });
    }
    let depth = config.probe.depth(p.frame_pulses);
    let limit = band_limit(depth as u64, config.probe.osr);
    let reason = if depth > MAX_SD_ROM_DEPTH {
        Some(format!(
            "a {} ΣΔ ROM of depth {depth} exceeds {MAX_SD_ROM_DEPTH} entries",
            config.probe.rom_mode.name()
        ))
    } else if depth < 16 || (limit as usize) <= p.bins {
        Some(format!(
            "the ΣΔ band f_s/(2·OSR) holds {} bin(s) at L = {depth}, fewer than B = {}",
            limit.saturating_sub(1),
            p.bins
        ))
    } else {
        None
    };
    let bins = match reason {
        Some(r) => Err(r),
        None => sd_bins(config, p.bins, depth),
    };
    let bins = match bins {
        Ok(b) => b,
        Err(why) => {
            let words = sign_probe_rom(p);
            return Ok(RtlRom {
                words,
                sd: None,
                note: format!("sign-of-cosine probe ROM (L = {}): {why}", p.rom_depth),
            });
        }
    };
    let probe_err = |source| CliError::Probe {
        origin: origin.to_string(),
        source,
    };
    let fs = config.sensor.laser_rate_hz;
    // The modulator's stability limit is lowest towards DC: check at the lowest probe.
    let lowest = bins.iter().copied().min().unwrap_or(1).max(1);
    let design =
        ProbeDesign::new(&config.probe, lowest as f64 / depth as f64).map_err(probe_err)?;
    let rom = ProbeRom::generate(&design, fs, p.frame_pulses, &bins).map_err(probe_err)?;
    p.rom_depth = rom.depth();
    p.validate().map_err(tofprobe_rtlgen::RtlError::from)?;
    let wrap = rom
        .wrap_summary()
        .map(|w| format!(", {w}"))
        .unwrap_or_default();
    let note = format!(
        "ΣΔ probe ROM ({} {}, order {}, OSR {}, A_p {}, window gain {}), L = {}, bins k = {:?} (f_k = k·f_s/L){wrap}, content hash {:016x}",
        rom.mode.name(),
        rom.window.name(),
        rom.order,
        rom.osr,
        rom.amplitude,
        rom.coherent_gain,
        rom.depth(),
        rom.bin_indices,
        rom.image.content_hash()
    );
    Ok(RtlRom {
        words: rom.image.words().to_vec(),
        sd: Some(rom),
        note,
    })
}
