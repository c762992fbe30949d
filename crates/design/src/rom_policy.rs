//! The chip ROM policy: the generator's parameters of a resolved design for the frame
//! actually simulated ([`rtl_params`], with the `--frame-pulses` / `--rom-depth`
//! overrides of the RTL commands), and the probe ROM they render and replay: the
//! configuration's ΣΔ probe ROM (`[probe]` design, windowed or periodic, bins from
//! `frequencies_hz` or the scene via `autobins`) whenever that ROM can exist for the frame
//! actually simulated, else the sign-of-cosine probe of `stimulus::sign_probe_rom` with
//! the reason stated. The ΣΔ ROM needs its bins inside the band f_s/(2·OSR), i.e. a depth
//! of a few hundred pulses at least (a windowed ROM of a 64-pulse frame has none; the
//! default's periodic ROM keeps its 20,000 entries however short the frame), and a
//! windowed ROM is N entries deep, so frames beyond [`MAX_SD_ROM_DEPTH`] keep the short
//! periodic sign probe rather than a ROM file of more than 2^24 lines. A periodic ROM is
//! never swapped: its depth is capped at resolution
//! ([`tofprobe_dsp::sd::MAX_PERIODIC_ROM_DEPTH`]), for every command alike. `tofprobe rtl`
//! itself renders the same ROM (the committed `rtl/` holds the default's): see
//! testbench/README.md.

use tofprobe_dsp::sd::{ProbeDesign, ProbeRom, RomMode};
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::stimulus::sign_probe_rom;

use crate::bin_choice::bin_indices_in;
use crate::error::DesignError;
use crate::resolve::ResolvedDesign;

/// ROM depth used when the design leaves L = N and N is a long frame: a periodic probe of
/// this depth (bin spacing f_s/L), not a 10^7-entry ROM.
pub const LONG_FRAME_ROM_DEPTH: usize = 4096;

/// Deepest windowed ΣΔ ROM `tofprobe rtl` renders into a chip ROM (2^16 entries; deeper is
/// a long frame's ROM, which no chip would store: the sign probe stands in, with a note). A
/// periodic ROM is rendered at its own depth, capped at resolution by
/// [`tofprobe_dsp::sd::MAX_PERIODIC_ROM_DEPTH`] for every command alike.
pub const MAX_RENDERED_SD_DEPTH: usize = 1 << 16;

/// The RTL commands' overrides of the resolved design: N and L of the simulated frame.
/// The registers keep the width the design's own frame needs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RtlOverrides {
    /// Pulses per frame N (short frames for co-simulation).
    pub frame_pulses: Option<u64>,
    /// ROM depth L; forces the sign-of-cosine probe ROM.
    pub rom_depth: Option<usize>,
}

/// The generator's parameters of `design` with the overrides `o` applied.
pub fn rtl_params(design: &ResolvedDesign, o: &RtlOverrides) -> Result<PixelParams, DesignError> {
    let mut p = design.pixel.clone();
    // The sign ROM of `--rom-depth` is built whole too (8 bytes per entry and 64 registers):
    // the same cap as a periodic ROM (2^30 aborted out of memory).
    let cap = tofprobe_dsp::sd::MAX_PERIODIC_ROM_DEPTH;
    if let Some(l) = o.rom_depth.filter(|&l| l > cap) {
        return Err(DesignError::pixel(
            &design.origin,
            tofprobe_pixel::PixelError::invalid(
                "rom_depth",
                l,
                format!("--rom-depth is at most {cap} entries (the ROM is built whole)"),
                cap,
            ),
        ));
    }
    if let Some(n) = o.frame_pulses {
        p.frame_pulses = n;
    }
    // A windowed long frame (L = N) keeps the short periodic sign probe; a periodic ROM is
    // the chip's as configured (its depth is capped at resolution, never swapped here).
    let windowed = design.document.probe.rom_mode == RomMode::Windowed;
    p.rom_depth = match o.rom_depth {
        Some(l) => l,
        None if windowed && p.rom_depth > MAX_RENDERED_SD_DEPTH => LONG_FRAME_ROM_DEPTH,
        None => p.rom_depth,
    };
    // A periodic chip ROM stays L deep for a short frame (the frame reads its first N
    // entries); a windowed ROM is one frame deep by definition.
    if o.frame_pulses.is_some() && o.rom_depth.is_none() && windowed {
        p.rom_depth = p.rom_depth.min(p.frame_pulses.max(1) as usize);
    }
    p.validate().map_err(tofprobe_rtlgen::RtlError::from)?;
    Ok(p)
}

