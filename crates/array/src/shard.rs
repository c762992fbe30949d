//! Sharding an array run across processes and machines, deterministically: [`tiles`]
//! partitions an R × C array into n rectangles (row bands, then column pieces), [`share`]
//! cuts a range of n items (a soak's configurations) into n contiguous shares, [`Shard`]
//! is the `i/n` of a job array. [`run_shard`] runs share i of an array and writes its
//! **tile set**: the tile's registers and detections (`registers.npy`, `detections.npy`),
//! its part of the SPAD rate maps (`signal_rate.npy`, `background_rate.npy`), the
//! manifest (`manifest.json`: the resolved design's hash, the seed, the tile's rectangle,
//! the resolved design without its maps) and the project's completion marker listing every
//! file's hash, written last. [`merge_sets`] (`crate::tile_set`) checks a list of tile
//! sets (whole, same design with its maps, same seed, every pixel exactly once, each
//! refusal naming the offending set) and writes the same output set `tofprobe simulate
//! --out` writes. A tile's registers do not depend on the tiling, so the merged set equals
//! the single run's byte for byte (its `summary.json` differs only in the timing figures,
//! `model_seconds` summed over the tiles).

use std::ops::Range;
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use tofprobe_design::ResolvedDesign;
use tofprobe_io::npy;

use crate::error::ArrayError;
use crate::model::run_tile;

pub use crate::set_plan::{BACKGROUND_MAP, DETECTIONS, MANIFEST, REGISTERS, SIGNAL_MAP};
pub use crate::tile_set::{merge_sets, read_manifest};

/// The `kind` a manifest carries, and the version of the tile set's layout.
pub(crate) const KIND: &str = "tofprobe array tile set";
pub(crate) const VERSION: u32 = 3;
/// The data files a manifest carries the hashes of.
pub(crate) const DATA_FILES: [&str; 4] = [REGISTERS, DETECTIONS, SIGNAL_MAP, BACKGROUND_MAP];

/// Share `index` of `count` (0-based: a job array's task `0 .. count − 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// Parses `i/n` (0 ≤ i < n); the error names the value and what would work.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || {
            format!(
                "`i/n` with 0 ≤ i < n, not `{text}` (0-based, e.g. 0/4 .. 3/4; \
                 a Slurm job array passes $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT)"
            )
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: u64 = i.trim().parse().map_err(|_| bad())?;
        let count: u64 = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Share `i` of `n` of the items `0 .. total`: contiguous, sizes differing by at most one,
/// the shares `0 .. n` covering `0 .. total` exactly once in order.
pub fn share(total: u64, shard: Shard) -> Range<u64> {
    let at = |i: u64| (u128::from(total) * u128::from(i) / u128::from(shard.count)) as u64;
    at(shard.index)..at(shard.index + 1)
}

/// A tile's rectangle: rows × cols.
pub type Rect = (Range<usize>, Range<usize>);

/// The partition of an R × C array into `n` rectangles (1 ≤ n ≤ R·C), in order: n ≤ R gives
/// n bands of whole rows; n > R gives every row its own band, row r cut into n_r column
/// pieces (the n_r share n over the rows). Deterministic, every pixel in exactly one tile.
pub fn tiles(rows: usize, cols: usize, n: usize) -> Result<Vec<Rect>, ArrayError> {
    let pixels = rows.saturating_mul(cols);
    if n == 0 || n > pixels {
        return Err(ArrayError::Shape(format!(
            "tiles = {n} for a {rows} × {cols} array: use 1 ..= {pixels} (one pixel per tile at most)"
        )));
    }
    let cut = |total: usize, i: usize, k: usize| total * i / k;
    if n <= rows {
        return Ok((0..n)
            .map(|i| (cut(rows, i, n)..cut(rows, i + 1, n), 0..cols))
            .collect());
    }
    let mut out = Vec::with_capacity(n);
    for r in 0..rows {
        let pieces = cut(n, r + 1, rows) - cut(n, r, rows);
        out.extend((0..pieces).map(|j| (r..r + 1, cut(cols, j, pieces)..cut(cols, j + 1, pieces))));
    }
    Ok(out)
}

/// The manifest of one tile set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TileManifest {
    pub kind: String,
    /// The tile set's layout (2: `.npy` files and the maps beside the manifest).
    pub version: u32,
    /// [`design_hash`] of the resolved design the shard ran, maps included.
    pub design_hash: String,
    pub seed: u64,
    pub shard: Shard,
    pub array_rows: usize,
    pub array_cols: usize,
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub registers_per_pixel: usize,
    /// FNV-1a-64 (hex) of each data file as the shard wrote it: a file changed and the
    /// marker re-sealed to match still differs from the manifest (version 3).
    pub files: std::collections::BTreeMap<String, String>,
    /// Wall time of the tile's model, s.
    pub model_seconds: f64,
    /// The resolved design with its rate maps empty (they are in the set's `.npy` maps,
    /// the tile's part of them), so a merge needs no configuration.
    pub design: ResolvedDesign,
}

