//! Sharding an array run across processes and machines, deterministically: [`tiles`]
//! partitions an R × C array into n rectangles (row bands, then column pieces), [`share`]
//! cuts a range of n items (a soak's configurations) into n contiguous shares, [`Shard`]
//! is the `i/n` of a job array. [`run_shard`] runs share i of an array and writes its
//! **tile set** (`tile.json`: the tile's registers and detections; `manifest.json`, written
//! last: the configuration hash, the seed, the tile's rectangle, the resolved design);
//! [`merge_sets`] checks a list of tile sets (same configuration, same seed, every pixel
//! exactly once, each refusal naming the offending set) and writes the same output set
//! `tofprobe simulate --out` writes. A tile's registers do not depend on the tiling, so
//! the merged set equals the single run's byte for byte (its `summary.json` differs only
//! in the timing figures, `model_seconds` summed over the tiles).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use tofprobe_design::ResolvedDesign;

use crate::error::ArrayError;
use crate::model::{Tile, merge, run_tile};
use crate::output::{ArraySummary, write_set};

/// The tile set's manifest, its completion file (written last).
pub const MANIFEST: &str = "manifest.json";
/// The tile set's registers and detections.
pub const TILE: &str = "tile.json";
/// The `kind` a manifest carries.
const KIND: &str = "tofprobe array tile set";

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
    let pixels = rows * cols;
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
pub struct TileManifest {
    pub kind: String,
    /// FNV-1a 64 of the configuration document with its seed set to 0 ([`config_hash`]).
    pub config_hash: String,
    pub seed: u64,
    pub shard: Shard,
    pub array_rows: usize,
    pub array_cols: usize,
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    /// Wall time of the tile's model, s.
    pub model_seconds: f64,
    /// The resolved design (`ResolvedDesign::to_json`), so a merge needs no configuration.
    pub design: String,
}

/// The configuration's hash: FNV-1a 64 of its document (TOML) with the seed set to 0, so
/// two runs differing only in the seed share it (and [`merge_sets`] names the seed).
pub fn config_hash(design: &ResolvedDesign) -> Result<String, ArrayError> {
    let mut doc = design.document.clone();
    doc.acquisition.seed = 0;
    let text = toml::to_string(&doc)
        .map_err(|e| ArrayError::Shape(format!("the configuration does not serialise: {e}")))?;
    Ok(format!("{:016x}", tofprobe_io::fnv1a64(text.as_bytes())))
}

/// Runs tile `shard` of the array of `design` ([`tiles`] of `shard.count`) on the current
/// rayon pool and writes its tile set into `dir` (whole or absent, the manifest last).
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
    let parts = tiles(a.rows, a.cols, count)?;
    let (rows, cols) = parts[shard.index as usize].clone();
    let rom = design.probe_rom()?;
    let t0 = Instant::now();
    let tile = run_tile(
        design,
        rom.as_ref().map(|r| &r.image),
        rows.clone(),
        cols.clone(),
    )?;
    let manifest = TileManifest {
        kind: KIND.into(),
        config_hash: config_hash(design)?,
        seed: design.document.acquisition.seed,
        shard,
        array_rows: a.rows,
        array_cols: a.cols,
        rows,
        cols,
        model_seconds: t0.elapsed().as_secs_f64(),
        design: design.to_json()?,
    };
    let out = |e: String| ArrayError::Output {
        path: dir.to_path_buf(),
        message: e,
    };
    let tile_json = serde_json::to_vec(&tile).map_err(|e| out(e.to_string()))?;
    let manifest_json = serde_json::to_vec_pretty(&manifest).map_err(|e| out(e.to_string()))?;
    let mut set = tofprobe_io::OutputSet::begin(dir).map_err(|e| out(e.to_string()))?;
    set.add(TILE, &tile_json).map_err(|e| out(e.to_string()))?;
    set.add(MANIFEST, &manifest_json)
        .map_err(|e| out(e.to_string()))?;
    set.commit(Some(MANIFEST)).map_err(|e| out(e.to_string()))?;
    Ok(manifest)
}

/// A tile set's refusal, naming the set.
fn refuse(dir: &Path, message: impl Into<String>) -> ArrayError {
    ArrayError::TileSet {
        path: dir.to_path_buf(),
        message: message.into(),
    }
}

