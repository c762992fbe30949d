//! The array section of `tofprobe size` on an `[array]` configuration (issue 27 point 4):
//! the pixel's size report (its area per library) composed with the chip's shared part and
//! its readout ([`crate::array_size`] holds the arithmetic).

use std::path::Path;

use serde::{Deserialize, Serialize};
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose, RtlOverrides};
use tofprobe_eda::size_report::SizeReport;
use tofprobe_eda::synth::{SynthSpec, synthesise};
use tofprobe_pixel::Mode;

use crate::array_options::{DoubleBuffer, SuperpixelSize, double_buffer, libraries, superpixel};
use crate::array_size::{
    ArrayTotal, DEFAULT_UTILISATION, PixelPitch, ReadoutFigures, RomLogic, RomMacroEstimate,
    TimestampComparison, rom_macro_estimates,
};
use crate::array_timing::{ArrayTiming, CornerOptionPaths, array_timing, corner_option_paths};
use crate::error::FlowError;

/// Entries of the probe ROM synthesised as logic (then scaled to the whole ROM).
pub const ROM_LOGIC_DEPTH: usize = 1024;

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
    /// whole array up to 8 × 8, a row and a column slice beyond: [`crate::array_timing`]).
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

/// Node (nm) of a library the report knows by name (sky130: 130, osu018: 180).
pub fn library_node_nm(library: &str) -> Option<f64> {
    let l = library.to_ascii_lowercase();
    if l.contains("sky130") {
        Some(130.0)
    } else if l.contains("osu018") {
        Some(180.0)
    } else {
        None
    }
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
    let readout = chip
        .readout
        .as_ref()
        .expect("Chip::array_of resolves the readout");
    let pixels = chip.pixels() as u64;

    // The pixel on every library the size report synthesised it on.
    let mut areas = vec![(size.area.library.clone(), size.area.total_area_um2)];
    if let Some(s) = &size.sky130 {
        areas.push((s.area.library.clone(), s.area.total_area_um2));
    }
    let pitch: Vec<PixelPitch> = areas
        .iter()
        .filter_map(|(lib, a)| {
            library_node_nm(lib).map(|n| PixelPitch::of(lib, n, *a, utilisation, node_nm))
        })
        .collect();
    let pitch_fits = pitch
        .iter()
        .map(|p| p.pitch_um)
        .fold(f64::INFINITY, f64::min)
        <= array.pitch_um;

    let rom = if chip.pixel.mode == Mode::Fourier {
        let depth = chip.pixel.rom_depth;
        let width_bits = chip.pixel.registers();
        let bits = depth as u64 * width_bits as u64;
        let mut logic = Vec::new();
        let mut libs = vec![size.area.liberty.clone()];
        if let Some(s) = &size.sky130 {
            libs.push(s.area.liberty.clone());
        }
        for lib in libs {
            logic.push(rom_logic(&chip, &lib, cache)?);
        }
        Some(RomSize {
            depth,
            width_bits,
            bits,
            macro_estimates: rom_macro_estimates(bits, node_nm),
            logic,
        })
    } else {
        None
    };

    // The array's paths: the timing liberty, then every sky130 corner (mapped on tt).
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
    let timing = array_timing(design, &libs, cache)?;
    let timing_meets_margin = timing
        .iter()
        .all(|t| t.broadcast.meets_margin && t.readout.meets_margin);
    let at_corner_options = corner_option_paths(&timing, &size.corner_options);
    // The array's own logic per mapped library: the slices' sum stands for the whole
    // array only when it was timed whole; else scaled (a row's logic × R, stated).
    let shared = |lib: &str| -> Option<f64> {
        let on: Vec<&ArrayTiming> = timing.iter().filter(|t| t.library == lib).collect();
        match on.as_slice() {
            [whole] => Some(whole.shared_logic_um2),
            [row, column] => {
                Some(row.shared_logic_um2 * chip.rows as f64 + column.shared_logic_um2)
            }
            _ => None,
        }
    };
    let totals: Vec<ArrayTotal> = areas
        .iter()
        .map(|(lib, a)| {
            let tech = library_node_nm(lib);
            let rom_um2 = rom
                .as_ref()
                .and_then(|r| {
                    r.macro_estimates
                        .iter()
                        .find(|e| Some(e.node_nm) == tech)
                        .map(|e| e.area_um2)
                })
                .unwrap_or(0.0);
            ArrayTotal::of(lib, pixels, *a, rom_um2, shared(lib))
        })
        .collect();

    let libs = libraries(size);
    let double_buffer = double_buffer(
        readout.double_buffer,
        chip.pixel.registers() as u64,
        chip.pixel.width,
        pixels,
        &libs,
        &totals,
    );
    let superpixel = match array.front_end(chip.pixel.tdc_bits)? {
        Some(sp) => Some(superpixel(
            &chip.pixel,
            &sp,
            array.spad_pitch_um(),
            &libs,
            cache,
        )?),
        None => None,
    };
    let figures = ReadoutFigures::of(readout);
    let s = design.sensor();
    let timestamps = TimestampComparison::of(pixels, s.tdc_bits(), s.laser_rate_hz, &figures);
    let assumptions = vec![
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
             the pixel clock, ideal clock, no wire load; arrays above {} pixels are timed as a \
             row (1 × C: a row stage's fan-out to C pixels, the column select over C) and a \
             column (R × 1: the root's fan-out to R row stages, a column bus over R rows); the \
             array's own logic is then the row's × R plus the column's (an upper bound: the \
             root is counted R times)",
            crate::array_timing::WHOLE_TIMING_MAX_PIXELS
        ),
        "timestamps: one T-bit timestamp per laser pulse per pixel (every pulse detected: the \
         paper's 17.5 MB per pixel per second at 10 MHz and 14 bits)"
            .into(),
    ];
    Ok(Some(ArraySizeReport {
        rows: chip.rows,
        cols: chip.cols,
        pixels,
        configured_pitch_um: array.pitch_um,
        pitch,
        pitch_fits,
        rom,
        totals,
        timing,
        timing_meets_margin,
        at_corner_options,
        readout: figures,
        timestamps,
        double_buffer,
        superpixel,
        assumptions,
    }))
}

