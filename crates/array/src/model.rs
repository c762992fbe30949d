//! The array model: the one pixel datapath run on every pixel. Pixel (r, c) reads its own
//! photon stream (`ResolvedDesign::pixel_source`: its rates, the scene at its centre, the
//! seed of (seed, r, c)) through the pixel's `FrameDriver` (the folded driver of a
//! periodic ROM, or the transaction driver), streamed in chunks, with the
//! chip's one probe ROM broadcast to all (Fourier) or the Haar signs of its counter. Where
//! the fold pays, the pixels run in groups of `LANES` through the pixel's lane driver
//! (`FoldLanes`: each pixel's folded driver, in lockstep; [`run_group`]), with the same
//! registers as one pixel at a time ([`run_pixel`]). A tile is a rectangle of pixels run
//! in parallel on the current rayon pool; tiles merge into the array byte for byte
//! whatever the tiling, the threads or the process. A superpixel (`[array] superpixel = G`)
//! reads its G² SPADs' streams and hands the driver their average, one code a pulse
//! ([`PixelStream`], `pixel::Superpixel`): the datapath is the one pixel's either way.
//! The `[array] level` picks the tile's run ([`run_tile_watched`]): bit-true here, the
//! drawn levels in `statistical`, and `"auto"` both — the pixels `statistical::auto`
//! calls moving through the same bit-true runner (`run_pixels`, any subset of pixels in
//! any grouping gives each its own registers), the others drawn.

use std::ops::Range;

use rayon::prelude::*;
use tofprobe_design::array::AUTO_THRESHOLD;
use tofprobe_design::{ArrayLevel, ResolvedDesign};
use tofprobe_dsp::rom::RomImage;
use tofprobe_io::watch::Watch;
use tofprobe_pixel::{FoldLanes, FrameDriver, LANES, Superpixel, fold_pays};
use tofprobe_scene::PhotonSource;

use crate::error::ArrayError;
pub use crate::frame::{ArrayFrame, Tile};
use crate::statistical::shared_model;

/// Pulses per streamed chunk of one pixel (64 k pulses: 256 kB of codes per thread).
const CHUNK: usize = 1 << 16;

/// Pulses per streamed chunk of a lane group (16 k pulses: 64 kB of codes per pixel, 512
/// kB per group of eight).
const LANE_CHUNK: usize = 1 << 14;

/// The pulses pixel (r, c) sees: its one SPAD's codes, or (G > 1) its G² SPADs' codes
/// averaged by the superpixel front end.
#[derive(Debug)]
pub struct PixelStream {
    sources: Vec<PhotonSource>,
    front: Option<Superpixel>,
    /// One chunk of each SPAD's codes (G > 1).
    scratch: Vec<Vec<u32>>,
}

impl PixelStream {
    /// The stream of pixel (r, c), in chunks of at most `chunk` pulses.
    pub fn new(
        design: &ResolvedDesign,
        r: usize,
        c: usize,
        chunk: usize,
    ) -> Result<Self, ArrayError> {
        let sources = design.pixel_sources(r, c)?;
        let front = match &design.array {
            Some(a) => a
                .front_end(design.pixel.tdc_bits)
                .map_err(|source| ArrayError::Pixel {
                    row: r,
                    col: c,
                    source,
                })?,
            None => None,
        };
        let scratch = match front {
            Some(_) => vec![vec![0u32; chunk]; sources.len()],
            None => Vec::new(),
        };
        Ok(PixelStream {
            sources,
            front,
            scratch,
        })
    }

    /// The pixel's codes of pulses `first ..` into `out` (at most the chunk); returns its
    /// pulses with a detection (a superpixel: with at least one valid SPAD).
    pub fn fill(&mut self, first: u64, out: &mut [u32]) -> u64 {
        let Some(front) = &self.front else {
            return self.sources[0].fill_counted_codes(first, out).detections;
        };
        let k = out.len();
        for (src, buf) in self.sources.iter().zip(&mut self.scratch) {
            src.fill_codes(first, &mut buf[..k]);
        }
        let streams: Vec<&[u32]> = self.scratch.iter().map(|b| &b[..k]).collect();
        front.combine_streams(&streams, out)
    }
}

