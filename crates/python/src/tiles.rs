//! The array in tiles, conversion only: the partition (`tofprobe_array::shard::tiles`),
//! one tile run on a rayon pool of the caller's size (`tofprobe_array::run_tile_watched`,
//! through `long_call::run`, so Ctrl-C stops it between chunks: a Dask task sizes the pool
//! to its worker's threads), tiles merged back (`tofprobe_array::model::merge`)
//! and the maps of the merged frame (`tofprobe_array::output::finish`). Tiles arriving
//! through pickle or a Dask frame may be misaligned: they are copied once (`convert`).

use std::ops::Range;
use std::time::Instant;

use numpy::IntoPyArray;
use numpy::ndarray::{Array2, Array3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use tofprobe_array::model::{ArrayFrame, Tile};

use crate::Design;
use crate::convert::{self, value_error};
use crate::long_call::{self, Progress};

/// The array shape, or a ValueError naming the missing `[array]`.
fn shape(d: &Design) -> PyResult<(usize, usize)> {
    d.inner
        .array
        .as_ref()
        .map(|a| (a.rows, a.cols))
        .ok_or_else(|| {
            crate::errors::input(format!(
                "`{}` has no [array] section: simulate_array and tiles run an [array] design",
                d.inner.origin
            ))
        })
}

/// The rectangles of `tiles` tiles, `((r0, r1), (c0, c1))` each.
pub fn rects(d: &Design, tiles: usize) -> PyResult<Vec<tofprobe_array::shard::Rect>> {
    let (r, c) = shape(d)?;
    tofprobe_array::shard::tiles(r, c, tiles)
        .map_err(|e| crate::errors::input(format!("`tiles`: {e}")))
}

/// Runs one tile on a pool of `threads` threads (`None`: the current pool), stopped by
/// Ctrl-C between chunks.
pub fn run_tile(
    d: &Design,
    py: Python<'_>,
    rows: Range<usize>,
    cols: Range<usize>,
    threads: Option<usize>,
) -> PyResult<Tile> {
    let pool = long_call::pool(threads)?;
    let rom = d.rom(py)?.map(|r| &r.image);
    let design = &d.inner;
    let progress = Progress::none(0);
    long_call::run(py, &progress, pool.as_ref(), |w| {
        tofprobe_array::run_tile_watched(design, rom, rows, cols, w)
    })?
    .map_err(value_error)
}

/// A tile as a dict: `rows`, `cols` (`(start, end)`), `registers` (int64 [h, w, K]),
/// `detections` (uint64 [h, w]).
pub fn tile_dict<'py>(py: Python<'py>, t: Tile) -> PyResult<Bound<'py, PyDict>> {
    let (h, w) = (t.rows.len(), t.cols.len());
    let out = PyDict::new(py);
    out.set_item("rows", (t.rows.start, t.rows.end))?;
    out.set_item("cols", (t.cols.start, t.cols.end))?;
    let regs =
        Array3::from_shape_vec((h, w, t.registers_per_pixel), t.registers).map_err(value_error)?;
    out.set_item("registers", regs.into_pyarray(py))?;
    let det = Array2::from_shape_vec((h, w), t.detections).map_err(value_error)?;
    out.set_item("detections", det.into_pyarray(py))?;
    Ok(out)
}

/// A dict of `tile_dict` back into a tile (`i` names it in errors).
fn tile_from(py: Python<'_>, i: usize, obj: &Bound<'_, PyAny>, k: usize) -> PyResult<Tile> {
    let name = format!("tiles[{i}]");
    let d = obj.cast::<PyDict>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "`{name}` must be a dict of run_tile (rows, cols, registers, detections)"
        ))
    })?;
    let get = |key: &str| -> PyResult<Bound<'_, PyAny>> {
        d.get_item(key)?
            .ok_or_else(|| crate::errors::input(format!("`{name}` has no `{key}`")))
    };
    let (r0, r1): (usize, usize) = get("rows")?.extract()?;
    let (c0, c1): (usize, usize) = get("cols")?.extract()?;
    let np = py.import("numpy")?;
    let flat = |key: &str| -> PyResult<Bound<'_, PyAny>> {
        np.call_method1("ravel", (np.call_method1("asarray", (get(key)?,))?,))
    };
    let regs = convert::int64_array(&format!("{name}['registers']"), &flat("registers")?)?;
    let dets = convert::int64_array(&format!("{name}['detections']"), &flat("detections")?)?;
    let pixels = r1.saturating_sub(r0) * c1.saturating_sub(c0);
    let regs = convert::slice(&regs, "registers")?;
    let dets = convert::slice(&dets, "detections")?;
    if regs.len() != pixels * k || dets.len() != pixels {
        return Err(crate::errors::input(format!(
            "`{name}`: rows {r0}..{r1} × cols {c0}..{c1} needs {} registers and {pixels} \
             detections, got {} and {}",
            pixels * k,
            regs.len(),
            dets.len()
        )));
    }
    let detections = dets
        .iter()
        .map(|&x| u64::try_from(x))
        .collect::<Result<_, _>>()
        .map_err(|_| {
            crate::errors::input(format!("`{name}['detections']` holds a negative count"))
        })?;
    Ok(Tile {
        rows: r0..r1,
        cols: c0..c1,
        registers_per_pixel: k,
        registers: regs.to_vec(),
        detections,
    })
}

