//! An array's output set before any work: its files ([`array_set`], [`tile_set`]) — names
//! known from the design alone, each with an upper bound of its size — and [`open`], which
//! starts the set in its directory only if the whole of it fits: within the set cap
//! (`--max-out-gib`), in the free space of the disk, into a directory this run may write
//! (its writer lock, [`tofprobe_io::lock`]) and without replacing a file that a previous
//! tofprobe set did not write (the completion marker's list, [`tofprobe_io::marker`]). So
//! `simulate --out`, `merge` and a shard refuse in milliseconds what would otherwise fail
//! after the model ran, or fill the disk halfway through the commit.

use std::path::Path;

use tofprobe_design::ResolvedDesign;
use tofprobe_io::disk::human_bytes;
use tofprobe_io::{OutputSet, npy};

use crate::error::ArrayError;
use crate::plot::{CELL_BYTES, DEFLECTION_CELL_BYTES, DEFLECTION_HEAD_BYTES, FRAME_BYTES};

/// The completion marker of array and tile sets: the project's one marker, listing every
/// file with its FNV-1a-64 (`tofprobe check-set` checks it; `merge` checks each tile set's).
pub const MARKER: &str = tofprobe_io::SET_MARKER;
/// The array set's summary.
pub const SUMMARY: &str = "summary.json";
/// A tile set's manifest (`crate::shard`).
pub const MANIFEST: &str = "manifest.json";
/// The tile's registers, int64 [rows, cols, K].
pub const REGISTERS: &str = "registers.npy";
/// The tile's detections, int64 [rows, cols].
pub const DETECTIONS: &str = "detections.npy";
/// The tile's SPADs' ρ_s and ρ_b, float64 [rows·G, cols·G].
pub const SIGNAL_MAP: &str = "signal_rate.npy";
pub const BACKGROUND_MAP: &str = "background_rate.npy";
/// Largest set written unless `--max-out-gib` allows more: 16 GiB (a 2048 × 2048 Fourier
/// array with 4 bins is ≈ 9 GB: its UFF file alone 4 kB a pixel).
pub const DEFAULT_MAX_SET_BYTES: u64 = 16 << 30;
/// Bound of `summary.json`: its fixed keys, the file names and one entry per bin.
const SUMMARY_BYTES: u64 = 16 << 10;
/// Bound of one bin's entry in the summary (four numbers with their keys).
const SUMMARY_BIN_BYTES: u64 = 256;

/// One file of a set: its name and the most bytes it will take.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SetFile {
    pub name: String,
    pub bytes: u64,
}

fn file(name: impl Into<String>, bytes: u64) -> SetFile {
    SetFile {
        name: name.into(),
        bytes,
    }
}

/// The array's shape, or the refusal of a design without `[array]`.
fn shape(design: &ResolvedDesign) -> Result<(usize, usize), ArrayError> {
    design
        .array
        .as_ref()
        .map(|a| (a.rows, a.cols))
        .ok_or_else(|| {
            ArrayError::Shape(format!(
                "`{}` has no [array] section: an array set is written for an [array] design",
                design.origin
            ))
        })
}

/// The files of the array set of `design` in the order they are written (`summary.json`
/// last; the marker follows it), each with its size bound: `.npy` exactly, `vibration.uff`
/// exactly ([`crate::uff::file_bytes`]), the SVGs from their per-cell bounds.
pub fn array_set(design: &ResolvedDesign) -> Result<Vec<SetFile>, ArrayError> {
    let (r, c) = shape(design)?;
    Ok(array_set_of(design, r, c))
}

/// [`array_set`] for `r` × `c` pixels of `design`'s pixel.
fn array_set_of(design: &ResolvedDesign, r: usize, c: usize) -> Vec<SetFile> {
    let k = design.pixel.registers();
    let pixels = (r as u64).saturating_mul(c as u64);
    let heat = FRAME_BYTES.saturating_add(pixels.saturating_mul(CELL_BYTES));
    let mut out = vec![
        file("registers.npy", npy::file_bytes(&[r, c, k])),
        file("detections.npy", npy::file_bytes(&[r, c])),
        file("level.npy", npy::file_bytes(&[r, c])),
        file("level.svg", heat),
    ];
    match design.pixel.mode {
        tofprobe_pixel::Mode::Haar => {
            out.push(file("event_time_ms.npy", npy::file_bytes(&[r, c])));
            out.push(file("event_time_sd_ms.npy", npy::file_bytes(&[r, c])));
            out.push(file("event_time.svg", heat));
        }
        tofprobe_pixel::Mode::Fourier => {
            let b = design.bins.len();
            out.push(file("amplitude_um.npy", npy::file_bytes(&[b, r, c])));
            out.push(file("phase_deg.npy", npy::file_bytes(&[b, r, c])));
            for k in 0..b {
                out.push(file(format!("amplitude_bin{k:02}.svg"), heat));
                out.push(file(format!("phase_bin{k:02}.svg"), heat));
            }
            out.push(file("strongest_bin.svg", heat));
            out.push(file(
                "deflection.svg",
                DEFLECTION_HEAD_BYTES.saturating_add(pixels.saturating_mul(DEFLECTION_CELL_BYTES)),
            ));
            out.push(file("vibration.uff", crate::uff::file_bytes(r, c, b)));
        }
    }
    let bins = design.bins.len() as u64;
    out.push(file(SUMMARY, SUMMARY_BYTES + bins * SUMMARY_BIN_BYTES));
    out
}

