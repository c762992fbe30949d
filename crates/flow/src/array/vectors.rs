//! The array's golden vectors: the array model (`tofprobe_array::rtl_model`, driven by `tofprobe_array::rtl_driver`) run on the array
//! scene's detections (or given ones), its run handed as plain data
//! ([`tofprobe_rtlgen::array_vectors::ArrayTrace`]) to the one writer of the files,
//! `tofprobe_rtlgen::array_vectors` (as the pixel's are written by `tofprobe_rtlgen::vectors`):
//! what `tofprobe vectors` writes and `tofprobe rtl` puts in an array set's kit.

use std::path::Path;

use tofprobe_array::rtl_driver::{ArrayRun, mid_frame_reset, run_with_reset};
use tofprobe_array::rtl_model::ArrayModel;
use tofprobe_design::readout::Readout;
use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose};
use tofprobe_rtlgen::array::ArrayTile;
use tofprobe_rtlgen::array_vectors::{ArrayPorts, ArrayTrace, exercise, vector_files};
use tofprobe_rtlgen::render::HEADER_MARK;
use tofprobe_rtlgen::write::write_generated;

use crate::array::chip;
use crate::error::FlowError;

/// Every input's detections for `frames` frames of the design's scene, `frame_pulses` per
/// frame: row-major over the pixels of `tile` (all when `None`), pixel (r, c)'s own stream
/// (`ResolvedDesign::pixel_source`); with `[array] superpixel = G > 1`, row-major over the
/// tile's SPAD grid, SPAD (r, c)'s own stream (`ResolvedDesign::spad_source`).
pub fn scene_detections(
    design: &ResolvedDesign,
    frame_pulses: u64,
    frames: u64,
    tile: Option<ArrayTile>,
) -> Result<Vec<Vec<Option<u32>>>, FlowError> {
    let a = design
        .array
        .as_ref()
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    let n = (frame_pulses * frames) as usize;
    let t = tile.unwrap_or(ArrayTile::whole(a.rows, a.cols));
    // The SPAD grid of the tile (G = 1: its pixels); SPAD (r, c)'s own stream.
    let g = a.superpixel;
    let mut out = Vec::with_capacity(t.pixels() * g * g);
    for r in t.row0 * g..(t.row0 + t.rows) * g {
        for c in t.col0 * g..(t.col0 + t.cols) * g {
            let mut v = vec![None; n];
            design.spad_source(r, c)?.fill(0, &mut v);
            out.push(v);
        }
    }
    Ok(out)
}

/// The array's golden vectors written (`tofprobe vectors` on an array design): the chip
/// for the overrides (the simulating commands' ROM), the array model run on `detections`
/// (`None`: the array scene's), the files of `tofprobe_rtlgen::array_vectors` in `vec_dir`.
#[derive(Debug)]
pub struct ArrayVectors {
    pub chip: Chip,
    pub readout: Readout,
    pub run: ArrayRun,
    pub detections: Vec<Vec<Option<u32>>>,
    pub model_seconds: f64,
}

/// Runs the array model of `design` and writes its vectors into `vec_dir`.
pub fn write_array_vectors(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    frames: u64,
    detections: Option<Vec<Vec<Option<u32>>>>,
    tile: Option<ArrayTile>,
    vec_dir: &Path,
    command: &str,
) -> Result<ArrayVectors, FlowError> {
    let stimulus = ArrayStimulus {
        frames,
        detections,
        tile,
        lead_misses: 0,
        exercise: false,
        mid_frame_reset: false,
        purpose: RomPurpose::Replayed,
    };
    write_vectors(design, o, stimulus, vec_dir, command)
}

/// What the array's golden vectors replay: frames, detections (`None`: the scene's), the
/// tile present, the lead misses and the ROM the chip carries.
pub(crate) struct ArrayStimulus {
    pub(crate) frames: u64,
    pub(crate) detections: Option<Vec<Vec<Option<u32>>>>,
    pub(crate) tile: Option<ArrayTile>,
    pub(crate) lead_misses: u64,
    /// Thin the scene's detections (`tofprobe_rtlgen::array_vectors::exercise`).
    pub(crate) exercise: bool,
    /// One cycle of `rst` in the middle of the first frame (`rtl::mid_frame_reset`).
    pub(crate) mid_frame_reset: bool,
    pub(crate) purpose: RomPurpose,
}

