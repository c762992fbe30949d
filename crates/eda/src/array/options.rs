//! Two options of the array's pixel, sized for `tofprobe size` (issue 27 points 1 and 7):
//!
//! - **The double buffer** (`[array] double_buffer`): a shadow copy of the R·W register
//!   bits and the W-bit status word, loaded on the frame's swap while the next frame
//!   accumulates, read out instead of the live registers (rendered by `templates/pixel.v`
//!   and co-simulated: docs/pixel-contract.md "Double buffer"). Its area here is an
//!   *estimate*, not a synthesis of that RTL, from the synthesised pixel's register-file
//!   split ([`crate::split`]): (R+1)·W flops at the register file's own area per flop (the
//!   flop and its private write-enable logic, as the shadow's load enable is), beside the
//!   bare flops at the liberty's smallest flop. The readout's select multiplexer reads the
//!   shadow instead of the live registers: it moves, it is not added. Reported for every
//!   array, whether the option is on or not, so the cost is known before it is chosen.
//! - **The superpixel** (`[array] superpixel = G`): the averaging front end
//!   (`templates/superpixel.v`) *synthesised* on each library of the size report, and the
//!   memory and area per SPAD — (pixel + front end) / G² — beside the plain pixel's (one
//!   SPAD, the pixel alone).

use std::path::Path;

use serde::{Deserialize, Serialize};
use tofprobe_pixel::{PixelParams, Superpixel};

use crate::array::area::ArrayTotal;
use crate::error::{EdaError, Result};
use crate::fsutil::write_atomic;
use crate::size_report::{AreaSection, SizeReport};
use crate::synth::{SynthSpec, synthesise};

/// The double buffer's area on one library.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DoubleBufferArea {
    /// Library name.
    pub library: String,
    /// The synthesised register file's area (its flops and private write logic, µm²).
    pub register_file_um2: f64,
    /// Its flops.
    pub register_file_flops: u64,
    /// The shadow copy: (R+1)·W flops × the register file's area per flop (µm², estimate).
    pub shadow_um2: f64,
    /// The shadow's bare flops: (R+1)·W × the liberty's smallest flop (µm², a lower bound).
    pub shadow_flops_only_um2: Option<f64>,
    /// The pixel's cell area without the shadow (µm²).
    pub pixel_um2: f64,
    /// With it.
    pub pixel_with_um2: f64,
    /// The array's total (pixels, ROM macro, shared logic) without the shadows (µm²).
    pub array_total_um2: f64,
    /// With a shadow in every pixel.
    pub array_total_with_um2: f64,
}

/// The double buffer's cost.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DoubleBuffer {
    /// Whether `[array] double_buffer` is on (the frame period is then max(N·C + 1, D)).
    pub enabled: bool,
    /// Shadow bits per pixel: (R+1)·W (the registers and the status word).
    pub shadow_bits_per_pixel: u64,
    /// Per library.
    pub areas: Vec<DoubleBufferArea>,
    /// How the area is obtained.
    pub basis: String,
}

/// The double buffer of an array of `pixels` pixels of `registers` × `width` bits (the
/// shadow holds them and the status word), from each library's synthesised pixel (`libs`)
/// and the array's totals there.
pub fn double_buffer(
    enabled: bool,
    registers: u64,
    width: u32,
    pixels: u64,
    libs: &[&AreaSection],
    totals: &[ArrayTotal],
) -> DoubleBuffer {
    let bits = (registers + 1) * u64::from(width);
    let areas = libs
        .iter()
        .map(|a| {
            let rf = a.split.register_file;
            // A clock-gated file has no write mux per flop: its area per flop is still the
            // file's own (flops, gates), which a shadow's load would need as well.
            let per_flop = if rf.flops > 0 {
                rf.area_um2 / rf.flops as f64
            } else {
                a.smallest_flop.as_ref().map_or(0.0, |f| f.1)
            };
            let shadow = per_flop * bits as f64;
            let total = totals
                .iter()
                .find(|t| t.library == a.library)
                .map_or(a.total_area_um2 * pixels as f64, |t| t.total_um2);
            DoubleBufferArea {
                library: a.library.clone(),
                register_file_um2: rf.area_um2,
                register_file_flops: rf.flops,
                shadow_um2: shadow,
                shadow_flops_only_um2: a.smallest_flop.as_ref().map(|f| f.1 * bits as f64),
                pixel_um2: a.total_area_um2,
                pixel_with_um2: a.total_area_um2 + shadow,
                array_total_um2: total,
                array_total_with_um2: total + shadow * pixels as f64,
            }
        })
        .collect();
    DoubleBuffer {
        enabled,
        shadow_bits_per_pixel: bits,
        areas,
        basis: "estimate (not a synthesis of the rendered shadow): (R+1)·W shadow flops — the \
                registers and the status word, as templates/pixel.v renders them with \
                double_buffer — at the synthesised register file's area per flop (flop + \
                private write enable, as the shadow's load enable), from the pixel's \
                register-file split on the same liberty; the readout select moves to the \
                shadow and the swap's clear reuses the registers' write path (neither added)"
            .into(),
    }
}