/// The tile set's files for the rectangle `rows` × `cols` of `design`'s array: the tile's
/// registers and detections as `.npy` (exactly) and the manifest, whose bound is the resolved
/// design's (its two rate maps, ≤ 32 characters a value in JSON) and 64 KiB.
pub fn tile_set(design: &ResolvedDesign, rows: usize, cols: usize) -> Vec<SetFile> {
    let k = design.pixel.registers();
    let spads = design.array.as_ref().map_or(0, |a| {
        (a.spad_rows() as u64).saturating_mul(a.spad_cols() as u64)
    });
    vec![
        file(REGISTERS, npy::file_bytes(&[rows, cols, k])),
        file(DETECTIONS, npy::file_bytes(&[rows, cols])),
        file(MANIFEST, spads.saturating_mul(64).saturating_add(64 << 10)),
    ]
}

/// Total of a set's size bounds.
pub fn total_bytes(files: &[SetFile]) -> u64 {
    files.iter().fold(0u64, |a, f| a.saturating_add(f.bytes))
}

/// What makes an array set too large fit in `max` bytes: its cost per pixel (the growth
/// from one pixel to two) and the largest square array of SPADs that fits.
fn what_fits(design: &ResolvedDesign, max: u64) -> String {
    let one = total_bytes(&array_set_of(design, 1, 1));
    let per_pixel = total_bytes(&array_set_of(design, 1, 2))
        .saturating_sub(one)
        .max(1);
    let g = design.array.as_ref().map_or(1, |a| a.superpixel as u64);
    let side = ((max.saturating_sub(one) / per_pixel + 1) as f64)
        .sqrt()
        .floor() as u64;
    if max < one {
        return format!(
            "≈ {} per pixel, and {} for even one pixel",
            human_bytes(per_pixel),
            human_bytes(one)
        );
    }
    format!(
        "≈ {} per pixel: array.rows = array.cols = {} SPADs fits, or fewer bins (pixel.bins)",
        human_bytes(per_pixel),
        side.max(1) * g
    )
}

/// Starts the set `files` of `design` in `dir` after every check that needs no work: the
/// size within `max_bytes` (refused naming `--max-out-gib` and what would fit), the
/// directory's writer lock (a second run is refused, naming the first), no foreign file
/// among the names, and room on the disk for the estimate. Nothing is written on a refusal
/// (a directory made for it is removed again).
pub fn open(
    design: &ResolvedDesign,
    dir: &Path,
    files: &[SetFile],
    max_bytes: u64,
) -> Result<OutputSet, ArrayError> {
    let total = total_bytes(files);
    if total > max_bytes {
        let largest = files
            .iter()
            .max_by_key(|f| f.bytes)
            .map(|f| format!("; the largest file, {}, ≈ {}", f.name, human_bytes(f.bytes)))
            .unwrap_or_default();
        return Err(ArrayError::Option {
            option: "max-out-gib".into(),
            value: tofprobe_io::text::number(max_bytes as f64 / (1u64 << 30) as f64),
            allowed: format!(
                "at least {} (default 16) for this set: {} of {} files would take ≈ \
                 {}{largest}; nothing was run or written ({})",
                tofprobe_io::text::number(total as f64 / (1u64 << 30) as f64),
                dir.display(),
                files.len() + 1,
                human_bytes(total),
                what_fits(design, max_bytes)
            ),
        });
    }
    let out = |e: std::io::Error| ArrayError::Output {
        path: dir.to_path_buf(),
        message: e.to_string(),
    };
    let mut set = OutputSet::begin(dir).map_err(out)?;
    let names: Vec<String> = files.iter().map(|f| f.name.clone()).collect();
    set.protect(MARKER, &names).map_err(out)?;
    let free = tofprobe_io::disk::free_bytes(dir).map_err(out)?;
    let room = free.saturating_sub(tofprobe_io::disk::MARGIN_BYTES);
    tofprobe_io::disk::check_room(dir, total, &what_fits(design, room)).map_err(out)?;
    Ok(set)
}