/// The resolved design's hash: FNV-1a 64 of its JSON (the rate maps included, streamed:
/// never held as text) with the seed set to 0 and without the configuration's path, so
/// shards that differ only in the seed or the configuration's name share it (the merge
/// names those apart), while a changed map image does not.
pub fn design_hash(design: &ResolvedDesign) -> Result<String, ArrayError> {
    let mut d = design.clone();
    d.document.acquisition.seed = 0;
    d.origin = String::new();
    let mut sink = tofprobe_io::HashingWriter::new(std::io::sink());
    serde_json::to_writer(&mut sink, &d)
        .map_err(|e| ArrayError::Shape(format!("the design does not serialise: {e}")))?;
    Ok(format!("{:016x}", sink.finish().1))
}

/// The rows × cols part of a row-major map of `width` columns.
pub(crate) fn map_part(
    map: &[f64],
    width: usize,
    rows: Range<usize>,
    cols: Range<usize>,
) -> Vec<f64> {
    rows.flat_map(|r| {
        map[r * width + cols.start..r * width + cols.end]
            .iter()
            .copied()
    })
    .collect()
}

/// Runs tile `shard` of the array of `design` ([`tiles`] of `shard.count`) on the current
/// rayon pool and writes its tile set into `dir` (whole or absent, the marker last). The
/// set is opened, and its size, directory and disk checked, before the model runs.
pub fn run_shard(
    design: &ResolvedDesign,
    shard: Shard,
    dir: &Path,
) -> Result<TileManifest, ArrayError> {
    let a = design.array.as_ref().ok_or_else(|| {
        ArrayError::Shape(format!(
            "`{}` has no [array] section: --shard splits an array",
            design.origin
        ))
    })?;
    let count = usize::try_from(shard.count).unwrap_or(usize::MAX);
    let parts = tiles(a.rows, a.cols, count).map_err(|_| ArrayError::Option {
        option: "shard".into(),
        value: shard.to_string(),
        allowed: format!(
            "n ≤ {} for the {} × {} array (one pixel per tile at most)",
            a.rows.saturating_mul(a.cols),
            a.rows,
            a.cols
        ),
    })?;
    let (rows, cols) = parts[shard.index as usize].clone();
    let files = crate::set_plan::tile_set(design, rows.len(), cols.len());
    let mut set = crate::set_plan::open(design, dir, &files, u64::MAX)?;
    let rom = design.probe_rom()?;
    let t0 = Instant::now();
    let tile = run_tile(
        design,
        rom.as_ref().map(|r| &r.image),
        rows.clone(),
        cols.clone(),
    )?;
    let mut bare = design.clone();
    if let Some(b) = bare.array.as_mut() {
        b.signal_rate = Vec::new();
        b.background_rate = Vec::new();
    }
    let mut manifest = TileManifest {
        kind: KIND.into(),
        version: VERSION,
        design_hash: design_hash(design)?,
        seed: design.document.acquisition.seed,
        shard,
        array_rows: a.rows,
        array_cols: a.cols,
        rows: rows.clone(),
        cols: cols.clone(),
        registers_per_pixel: tile.registers_per_pixel,
        files: Default::default(),
        model_seconds: t0.elapsed().as_secs_f64(),
        design: bare,
    };
    let out = |e: std::io::Error| ArrayError::Output {
        path: dir.to_path_buf(),
        message: e.to_string(),
    };
    let (rt, ct, g) = (rows.len(), cols.len(), a.superpixel);
    let spads = (rows.start * g..rows.end * g, cols.start * g..cols.end * g);
    set.add_streamed(REGISTERS, |w| {
        npy::write(w, &[rt, ct, tile.registers_per_pixel], &tile.registers)
    })
    .map_err(out)?;
    set.add_streamed(DETECTIONS, |w| {
        npy::write_iter(w, &[rt, ct], tile.detections.iter().map(|&d| d as i64))
    })
    .map_err(out)?;
    for (name, map) in [
        (SIGNAL_MAP, &a.signal_rate),
        (BACKGROUND_MAP, &a.background_rate),
    ] {
        let part = map_part(map, a.spad_cols(), spads.0.clone(), spads.1.clone());
        set.add_streamed(name, |w| npy::write(w, &[rt * g, ct * g], &part))
            .map_err(out)?;
    }
    for name in DATA_FILES {
        let h = set.staged_hash(name).unwrap_or_default();
        manifest.files.insert(name.to_string(), format!("{h:016x}"));
    }
    set.add_streamed(MANIFEST, |w| {
        serde_json::to_writer_pretty(&mut *w, &manifest).map_err(std::io::Error::other)
    })
    .map_err(out)?;
    let preamble = format!(
        "# Generated by tofprobe {}: the completion marker of the tile set of shard {shard} \
         (each file's FNV-1a-64), written last; `tofprobe merge` and `tofprobe check-set` \
         check it.\n",
        env!("CARGO_PKG_VERSION")
    );
    set.commit_marked(crate::set_plan::MARKER, &preamble)
        .map_err(out)?;
    Ok(manifest)
}