/// One frame of pixel (r, c): its register words and its detections.
pub fn run_pixel(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
    r: usize,
    c: usize,
) -> Result<(Vec<i64>, u64), ArrayError> {
    pixel_watched(design, rom, r, c, &Watch::default())
}

/// [`run_pixel`], counting its pulses on `watch` and stopping when told, chunk by chunk.
fn pixel_watched(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
    r: usize,
    c: usize,
    watch: &Watch,
) -> Result<(Vec<i64>, u64), ArrayError> {
    let n = design.pixel.frame_pulses;
    let mut source = PixelStream::new(design, r, c, CHUNK.min(n as usize))?;
    let err = |source| ArrayError::Pixel {
        row: r,
        col: c,
        source,
    };
    // The folded driver when it pays (periodic ROM, Fourier), the transaction driver
    // otherwise: bit-identical registers either way.
    let mut tm = FrameDriver::new(&design.pixel, rom).map_err(err)?;
    // The source counts the detections as it draws them: no second pass over the pulses.
    // The compact codes (4 bytes a pulse), read by the driver without conversion.
    let mut buf = vec![0u32; CHUNK.min(n as usize)];
    let (mut first, mut detections) = (0u64, 0u64);
    while first < n {
        let k = (n - first).min(buf.len() as u64) as usize;
        detections += source.fill(first, &mut buf[..k]);
        tm.run(&buf[..k], first).map_err(err)?;
        first += k as u64;
        if !watch.advance(k as u64) {
            return Err(ArrayError::Stopped);
        }
    }
    Ok((tm.readout().words, detections))
}

/// One frame of the pixels `group` (at most [`LANES`], each (r, c)) through the lane
/// driver (`FoldLanes`, the folded driver of each pixel run in lockstep): each pixel's
/// register words and detections, exactly [`run_pixel`]'s. Each pixel reads its own
/// stream, so the result does not depend on which pixels share a group.
pub fn run_group(
    design: &ResolvedDesign,
    rom: &RomImage,
    group: &[(usize, usize)],
) -> Result<Vec<(Vec<i64>, u64)>, ArrayError> {
    group_watched(design, rom, group, &Watch::default())
}

/// [`run_group`], counting its pixel-pulses on `watch` and stopping when told.
fn group_watched(
    design: &ResolvedDesign,
    rom: &RomImage,
    group: &[(usize, usize)],
    watch: &Watch,
) -> Result<Vec<(Vec<i64>, u64)>, ArrayError> {
    let err = |(row, col): (usize, usize)| move |source| ArrayError::Pixel { row, col, source };
    let first = *group
        .first()
        .ok_or_else(|| ArrayError::Shape("a lane group of no pixels".into()))?;
    let n = design.pixel.frame_pulses;
    let len = LANE_CHUNK.min(n as usize);
    let mut sources = group
        .iter()
        .map(|&(r, c)| PixelStream::new(design, r, c, len))
        .collect::<Result<Vec<_>, _>>()?;
    let mut lanes = FoldLanes::new(&design.pixel, rom, group.len()).map_err(err(first))?;
    let mut bufs = vec![vec![0u32; len]; group.len()];
    let mut detections = vec![0u64; group.len()];
    let mut start = 0u64;
    while start < n {
        let k = (n - start).min(len as u64) as usize;
        for ((src, buf), d) in sources.iter_mut().zip(&mut bufs).zip(&mut detections) {
            *d += src.fill(start, &mut buf[..k]);
        }
        let chunk: Vec<&[u32]> = bufs.iter().map(|b| &b[..k]).collect();
        lanes.run(&chunk, start).map_err(err(first))?;
        start += k as u64;
        if !watch.advance((k * group.len()) as u64) {
            return Err(ArrayError::Stopped);
        }
    }
    Ok(lanes
        .readout()
        .into_iter()
        .map(|r| r.words)
        .zip(detections)
        .collect())
}