/// Runs the array model of the chip of `design` for `o` and writes its vectors into
/// `vec_dir`.
pub(crate) fn write_vectors(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    stimulus: ArrayStimulus,
    vec_dir: &Path,
    command: &str,
) -> Result<ArrayVectors, FlowError> {
    if stimulus.frames == 0 || stimulus.frames > 100 {
        return Err(FlowError::option("frames", stimulus.frames, "1..=100"));
    }
    let chip = chip(design, o, stimulus.purpose)?;
    let (v, files) = array_vector_files(design, chip, stimulus, command)?;
    write_generated(vec_dir, &files)?;
    Ok(v)
}

/// The array model of `chip` run on the stimulus, and the vector files
/// (`tofprobe_rtlgen::array_vectors::vector_files`, headers naming `command`): what
/// `tofprobe vectors` writes into its directory and `tofprobe rtl` into an array set's
/// verification kit.
pub(crate) fn array_vector_files(
    design: &ResolvedDesign,
    chip: Chip,
    stimulus: ArrayStimulus,
    command: &str,
) -> Result<(ArrayVectors, Vec<(String, String)>), FlowError> {
    let ArrayStimulus {
        frames,
        detections,
        tile,
        lead_misses: v_lead,
        exercise: thin,
        mid_frame_reset: reset,
        purpose: _,
    } = stimulus;
    let ro = chip
        .readout
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    let p = &chip.pixel;
    let mut detections = match detections {
        Some(d) => d,
        None => {
            // The pulses before a mid-frame reset take the first detections: one frame more.
            let drawn = frames + u64::from(reset);
            let mut d = scene_detections(design, p.frame_pulses, drawn, tile)?;
            if thin {
                let cols = tile.map_or(ro.cols, |t| t.cols);
                exercise(&mut d, cols, chip.superpixel);
            }
            d
        }
    };
    for d in &mut detections {
        d.iter_mut()
            .take(usize::try_from(v_lead).unwrap_or(usize::MAX))
            .for_each(|x| *x = None);
    }
    let t0 = std::time::Instant::now();
    let mut model = ArrayModel::tile(&ro, p, &chip.rom.words, None, tile)?
        .with_superpixel(chip.superpixel, p)?;
    let reset_at = reset.then(|| mid_frame_reset(&ro));
    let r = run_with_reset(&mut model, &detections, frames, reset_at)?;
    let model_seconds = t0.elapsed().as_secs_f64();
    let top = tofprobe_rtlgen::array::array_module_name(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX);
    let header = format!(
        "{HEADER_MARK} {} (array vectors): {} x {} {:?} pixels, N = {}, {} frame(s); `{}`. DO NOT EDIT.",
        env!("CARGO_PKG_VERSION"),
        ro.rows,
        ro.cols,
        p.mode,
        p.frame_pulses,
        frames,
        tofprobe_io::text::sanitize(command)
    );
    let files = vector_files(&trace(&r), &detections, p.tdc_bits, &top, &header);
    Ok((
        ArrayVectors {
            chip,
            readout: ro,
            run: r,
            detections,
            model_seconds,
        },
        files,
    ))
}

/// The model's run as the plain data the vector files hold.
pub fn trace(run: &ArrayRun) -> ArrayTrace<'_> {
    ArrayTrace {
        bits: run.readout.bits,
        superpixel: run.superpixel,
        ports: run
            .pins
            .iter()
            .map(|p| ArrayPorts {
                pulse_o: p.pulse_o,
                ready: p.ready,
                ro_valid: p.ro_valid,
                ro_data: p.ro_data,
            })
            .collect(),
        pulses: run.pulse_cycles.len(),
        pixels: run
            .positions
            .iter()
            .map(|&q| run.readout.order(q))
            .collect(),
        words: &run.words,
        reset_at: run.reset_at,
    }
}