/// The chip's probe ROM synthesised as logic on `liberty`: its first
/// min(L, [`ROM_LOGIC_DEPTH`]) entries, rendered by the generator, the area scaled by L/D.
pub fn rom_logic(chip: &Chip, liberty: &Path, cache: &Path) -> Result<RomLogic, FlowError> {
    let l = chip.pixel.rom_depth;
    let d = l.min(ROM_LOGIC_DEPTH);
    let mut p = chip.pixel.clone();
    p.rom_depth = d;
    let words = p.registers().div_ceil(64);
    let rom = &chip.rom.words[..d * words];
    let files = tofprobe_rtlgen::render(&p, rom, &tofprobe_rtlgen::RenderOptions::default())?;
    let dir = cache.join("rom-logic").join(format!(
        "{:016x}",
        tofprobe_io::fnv1a64(
            &files
                .iter()
                .flat_map(|f| f.contents.bytes())
                .collect::<Vec<u8>>()
        )
    ));
    std::fs::create_dir_all(&dir).map_err(|e| FlowError::output(dir.clone(), e.to_string()))?;
    let mut sources = Vec::new();
    let rom_name = tofprobe_rtlgen::module_names(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX).1;
    for f in files.iter().filter(|f| f.template == "probe_rom.v") {
        let path = dir.join(&f.name);
        tofprobe_io::write_atomic(&path, f.contents.as_bytes())
            .map_err(|e| FlowError::output(path.clone(), e.to_string()))?;
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
    let lib = tofprobe_eda::liberty::Liberty::load(liberty)?;
    Ok(RomLogic {
        library: lib.name,
        synthesised_depth: d,
        synthesised_area_um2: s.total_area_um2,
        synthesised_cells: s.cell_count,
        area_um2: s.total_area_um2 * l as f64 / d as f64,
    })
}

/// The array section as Markdown (appended to the size report's).
pub fn markdown(a: &ArraySizeReport) -> String {
    let mut m = format!(
        "\n## The array: {} × {} = {} pixels\n\n",
        a.rows, a.cols, a.pixels
    );
    m += "| library | pixel cell area (µm²) | utilisation | node (nm) | implied pitch (µm) |\n|---|---|---|---|---|\n";
    for p in &a.pitch {
        m += &format!(
            "| {} | {:.0} | {:.0} % | {} | {:.1} |\n",
            p.library,
            p.cell_area_um2,
            p.utilisation * 100.0,
            p.node_nm,
            p.pitch_um
        );
    }
    m += &format!(
        "\nConfigured pitch {} µm: {}.\n",
        a.configured_pitch_um,
        if a.pitch_fits {
            "the pixel fits it on at least one library"
        } else {
            "the pixel does not fit it on any library measured"
        }
    );
    if let Some(r) = &a.rom {
        m += &format!(
            "\n### The probe ROM (shared, broadcast)\n\n{} entries × {} bits = {} bits ({:.1} kB).\n\n\
             | technology | µm² per bit | ROM macro area (mm², estimate) | basis |\n|---|---|---|---|\n",
            r.depth,
            r.width_bits,
            r.bits,
            r.bits as f64 / 8000.0
        );
        for e in &r.macro_estimates {
            m += &format!(
                "| {} | {:.2} | {:.3} | {} |\n",
                e.technology,
                e.um2_per_bit,
                e.area_um2 / 1e6,
                e.basis
            );
        }
        m += "\n| library | entries synthesised | their area (µm²) | cells | whole ROM as logic (mm², scaled) |\n|---|---|---|---|---|\n";
        for l in &r.logic {
            m += &format!(
                "| {} | {} | {:.0} | {} | {:.3} |\n",
                l.library,
                l.synthesised_depth,
                l.synthesised_area_um2,
                l.synthesised_cells,
                l.area_um2 / 1e6
            );
        }
    }
    m += "\n### Array area\n\n| library | pixels (mm²) | ROM macro (mm², estimate) | shared logic (mm²) | total (mm²) | pixels' share |\n|---|---|---|---|---|---|\n";
    for t in &a.totals {
        m += &format!(
            "| {} | {:.3} | {:.3} | {} | {:.3} | {:.0} % |\n",
            t.library,
            t.pixels_um2 / 1e6,
            t.rom_macro_um2 / 1e6,
            t.shared_logic_um2
                .map_or("–".to_string(), |s| format!("{:.3}", s / 1e6)),
            t.total_um2 / 1e6,
            t.pixel_share * 100.0
        );
    }
    if !a.timing.is_empty() {
        m += &format!(
            "\n### Broadcast and readout timing (pixel clock {:.1} MHz, margin 10 %)\n\n\
             Each path's delay is the whole path (the array's part + the pixel's own part, the pixel \
             timed alone from those inputs or to those outputs).\n\n\
             | netlist | library | array logic (µm²) | broadcast delay (ns): array + pixel | slack | readout delay (ns): array + pixel | slack |\n|---|---|---|---|---|---|---|\n",
            a.timing[0].clock_mhz
        );
        for t in &a.timing {
            m += &format!(
                "| {} | {} | {:.0} | {:.3}: {:.3} + {:.3} | {:.3} ns ({:.1} %){} | {:.3}: {:.3} + {:.3} | {:.3} ns ({:.1} %){} |\n",
                t.netlist,
                t.library,
                t.shared_logic_um2,
                t.broadcast.delay_ns,
                t.broadcast.array_part_ns,
                t.broadcast.pixel_part_ns,
                t.broadcast.slack_ns,
                t.broadcast.slack_percent,
                if t.broadcast.meets_margin {
                    ""
                } else {
                    " **short**"
                },
                t.readout.delay_ns,
                t.readout.array_part_ns,
                t.readout.pixel_part_ns,
                t.readout.slack_ns,
                t.readout.slack_percent,
                if t.readout.meets_margin {
                    ""
                } else {
                    " **short**"
                },
            );
        }
        m += &format!(
            "\nBroadcast and readout {} the pixel clock with ≥ 10 % slack on every library and corner timed.\n",
            if a.timing_meets_margin {
                "meet"
            } else {
                "do NOT all meet"
            }
        );
        for o in &a.at_corner_options {
            m += &format!(
                "- {} on {}: with the option that meets this corner (A = {}, {:.1} MHz), broadcast slack {:.1} %, readout slack {:.1} %: {}.\n",
                o.netlist,
                o.library,
                o.adders,
                o.clock_mhz,
                o.broadcast_slack_percent,
                o.readout_slack_percent,
                if o.meets_margin {
                    "both meet with ≥ 10 %"
                } else {
                    "**short** of the 10 % margin"
                }
            );
        }
    }
    m += &crate::array_options::markdown(&a.double_buffer, a.superpixel.as_ref());
    let r = &a.readout;
    m += &format!(
        "\n### Readout\n\n\
         | figure | value |\n|---|---|\n\
         | port | {} bits per beat, one beat every {} cycle(s) at f_clk = {:.1} MHz: {:.3} Gbit/s |\n\
         | words per pixel | registers + status, {} beat(s) each |\n\
         | bits per frame | {} payload, {} on the port |\n\
         | readout | {} cycles = {:.3} ms |\n\
         | frame | {} cycles{}: {:.4} frames/s, pixels see {:.3} % of the pulses |\n\
         | mean output rate | {:.3} Mbit/s |\n",
        r.bits_per_beat,
        r.cycles_per_beat,
        r.clock_hz / 1e6,
        r.port_bits_per_s / 1e9,
        r.beats_per_word,
        r.payload_bits_per_frame,
        r.stream_bits_per_frame,
        r.readout_cycles,
        r.readout_seconds * 1e3,
        r.frame_cycles,
        if r.double_buffer {
            " (double-buffered: max(N·C + 1, D))"
        } else {
            " (N·C + D)"
        },
        r.frame_rate_hz,
        r.duty * 100.0,
        r.mean_bits_per_s / 1e6
    );
    let t = &a.timestamps;
    m += &format!(
        "\n### Against reading every timestamp out\n\n\
         One {}-bit timestamp per pulse at {:.1} MHz is {:.1} MB per pixel per second (the paper's \
         17.5 MB at 14 bits); the array's timestamps: {:.2} Gbit/s ({} the paper's 100 Gbit/s), \
         against {:.3} Mbit/s of registers: {:.0}× less.\n",
        t.timestamp_bits,
        t.laser_rate_hz / 1e6,
        t.bytes_per_pixel_per_s / 1e6,
        t.array_bits_per_s / 1e9,
        if t.exceeds_paper_line {
            "above"
        } else {
            "below"
        },
        t.readout_bits_per_s / 1e6,
        t.reduction
    );
    // The paper's per-pixel figure beside: one source of the numbers (`paper_memory`).
    if let Ok(figs) = tofprobe_eda::paper_memory::section8() {
        m += &format!("\n{}", tofprobe_eda::paper_memory::markdown(&figs));
    }
    m += "\nAssumptions:\n\n";
    for s in &a.assumptions {
        m += &format!("- {s}\n");
    }
    m
}
