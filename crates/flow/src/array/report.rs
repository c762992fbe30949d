//! The array section of `tofprobe size` on an `[array]` configuration (issue 27 point 4):
//! the flow builds the chip's plain description ([`eda_spec`]: the pixel, the ROM, the
//! netlists to time, the options), `tofprobe_eda::array::measure` measures it on the
//! libraries of the pixel's size report, and [`array_report`] composes that with the
//! readout's figures ([`crate::array::size`]); [`crate::array::markdown`] writes it.

use std::path::Path;

use serde::{Deserialize, Serialize};
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose, RtlOverrides};
use tofprobe_eda::array::area::{ArrayTotal, DEFAULT_UTILISATION, PixelPitch};
use tofprobe_eda::array::options::{DoubleBuffer, SuperpixelSize};
use tofprobe_eda::array::rom::RomSize;
use tofprobe_eda::array::timing::{
    ArrayTiming, CornerOptionPaths, WHOLE_TIMING_MAX_PIXELS, slices,
};
use tofprobe_eda::array::{ArrayEdaSpec, ArraySlice, measure};
use tofprobe_eda::size_report::SizeReport;

use crate::array::size::{ReadoutFigures, TimestampComparison};
use crate::error::FlowError;

/// The array section of the size report.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ArraySizeReport {
    /// Rows of pixels.
    pub rows: usize,
    /// Columns of pixels.
    pub cols: usize,
    /// R × C.
    pub pixels: u64,
    /// `[array] pitch_um` as configured (µm).
    pub configured_pitch_um: f64,
    /// The pitch the pixel's cell area implies, per library.
    pub pitch: Vec<PixelPitch>,
    /// Whether the configured pitch holds the pixel at the stated node on every library
    /// measured (the smallest implied pitch ≤ configured).
    pub pitch_fits: bool,
    /// The probe ROM (Fourier; none in Haar mode).
    pub rom: Option<RomSize>,
    /// Pixels + ROM macro + the array's own logic per library.
    pub totals: Vec<ArrayTotal>,
    /// The broadcast and readout paths at the pixel clock, per library and corner (the
    /// whole array up to 8 × 8, a row and a column slice beyond: `tofprobe_eda::array::timing`).
    pub timing: Vec<ArrayTiming>,
    /// Every broadcast and readout path meets the pixel clock with the 10 % margin.
    pub timing_meets_margin: bool,
    /// Where a corner misses the pixel clock and the size report found the adders that meet
    /// it (`SizeReport::corner_options`): the same paths at that option's slower clock.
    #[serde(default)]
    pub at_corner_options: Vec<CornerOptionPaths>,
    /// The readout (contract: docs/pixel-contract.md, "Array").
    pub readout: ReadoutFigures,
    /// Reading every timestamp out instead.
    pub timestamps: TimestampComparison,
    /// The double buffer's shadow registers: their bits and area per pixel and in the array
    /// (an estimate from the register-file split; reported whether or not it is on).
    pub double_buffer: DoubleBuffer,
    /// `[array] superpixel = G > 1`: the averaging front end synthesised, memory and area
    /// per SPAD beside the plain pixel's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub superpixel: Option<SuperpixelSize>,
    /// The assumptions behind the figures.
    pub assumptions: Vec<String>,
}

/// Lowest placement utilisation `--utilisation` takes.
pub const MIN_UTILISATION: f64 = 0.05;

/// Checks what `tofprobe size` asks of an array before any synthesis: the utilisation
/// (0 < u ≤ 1; `None`: [`DEFAULT_UTILISATION`]) and the array's readout (the chip resolves
/// it: a frame rate the readout cannot reach is refused here, naming the bandwidth).
pub fn check(design: &ResolvedDesign, utilisation: Option<f64>) -> Result<f64, FlowError> {
    if let (Some(u), None) = (utilisation, &design.array) {
        return Err(FlowError::option(
            "utilisation",
            tofprobe_io::text::number(u),
            "an [array] configuration only (it turns the pixel's cell area into the array's \
             pitch; a single pixel has none)",
        ));
    }
    let u = utilisation.unwrap_or(DEFAULT_UTILISATION);
    // Below 5 % a pitch is mostly empty rows (1e-300 once printed a 152-digit pitch).
    if !(u.is_finite() && (MIN_UTILISATION..=1.0).contains(&u)) {
        return Err(FlowError::option(
            "utilisation",
            tofprobe_io::text::number(u),
            "0.05 ≤ utilisation ≤ 1 (0.7 is the usual placement density)",
        ));
    }
    if design.array.is_some() {
        Chip::array_of(design, &RtlOverrides::default(), RomPurpose::Rendered)?;
    }
    Ok(u)
}