/// Tiles (dicts of `run_tile`) merged into the array's frame.
pub fn merge(d: &Design, py: Python<'_>, tiles: &Bound<'_, PyAny>) -> PyResult<ArrayFrame> {
    let (r, c) = shape(d)?;
    let list = tiles.cast::<PyList>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err("`tiles` must be a list of run_tile's dicts")
    })?;
    let k = d.inner.pixel.registers();
    let mut parts = Vec::with_capacity(list.len());
    for (i, t) in list.iter().enumerate() {
        parts.push(tile_from(py, i, &t, k)?);
    }
    py.detach(|| tofprobe_array::model::merge(r, c, &parts))
        .map_err(|e| crate::errors::input(format!("`tiles`: {e}")))
}

/// Runs the array in `tiles` tiles one after the other (each on `pool`, or the current
/// pool), reporting pixel-pulses to `progress` and stopped by Ctrl-C between chunks.
pub fn run_local(
    d: &Design,
    py: Python<'_>,
    tiles: usize,
    progress: Option<&Bound<'_, PyAny>>,
    pool: Option<&rayon::ThreadPool>,
) -> PyResult<(ArrayFrame, f64)> {
    let (r, c) = shape(d)?;
    let parts = rects(d, tiles)?;
    let rom = d.rom(py)?.map(|r| &r.image);
    let design = &d.inner;
    let total = (r * c) as u64 * design.pixel.frame_pulses;
    let progress = Progress::new(py, progress, "simulate_array", "pixel-pulses", total)?;
    long_call::run(py, &progress, pool, |w| {
        let t0 = Instant::now();
        let done = parts
            .into_iter()
            .map(|(rs, cs)| tofprobe_array::run_tile_watched(design, rom, rs, cs, w))
            .collect::<Result<Vec<_>, _>>()?;
        let frame = tofprobe_array::model::merge(r, c, &done)?;
        Ok((frame, t0.elapsed().as_secs_f64()))
    })?
    .map_err(|e: tofprobe_array::ArrayError| value_error(e))
}

/// The array's dict: `registers`, `detections` and, Fourier, `frequencies_hz`,
/// `amplitude_um`, `phase_deg` (the maps of `tofprobe_array::output::finish`).
pub fn array_dict<'py>(
    d: &Design,
    py: Python<'py>,
    frame: ArrayFrame,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let rom = d.rom(py)?;
    let design = &d.inner;
    let (frame, maps, _, _) = py
        .detach(|| tofprobe_array::output::finish(design, rom, frame, seconds))
        .map_err(value_error)?;
    let (r, c, k) = (frame.rows, frame.cols, frame.registers_per_pixel);
    let out = PyDict::new(py);
    let regs = Array3::from_shape_vec((r, c, k), frame.registers).map_err(value_error)?;
    out.set_item("registers", regs.into_pyarray(py))?;
    let det = Array2::from_shape_vec((r, c), frame.detections).map_err(value_error)?;
    out.set_item("detections", det.into_pyarray(py))?;
    let levels: Vec<i64> = py
        .detach(|| tofprobe_array::statistical::auto::level_map(design))
        .map_err(value_error)?
        .into_iter()
        .map(tofprobe_array::statistical::auto::level_code)
        .collect();
    let level = Array2::from_shape_vec((r, c), levels).map_err(value_error)?;
    out.set_item("level", level.into_pyarray(py))?;
    if let Some(m) = maps {
        let b = m.bins();
        out.set_item("frequencies_hz", m.frequencies_hz.into_pyarray(py))?;
        let amp = Array3::from_shape_vec((b, r, c), m.amplitude_um).map_err(value_error)?;
        out.set_item("amplitude_um", amp.into_pyarray(py))?;
        let ph = Array3::from_shape_vec((b, r, c), m.phase_deg).map_err(value_error)?;
        out.set_item("phase_deg", ph.into_pyarray(py))?;
    }
    Ok(out)
}
