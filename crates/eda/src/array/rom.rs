//! The probe ROM of an array chip as a memory: its bits, an area *estimate* for a ROM
//! macro per technology ([`rom_macro_estimates`]), beside its size as synthesised logic (a
//! depth-D prefix of the real ROM synthesised and scaled by L/D, [`rom_logic`]).

use std::path::Path;

use serde::{Deserialize, Serialize};
use tofprobe_pixel::PixelParams;

use crate::error::{EdaError, Result};
use crate::fsutil::write_atomic;
use crate::liberty::Liberty;
use crate::synth::{SynthSpec, synthesise};

/// Entries of the probe ROM synthesised as logic (then scaled to the whole ROM).
pub const ROM_LOGIC_DEPTH: usize = 1024;

/// A ROM macro's area per bit on sky130 (µm²), an *estimate*: the densest open memory macro
/// for sky130 at hand is OpenRAM's 1024 × 32 single-port SRAM, 534,277 µm² for 32,768 bits
/// (16.3 µm² a bit, periphery included; vsdip/vsdsram_sky130). A mask ROM's one-transistor
/// cell is denser than a 6T SRAM cell, so this bounds a ROM macro from above.
pub const SKY130_MACRO_UM2_PER_BIT: f64 = 534_277.0 / 32_768.0;

/// The probe ROM of the chip, as a memory.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RomSize {
    /// L: entries.
    pub depth: usize,
    /// Bits per entry (one per register, 2B).
    pub width_bits: usize,
    /// L × 2B.
    pub bits: u64,
    /// Area estimates of a ROM macro per technology (labelled estimates).
    pub macro_estimates: Vec<RomMacroEstimate>,
    /// The ROM synthesised as logic, per library.
    pub logic: Vec<RomLogic>,
}

/// One technology's ROM-macro estimate.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RomMacroEstimate {
    /// Technology (`sky130`, `osu018`, or the target node).
    pub technology: String,
    /// Its feature size (nm).
    pub node_nm: f64,
    /// Area per bit (µm²).
    pub um2_per_bit: f64,
    /// Area of the whole ROM (µm²).
    pub area_um2: f64,
    /// Where the figure comes from.
    pub basis: String,
}

/// The ROM-macro estimates for `bits` bits on sky130, osu018 (180 nm) and `node_nm`, scaled
/// from sky130 by (node / 130)² (the size report's first-order scaling).
pub fn rom_macro_estimates(bits: u64, node_nm: f64) -> Vec<RomMacroEstimate> {
    let est = |technology: &str, node: f64, basis: String| {
        let per = SKY130_MACRO_UM2_PER_BIT * crate::scaling::node_factor(node);
        RomMacroEstimate {
            technology: technology.into(),
            node_nm: node,
            um2_per_bit: per,
            area_um2: per * bits as f64,
            basis,
        }
    };
    let sky = "estimate: OpenRAM sky130 1024×32 SRAM macro density (534,277 µm² / 32,768 bits, \
               periphery included), an upper bound for a mask ROM"
        .to_string();
    let mut v = vec![
        est("sky130", 130.0, sky.clone()),
        est("osu018", 180.0, format!("{sky}, scaled by (180/130)²")),
    ];
    if (node_nm - 130.0).abs() > 1e-9 && (node_nm - 180.0).abs() > 1e-9 {
        v.push(est(
            &format!("{node_nm} nm"),
            node_nm,
            format!("{sky}, scaled by ({node_nm}/130)²"),
        ));
    }
    v
}

/// The probe ROM synthesised as logic on one library: a depth-D prefix of the ROM, scaled
/// to the whole by L/D (ΣΔ bits are close to random, so logic grows with the bits).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RomLogic {
    /// Library name.
    pub library: String,
    /// D: entries synthesised.
    pub synthesised_depth: usize,
    /// Area of those D entries (µm²).
    pub synthesised_area_um2: f64,
    /// Cells of those D entries.
    pub synthesised_cells: u64,
    /// The whole ROM's area as logic, scaled by L/D (µm²).
    pub area_um2: f64,
}

/// The probe ROM `rom` of the pixel `pixel` (L = `pixel.rom_depth` entries) synthesised as
/// logic on `liberty`: its first min(L, [`ROM_LOGIC_DEPTH`]) entries, rendered by the
/// generator, the area scaled by L/D.
pub fn rom_logic(
    pixel: &PixelParams,
    rom: &[u64],
    liberty: &Path,
    cache: &Path,
) -> Result<RomLogic> {
    let l = pixel.rom_depth;
    let d = l.min(ROM_LOGIC_DEPTH);
    let mut p = pixel.clone();
    p.rom_depth = d;
    let words = p.registers().div_ceil(64);
    let prefix = rom.get(..d * words).ok_or_else(|| EdaError::OutOfRange {
        field: "probe ROM words",
        value: rom.len().to_string(),
        allowed: format!("at least {} (D = {d} entries of {words} words)", d * words),
    })?;
    let files = tofprobe_rtlgen::render(&p, prefix, &tofprobe_rtlgen::RenderOptions::default())?;
    let bytes: Vec<u8> = files.iter().flat_map(|f| f.contents.bytes()).collect();
    let dir = cache
        .join("rom-logic")
        .join(format!("{:016x}", tofprobe_io::fnv1a64(&bytes)));
    std::fs::create_dir_all(&dir).map_err(|e| EdaError::io("creating", &dir, e))?;
    let mut sources = Vec::new();
    let rom_name = tofprobe_rtlgen::module_names(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX).1;
    for f in files.iter().filter(|f| f.template == "probe_rom.v") {
        let path = dir.join(&f.name);
        write_atomic(&path, f.contents.as_bytes())?;
        if f.name.ends_with(".v") {
            sources.push(path);
        }
    }
    let spec = SynthSpec {
        sources,
        top: rom_name,
        params: vec![],
        liberty: liberty.to_path_buf(),
        delay_target_ps: None,
        keep: vec![],
    };
    let s = synthesise(&spec, &cache.join("synth"))?;
    let lib = Liberty::load(liberty)?;
    Ok(RomLogic {
        library: lib.name,
        synthesised_depth: d,
        synthesised_area_um2: s.total_area_um2,
        synthesised_cells: s.cell_count,
        area_um2: s.total_area_um2 * l as f64 / d as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rom_macro_scales_with_the_node_squared() {
        let e = rom_macro_estimates(640_000, 40.0);
        assert_eq!(e.len(), 3);
        // 16.305 µm²/bit × 640 kbit = 10.44 mm² on sky130.
        assert!((e[0].um2_per_bit - 16.3048).abs() < 1e-3, "{e:?}");
        assert!((e[0].area_um2 - 640_000.0 * 534_277.0 / 32_768.0).abs() < 1e-6);
        assert!((e[1].area_um2 / e[0].area_um2 - (180.0f64 / 130.0).powi(2)).abs() < 1e-12);
        assert!((e[2].area_um2 / e[0].area_um2 - (40.0f64 / 130.0).powi(2)).abs() < 1e-12);
        assert_eq!(rom_macro_estimates(1, 130.0).len(), 2);
    }
}