/// The array shape of a design, or an error naming the missing `[array]`.
fn shape(design: &ResolvedDesign) -> Result<(usize, usize), ArrayError> {
    design
        .array
        .as_ref()
        .map(|a| (a.rows, a.cols))
        .ok_or_else(|| ArrayError::Shape(format!("`{}` has no [array] section", design.origin)))
}

/// Runs the pixels of rows × cols (within the array) in parallel on the current rayon
/// pool. `rom` is the chip's probe ROM (Fourier; `None` in Haar mode).
pub fn run_tile(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
    rows: Range<usize>,
    cols: Range<usize>,
) -> Result<Tile, ArrayError> {
    run_tile_watched(design, rom, rows, cols, &Watch::default())
}

/// [`run_tile`] watched: every pixel counts its pulses on `watch` chunk by chunk (a tile
/// of P pixels counts P·N pixel-pulses), and the tile stops with [`ArrayError::Stopped`]
/// within a chunk of [`Watch::stop`] (a few milliseconds). The registers of a run that
/// was not stopped are [`run_tile`]'s.
pub fn run_tile_watched(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
    rows: Range<usize>,
    cols: Range<usize>,
    watch: &Watch,
) -> Result<Tile, ArrayError> {
    let (nr, nc) = shape(design)?;
    if rows.start >= rows.end || cols.start >= cols.end || rows.end > nr || cols.end > nc {
        return Err(ArrayError::Shape(format!(
            "tile rows {rows:?} × cols {cols:?} is not a non-empty part of the {nr} × {nc} array"
        )));
    }
    let level = design
        .array
        .as_ref()
        .map_or(ArrayLevel::BitTrue, |a| a.level);
    let (w, r0, c0) = (cols.len(), rows.start, cols.start);
    let at = |i: usize| (r0 + i / w, c0 + i % w);
    let count = rows.len() * w;
    match level {
        ArrayLevel::BitTrue => {
            let pixels: Vec<_> = (0..count).map(at).collect();
            let (registers, detections) = run_pixels(design, rom, &pixels, watch)?;
            Ok(Tile {
                rows,
                cols,
                registers_per_pixel: design.pixel.registers(),
                registers,
                detections,
            })
        }
        // The statistical and closed-form levels draw registers instead of running pulses.
        ArrayLevel::Statistical | ArrayLevel::ClosedForm => {
            crate::statistical::run_tile(design, rows, cols, watch)
        }
        // Auto: the moving pixels bit-true, the others drawn (statistical::auto's rule).
        ArrayLevel::Auto => {
            let model = shared_model(design, ArrayLevel::Statistical)?;
            let k = design
                .array
                .as_ref()
                .map_or(AUTO_THRESHOLD, |a| a.auto_threshold);
            let moving = model.auto_levels(design, rows.clone(), cols.clone(), k)?;
            let mut tile = model.run_tile_except(design, rows, cols, &moving, watch)?;
            let which: Vec<usize> = (0..count).filter(|&i| moving[i]).collect();
            let pixels: Vec<_> = which.iter().map(|&i| at(i)).collect();
            let (registers, detections) = run_pixels(design, rom, &pixels, watch)?;
            let k = tile.registers_per_pixel;
            for (j, &i) in which.iter().enumerate() {
                tile.registers[i * k..(i + 1) * k].copy_from_slice(&registers[j * k..(j + 1) * k]);
                tile.detections[i] = detections[j];
            }
            Ok(tile)
        }
    }
}