/// The superpixel's front end and the pixel per SPAD on one library.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SpadArea {
    /// Library name.
    pub library: String,
    /// The front end synthesised (µm²).
    pub front_end_um2: f64,
    /// Its cells.
    pub front_end_cells: u64,
    /// The pixel's cell area (µm²).
    pub pixel_um2: f64,
    /// (pixel + front end) / G² (µm²).
    pub per_spad_um2: f64,
    /// The plain pixel (one SPAD per pixel): the pixel alone (µm²).
    pub plain_per_spad_um2: f64,
}

/// The superpixel's memory and area per SPAD beside the plain pixel's.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SuperpixelSize {
    /// G.
    pub side: u32,
    /// G².
    pub spads_per_pixel: u32,
    /// A SPAD's pitch as written (µm).
    pub spad_pitch_um: f64,
    /// k: the shift after the multiply.
    pub shift: u32,
    /// Table words (G²) and their bits (k + 1).
    pub table_words: u32,
    pub table_bits: u32,
    /// The register file of one pixel: R·W bits.
    pub register_bits_per_pixel: u64,
    /// R·W / G².
    pub bits_per_spad: f64,
    /// The plain pixel's: R·W.
    pub plain_bits_per_spad: u64,
    /// Per library.
    pub area: Vec<SpadArea>,
}

/// The superpixel `sp` of the pixel `p` on each library of `libs` (the front end
/// synthesised with the project's synthesis, cached under `cache`).
pub fn superpixel(
    p: &PixelParams,
    sp: &Superpixel,
    spad_pitch_um: f64,
    libs: &[&AreaSection],
    cache: &Path,
) -> Result<SuperpixelSize> {
    let g2 = sp.spads() as u32;
    let bits = p.registers() as u64 * u64::from(p.width);
    let area = libs
        .iter()
        .map(|a| {
            let (um2, cells) = front_end_logic(p, sp, &a.liberty, cache)?;
            Ok(SpadArea {
                library: a.library.clone(),
                front_end_um2: um2,
                front_end_cells: cells,
                pixel_um2: a.total_area_um2,
                per_spad_um2: (a.total_area_um2 + um2) / f64::from(g2),
                plain_per_spad_um2: a.total_area_um2,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(SuperpixelSize {
        side: sp.side(),
        spads_per_pixel: g2,
        spad_pitch_um,
        shift: sp.shift(),
        table_words: g2,
        table_bits: sp.table_bits(),
        register_bits_per_pixel: bits,
        bits_per_spad: bits as f64 / f64::from(g2),
        plain_bits_per_spad: bits,
        area,
    })
}

/// The front end rendered and synthesised on `liberty`: (area µm², cells).
pub fn front_end_logic(
    p: &PixelParams,
    sp: &Superpixel,
    liberty: &Path,
    cache: &Path,
) -> Result<(f64, u64)> {
    let o = tofprobe_rtlgen::RenderOptions::default();
    let f = tofprobe_rtlgen::superpixel::render_superpixel(p, sp, &o)?;
    let dir = cache.join("superpixel").join(format!(
        "{:016x}",
        tofprobe_io::fnv1a64(f.contents.as_bytes())
    ));
    std::fs::create_dir_all(&dir).map_err(|e| EdaError::io("creating", &dir, e))?;
    let path = dir.join(&f.name);
    write_atomic(&path, f.contents.as_bytes())?;
    let spec = SynthSpec {
        sources: vec![path],
        top: tofprobe_rtlgen::superpixel::module_name(&o.module_prefix),
        params: vec![],
        liberty: liberty.to_path_buf(),
        delay_target_ps: None,
        keep: vec![],
    };
    let s = synthesise(&spec, &cache.join("synth"))?;
    Ok((s.total_area_um2, s.cell_count))
}

/// The libraries the size report synthesised the pixel on.
pub fn libraries(size: &SizeReport) -> Vec<&AreaSection> {
    let mut v = vec![&size.area];
    if let Some(s) = &size.sky130 {
        v.push(&s.area);
    }
    v
}