/// The ROM `tofprobe rtl` renders for `p` (setting `p.rom_depth` to its depth): the sign
/// probe when `--rom-depth` is given or a windowed ΣΔ ROM would exceed [`MAX_RENDERED_SD_DEPTH`],
/// else [`rtl_rom`].
pub fn chip_rom(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    p: &mut PixelParams,
) -> Result<RtlRom, DesignError> {
    let probe = &design.document.probe;
    let sd_depth = probe.depth(p.frame_pulses);
    let windowed = probe.rom_mode == RomMode::Windowed;
    if o.rom_depth.is_some() || (windowed && sd_depth > MAX_RENDERED_SD_DEPTH) {
        let why = if o.rom_depth.is_some() {
            "--rom-depth given".to_string()
        } else {
            format!(
                "the {} ΣΔ ROM would be {sd_depth} entries deep (> {MAX_RENDERED_SD_DEPTH})",
                probe.rom_mode.name()
            )
        };
        return Ok(RtlRom {
            words: sign_probe_rom(p),
            sd: None,
            note: format!("sign-of-cosine probe ROM (L = {}): {why}", p.rom_depth),
        });
    }
    rtl_rom(design, p)
}

/// The ROM the simulating commands (`vectors`, `cosim`) replay: the sign probe when
/// `--rom-depth` is given, else [`rtl_rom`].
pub fn simulation_rom(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    p: &mut PixelParams,
) -> Result<RtlRom, DesignError> {
    if o.rom_depth.is_some() {
        return Ok(RtlRom {
            words: sign_probe_rom(p),
            sd: None,
            note: "sign-of-cosine probe ROM (--rom-depth given)".to_string(),
        });
    }
    rtl_rom(design, p)
}

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

/// Chooses the ROM for `p` (the frame actually simulated) and sets `p.rom_depth` to its
/// depth. Errors only when the ΣΔ ROM should exist but the `[probe]` design rejects it
/// (e.g. an unstable amplitude); an impossible ΣΔ ROM falls back with a note.
pub fn rtl_rom(design: &ResolvedDesign, p: &mut PixelParams) -> Result<RtlRom, DesignError> {
    let config = &design.document;
    if p.mode == Mode::Haar {
        return Ok(RtlRom {
            words: Vec::new(),
            sd: None,
            note: "Haar mode: no probe ROM".into(),
        });
    }
    let depth = config.probe.depth(p.frame_pulses);
    let reason = if depth > MAX_SD_ROM_DEPTH {
        Some(format!(
            "a {} ΣΔ ROM of depth {depth} exceeds {MAX_SD_ROM_DEPTH} entries",
            config.probe.rom_mode.name()
        ))
    } else if depth < 16 {
        Some(format!(
            "a ΣΔ ROM of {depth} entries is too short to probe (fewer than 16)"
        ))
    } else {
        crate::bin_choice::band_check(depth as u64, config.probe.osr, p.bins).err()
    };
    let bins = match reason {
        Some(r) => Err(r),
        None => {
            bin_indices_in(config, &design.context, p.bins, depth as u64).map_err(|e| e.to_string())
        }
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
    let probe_err = |source| DesignError::probe(&design.origin, source);
    let fs = config.sensor.laser_rate_hz;
    // The modulator's stability limit is lowest towards DC: check at the lowest probe
    // (the resolved design's own when the bins are its own).
    let lowest = bins.iter().copied().min().unwrap_or(1).max(1);
    let probe = match &design.probe_design {
        Some(d) if bins == design.bins && depth == design.pixel.rom_depth => d.clone(),
        _ => ProbeDesign::new(&config.probe, lowest as f64 / depth as f64).map_err(probe_err)?,
    };
    let rom = ProbeRom::generate(&probe, fs, p.frame_pulses, &bins).map_err(probe_err)?;
    p.rom_depth = rom.depth();
    p.validate().map_err(tofprobe_rtlgen::RtlError::from)?;
    let wrap = rom
        .wrap_summary()
        .map(|w| format!(", {w}"))
        .unwrap_or_default();
    // Named only when not the default, so the committed headers keep their text.
    let convention = match rom.convention {
        tofprobe_dsp::sd::ProbeConvention::Tofprobe => String::new(),
        c => format!(", {} convention", c.name()),
    };
    let note = format!(
        "ΣΔ probe ROM ({} {}{convention}, order {}, OSR {}, A_p {}, window gain {}), L = {}, bins k = {:?} (f_k = k·f_s/L){wrap}, content hash {:016x}",
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