/// The bit-true registers (`pixels.len()` × K, in the order of `pixels`) and detections of
/// the pixels `pixels`, in parallel on the current rayon pool: a group of [`LANES`] at a
/// time where the fold pays, else one by one. Each pixel reads its own stream, so its
/// registers do not depend on which pixels are run with it.
fn run_pixels(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
    pixels: &[(usize, usize)],
    watch: &Watch,
) -> Result<(Vec<i64>, Vec<u64>), ArrayError> {
    let k = design.pixel.registers();
    // The registers and detections are filled in place, pixel by pixel (a group of
    // LANES at a time): nothing per pixel is held besides them (the memory the resolution
    // counts, `SensorArray::bytes_per_pixel`).
    let mut registers = vec![0i64; pixels.len() * k];
    let mut detections = vec![0u64; pixels.len()];
    let put = |words: &[i64], out: &mut [i64], (r, c): (usize, usize)| {
        if words.len() != out.len() {
            return Err(ArrayError::Shape(format!(
                "pixel ({r}, {c}) read out {} registers, not {}",
                words.len(),
                out.len()
            )));
        }
        out.copy_from_slice(words);
        Ok(())
    };
    match rom {
        // A folded pixel: groups of LANES pixels (in the order given) in lockstep.
        Some(rom) if fold_pays(&design.pixel) => registers
            .par_chunks_mut(LANES * k.max(1))
            .zip(detections.par_chunks_mut(LANES))
            .zip(pixels.par_chunks(LANES))
            .try_for_each(|((regs, dets), group)| {
                let out = group_watched(design, rom, group, watch)?;
                for (j, (words, d)) in out.into_iter().enumerate() {
                    put(&words, &mut regs[j * k..(j + 1) * k], group[j])?;
                    dets[j] = d;
                }
                Ok::<(), ArrayError>(())
            })?,
        _ => registers
            .par_chunks_mut(k.max(1))
            .zip(detections.par_iter_mut())
            .zip(pixels.par_iter())
            .try_for_each(|((regs, det), &(r, c))| {
                let (words, d) = pixel_watched(design, rom, r, c, watch)?;
                put(&words, &mut regs[..k], (r, c))?;
                *det = d;
                Ok::<(), ArrayError>(())
            })?,
    }
    Ok((registers, detections))
}

/// Merges tiles that cover the R × C array exactly once into the array's frame; refuses a
/// gap or an overlap, naming the first pixel.
pub fn merge(rows: usize, cols: usize, tiles: &[Tile]) -> Result<ArrayFrame, ArrayError> {
    let k = tiles.first().map_or(0, |t| t.registers_per_pixel);
    let mut registers = vec![0i64; rows * cols * k];
    let mut detections = vec![0u64; rows * cols];
    let mut seen = vec![false; rows * cols];
    for t in tiles {
        if t.registers_per_pixel != k || t.rows.end > rows || t.cols.end > cols {
            return Err(ArrayError::Shape(format!(
                "tile rows {:?} × cols {:?} does not fit the {rows} × {cols} array of {k} registers",
                t.rows, t.cols
            )));
        }
        let w = t.cols.len();
        for (i, words) in t.registers.chunks_exact(k.max(1)).enumerate() {
            let (r, c) = (t.rows.start + i / w, t.cols.start + i % w);
            let p = r * cols + c;
            if std::mem::replace(&mut seen[p], true) {
                return Err(ArrayError::Shape(format!(
                    "pixel ({r}, {c}) is in two tiles"
                )));
            }
            registers[p * k..(p + 1) * k].copy_from_slice(words);
            detections[p] = t.detections[i];
        }
    }
    if let Some(p) = seen.iter().position(|s| !s) {
        return Err(ArrayError::Shape(format!(
            "pixel ({}, {}) is in no tile",
            p / cols,
            p % cols
        )));
    }
    Ok(ArrayFrame {
        rows,
        cols,
        registers_per_pixel: k,
        registers,
        detections,
    })
}

/// Runs the whole array as one tile.
pub fn run_array(
    design: &ResolvedDesign,
    rom: Option<&RomImage>,
) -> Result<ArrayFrame, ArrayError> {
    let (r, c) = shape(design)?;
    // The whole array as one tile: its vectors are the frame's, moved, not copied.
    let t = run_tile(design, rom, 0..r, 0..c)?;
    Ok(ArrayFrame {
        rows: r,
        cols: c,
        registers_per_pixel: t.registers_per_pixel,
        registers: t.registers,
        detections: t.detections,
    })
}