/// The array section for `design` (None without `[array]`), on the libraries of `size`;
/// `node_nm` the node the pitch is stated at; `cache` the synthesis cache.
pub fn array_report(
    design: &ResolvedDesign,
    size: &SizeReport,
    node_nm: f64,
    utilisation: Option<f64>,
    cache: &Path,
) -> Result<Option<ArraySizeReport>, FlowError> {
    let Some(array) = &design.array else {
        return Ok(None);
    };
    let utilisation = check(design, utilisation)?;
    let chip = Chip::array_of(design, &RtlOverrides::default(), RomPurpose::Rendered)?;
    let spec = eda_spec(design, &chip, node_nm, utilisation, WHOLE_TIMING_MAX_PIXELS)?;
    let readout = chip
        .readout
        .as_ref()
        .expect("Chip::array_of resolves the readout");
    let pixels = chip.pixels() as u64;
    let m = measure(&spec, size, cache)?;
    let pitch_fits = m
        .pitch
        .iter()
        .map(|p| p.pitch_um)
        .fold(f64::INFINITY, f64::min)
        <= array.pitch_um;
    let figures = ReadoutFigures::of(readout);
    let s = design.sensor();
    let timestamps = TimestampComparison::of(pixels, s.tdc_bits(), s.laser_rate_hz, &figures);
    Ok(Some(ArraySizeReport {
        rows: chip.rows,
        cols: chip.cols,
        pixels,
        configured_pitch_um: array.pitch_um,
        pitch: m.pitch,
        pitch_fits,
        rom: m.rom,
        totals: m.totals,
        timing: m.timing,
        timing_meets_margin: m.timing_meets_margin,
        at_corner_options: m.at_corner_options,
        readout: figures,
        timestamps,
        double_buffer: m.double_buffer,
        superpixel: m.superpixel,
        assumptions: assumptions(utilisation, node_nm),
    }))
}

/// The plain description of the array chip `chip` of `design` (its rendered chip,
/// `Chip::array_of`) that `tofprobe_eda::array` measures: the chip's pixel and ROM, its clock, the netlists to time (the
/// whole array up to `whole_max` pixels, a row and a column beyond, each with the readout
/// its shape resolves to), the double buffer and the superpixel.
pub fn eda_spec(
    design: &ResolvedDesign,
    chip: &Chip,
    node_nm: f64,
    utilisation: f64,
    whole_max: usize,
) -> Result<ArrayEdaSpec, FlowError> {
    let array = design
        .array
        .as_ref()
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    let laser = design.sensor().laser_rate_hz;
    let p = &chip.pixel;
    let slices = slices(chip.rows, chip.cols, whole_max)
        .into_iter()
        .map(|(name, rows, cols)| {
            let r = tofprobe_design::Readout::new(&array.readout, rows, cols, p, laser)
                .map_err(|m| FlowError::option("array slice", format!("{rows} × {cols}"), &m))?;
            Ok(ArraySlice {
                name,
                array: tofprobe_rtlgen::ArraySpec {
                    rows,
                    cols,
                    bits: r.bits,
                    beats_per_word: r.beats_per_word,
                    beat_cycles: r.beat_cycles,
                    slot_cycles: r.slot_cycles(),
                    fault: None,
                    tile: None,
                    superpixel: 1,
                    double_buffer: false,
                },
            })
        })
        .collect::<Result<Vec<_>, FlowError>>()?;
    let superpixel = array
        .front_end(p.tdc_bits)?
        .map(|sp| (sp, array.spad_pitch_um()));
    let double_buffer = chip.readout.as_ref().is_some_and(|r| r.double_buffer);
    Ok(ArrayEdaSpec {
        clock_mhz: p.cycles_per_pulse as f64 * laser / 1e6,
        pixel: chip.pixel.clone(),
        rom: chip.rom.words.clone(),
        rows: chip.rows,
        cols: chip.cols,
        slices,
        double_buffer,
        superpixel,
        node_nm,
        utilisation,
    })
}

/// The assumptions behind the array section's figures.
fn assumptions(utilisation: f64, node_nm: f64) -> Vec<String> {
    vec![
        format!(
            "pitch: the pixel's cell area at {:.0} % placement utilisation, scaled to {node_nm} nm \
             by (node / library node)² — routing and power grid beyond that utilisation are not \
             counted (a routed macro's area: `tofprobe layout`)",
            utilisation * 100.0
        ),
        "ROM macro: an estimate from the OpenRAM sky130 SRAM macro's density (an upper bound for \
         a mask ROM), scaled by node²; the ROM as logic: a 1024-entry prefix of the real ROM \
         synthesised and scaled by L/1024"
            .into(),
        format!(
            "broadcast and readout timing: OpenSTA on the array's top (pixels and ROM as black \
             boxes, mapped by the delay-driven ABC script) linked with the gate-level pixel, at \
             the pixel clock, ideal clock, no wire load; arrays above {WHOLE_TIMING_MAX_PIXELS} \
             pixels are timed as a row (1 × C: a row stage's fan-out to C pixels, the column \
             select over C) and a column (R × 1: the root's fan-out to R row stages, a column bus \
             over R rows); the array's own logic is then the row's × R plus the column's (an \
             upper bound: the root is counted R times)"
        ),
        "timestamps: one T-bit timestamp per laser pulse per pixel (every pulse detected: the \
         paper's 17.5 MB per pixel per second at 10 MHz and 14 bits)"
            .into(),
    ]
}
