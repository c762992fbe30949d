//! Every EDA measurement of an array chip in one call ([`measure`]): the pixel's pitch on
//! each library the size report synthesised it on, the probe ROM (macro estimates and
//! logic), the broadcast and readout paths on the timing liberty and every sky130 corner,
//! the array's totals, the double buffer and the superpixel.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tofprobe_pixel::Mode;

use crate::array::area::{ArrayTotal, PixelPitch, library_node_nm};
use crate::array::options::{DoubleBuffer, SuperpixelSize, double_buffer, libraries, superpixel};
use crate::array::rom::{RomSize, rom_logic, rom_macro_estimates};
use crate::array::spec::ArrayEdaSpec;
use crate::array::timing::{ArrayTiming, CornerOptionPaths, array_timing, corner_option_paths};
use crate::error::Result;
use crate::size_report::SizeReport;

/// What [`measure`] found.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ArrayMeasurements {
    /// The pitch the pixel's cell area implies, per library.
    pub pitch: Vec<PixelPitch>,
    /// The probe ROM (Fourier; none in Haar mode).
    pub rom: Option<RomSize>,
    /// Pixels + ROM macro + the array's own logic per library.
    pub totals: Vec<ArrayTotal>,
    /// The broadcast and readout paths, per library and corner and netlist.
    pub timing: Vec<ArrayTiming>,
    /// Every broadcast and readout path meets the pixel clock with the 10 % margin.
    pub timing_meets_margin: bool,
    /// The same paths at the clock of each corner option of the size report.
    pub at_corner_options: Vec<CornerOptionPaths>,
    /// The double buffer's shadow registers.
    pub double_buffer: DoubleBuffer,
    /// The superpixel's front end (`spec.superpixel`).
    pub superpixel: Option<SuperpixelSize>,
}

/// Measures the array of `spec` on the libraries of `size` (the pixel's size report),
/// synthesising under `cache`.
pub fn measure(spec: &ArrayEdaSpec, size: &SizeReport, cache: &Path) -> Result<ArrayMeasurements> {
    let pixels = (spec.rows * spec.cols) as u64;
    let libs = libraries(size);
    let pitch: Vec<PixelPitch> = libs
        .iter()
        .filter_map(|a| {
            library_node_nm(&a.library).map(|n| {
                PixelPitch::of(
                    &a.library,
                    n,
                    a.total_area_um2,
                    spec.utilisation,
                    spec.node_nm,
                )
            })
        })
        .collect();
    let rom = rom_size(spec, size, cache)?;
    let timing = array_timing(spec, &timing_liberties(size), cache)?;
    let timing_meets_margin = timing
        .iter()
        .all(|t| t.broadcast.meets_margin && t.readout.meets_margin);
    let at_corner_options = corner_option_paths(&timing, &size.corner_options);
    let totals: Vec<ArrayTotal> = libs
        .iter()
        .map(|a| {
            let tech = library_node_nm(&a.library);
            let rom_um2 = rom
                .as_ref()
                .and_then(|r| {
                    r.macro_estimates
                        .iter()
                        .find(|e| Some(e.node_nm) == tech)
                        .map(|e| e.area_um2)
                })
                .unwrap_or(0.0);
            let shared = shared_logic(&timing, &a.library, spec.rows);
            ArrayTotal::of(&a.library, pixels, a.total_area_um2, rom_um2, shared)
        })
        .collect();
    let p = &spec.pixel;
    let double_buffer = double_buffer(
        spec.double_buffer,
        p.registers() as u64,
        p.width,
        pixels,
        &libs,
        &totals,
    );
    let superpixel = match &spec.superpixel {
        Some((sp, pitch_um)) => Some(superpixel(p, sp, *pitch_um, &libs, cache)?),
        None => None,
    };
    Ok(ArrayMeasurements {
        pitch,
        rom,
        totals,
        timing,
        timing_meets_margin,
        at_corner_options,
        double_buffer,
        superpixel,
    })
}

/// The probe ROM as a memory (Fourier mode; none in Haar mode): its macro estimates and
/// its logic on every library of `size`.
fn rom_size(spec: &ArrayEdaSpec, size: &SizeReport, cache: &Path) -> Result<Option<RomSize>> {
    let p = &spec.pixel;
    if p.mode != Mode::Fourier {
        return Ok(None);
    }
    let bits = p.rom_depth as u64 * p.registers() as u64;
    let logic = libraries(size)
        .iter()
        .map(|a| rom_logic(p, &spec.rom, &a.liberty, cache))
        .collect::<Result<Vec<_>>>()?;
    Ok(Some(RomSize {
        depth: p.rom_depth,
        width_bits: p.registers(),
        bits,
        macro_estimates: rom_macro_estimates(bits, spec.node_nm),
        logic,
    }))
}

/// The liberties the array's paths are timed on: the timing liberty, then every sky130
/// corner (mapped on the sky130 liberty of the size report, timed on the corner's).
fn timing_liberties(size: &SizeReport) -> Vec<(PathBuf, Option<PathBuf>)> {
    let mut libs = vec![(size.area.liberty.clone(), None)];
    if let Some(s) = &size.sky130
        && s.has_timing
    {
        for c in size
            .timing_corners
            .iter()
            .filter(|c| c.library.starts_with("sky130"))
        {
            libs.push((s.area.liberty.clone(), Some(c.liberty.clone())));
        }
    }
    libs
}

/// The array's own logic on the mapped library `lib`: the slices' sum stands for the whole
/// array only when it was timed whole; else scaled (a row's logic × R, stated).
fn shared_logic(timing: &[ArrayTiming], lib: &str, rows: usize) -> Option<f64> {
    let on: Vec<&ArrayTiming> = timing.iter().filter(|t| t.library == lib).collect();
    match on.as_slice() {
        [whole] => Some(whole.shared_logic_um2),
        [row, column] => Some(row.shared_logic_um2 * rows as f64 + column.shared_logic_um2),
        _ => None,
    }
}