/// Reads one tile set: its manifest and its tile (checked against each other).
pub fn read_set(dir: &Path) -> Result<(TileManifest, Tile), ArrayError> {
    const CAP: u64 = 1 << 34;
    let m = dir.join(MANIFEST);
    if !m.is_file() {
        return Err(refuse(
            dir,
            format!(
                "no {MANIFEST}: not a tile set, or one whose run did not finish (rerun its --shard)"
            ),
        ));
    }
    let text = tofprobe_io::read_bounded_text(&m, CAP)
        .map_err(|e| refuse(dir, format!("{MANIFEST}: {e}")))?;
    let manifest: TileManifest =
        serde_json::from_str(&text).map_err(|e| refuse(dir, format!("{MANIFEST}: {e}")))?;
    if manifest.kind != KIND {
        return Err(refuse(
            dir,
            format!("{MANIFEST} is a `{}`, not a `{KIND}`", manifest.kind),
        ));
    }
    let text = tofprobe_io::read_bounded_text(&dir.join(TILE), CAP)
        .map_err(|e| refuse(dir, format!("{TILE}: {e}")))?;
    let tile: Tile =
        serde_json::from_str(&text).map_err(|e| refuse(dir, format!("{TILE}: {e}")))?;
    let pixels = tile.rows.len() * tile.cols.len();
    if tile.rows != manifest.rows
        || tile.cols != manifest.cols
        || tile.detections.len() != pixels
        || tile.registers.len() != pixels * tile.registers_per_pixel
    {
        return Err(refuse(
            dir,
            format!(
                "{TILE} does not hold the rows {:?} × cols {:?} its manifest names",
                manifest.rows, manifest.cols
            ),
        ));
    }
    Ok((manifest, tile))
}

/// Merges tile sets into the array's output set in `out` (what `tofprobe simulate --out`
/// writes for the same configuration and seed). Refuses, naming the offending set: a
/// directory that is not a finished tile set, a different configuration or seed than the
/// first set, a tile overlapping another set's, and pixels in no set (naming the first
/// pixel and the shares missing).
pub fn merge_sets(dirs: &[PathBuf], out: &Path) -> Result<ArraySummary, ArrayError> {
    let Some(first_dir) = dirs.first() else {
        return Err(ArrayError::Shape(
            "merge needs at least one tile set".into(),
        ));
    };
    let mut sets = Vec::with_capacity(dirs.len());
    for d in dirs {
        sets.push((d.as_path(), read_set(d)?));
    }
    let (m0, _) = &sets[0].1;
    let (nr, nc) = (m0.array_rows, m0.array_cols);
    let mut owner: Vec<Option<usize>> = vec![None; nr * nc];
    for (i, (dir, (m, _))) in sets.iter().enumerate() {
        if m.config_hash != m0.config_hash || (m.array_rows, m.array_cols) != (nr, nc) {
            return Err(refuse(
                dir,
                format!(
                    "a different configuration (hash {}) than {} (hash {}): merge sets of one configuration",
                    m.config_hash,
                    first_dir.display(),
                    m0.config_hash
                ),
            ));
        }
        if m.seed != m0.seed {
            return Err(refuse(
                dir,
                format!(
                    "seed {} differs from {}'s seed {}: merge sets of one seed",
                    m.seed,
                    first_dir.display(),
                    m0.seed
                ),
            ));
        }
        if m.rows.end > nr || m.cols.end > nc {
            return Err(refuse(
                dir,
                format!(
                    "tile rows {:?} × cols {:?} lies outside the {nr} × {nc} array",
                    m.rows, m.cols
                ),
            ));
        }
        for r in m.rows.clone() {
            for c in m.cols.clone() {
                if let Some(j) = owner[r * nc + c].replace(i) {
                    return Err(refuse(
                        dir,
                        format!(
                            "tile rows {:?} × cols {:?} overlaps {} at pixel ({r}, {c})",
                            m.rows,
                            m.cols,
                            sets[j].0.display()
                        ),
                    ));
                }
            }
        }
    }
    if let Some(p) = owner.iter().position(Option::is_none) {
        let count = usize::try_from(m0.shard.count).unwrap_or(usize::MAX);
        let missing: Vec<String> = tiles(nr, nc, count)
            .map(|t| {
                t.iter()
                    .enumerate()
                    .filter(|(_, (rs, cs))| owner[rs.start * nc + cs.start].is_none())
                    .map(|(i, _)| format!("{i}/{count}"))
                    .collect()
            })
            .unwrap_or_default();
        return Err(refuse(
            first_dir,
            format!(
                "the sets leave pixel ({}, {}) of the {nr} × {nc} array uncovered (missing shard(s): {})",
                p / nc,
                p % nc,
                missing.join(", ")
            ),
        ));
    }
    let design = ResolvedDesign::from_json(&m0.design)?;
    let seconds: f64 = sets.iter().map(|(_, (m, _))| m.model_seconds).sum();
    let tiles: Vec<Tile> = sets.into_iter().map(|(_, (_, t))| t).collect();
    let frame = merge(nr, nc, &tiles)?;
    let rom = design.probe_rom()?;
    write_set(&design, rom.as_ref(), frame, seconds, out)
}
