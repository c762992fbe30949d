//! Tile sets read back and merged ([`merge_sets`]), every input checked before it sizes
//! anything. A set is read in this order, each step bounded by the one before:
//! 1. its completion marker must be there (a set cut short in its commit is refused with
//!    `check-set`'s words, naming the files the cut left beside the old ones);
//! 2. `manifest.json`, at most 32 MiB (it holds the design without its maps), parsed
//!    streamed; its shape is checked against the design it carries — the array within the
//!    resolution's bounds and the memory cap, the tile inside it, the register count the
//!    pixel's — before any table is sized from it (a manifest claiming 2^31 × 2^31 pixels
//!    is refused here, in microseconds);
//! 3. each `.npy` file must have exactly the length its checked shape gives;
//! 4. every file's hash must be the marker's (a register edited since is named).
//!
//! [`merge_sets`] then compares the sets with the first (the resolved design's hash, its
//! maps included, and the seed), checks that the tiles cover the array exactly once,
//! opens the output set (its size, directory and disk checked: `crate::set_plan`), and
//! only then reads the registers, detections and map parts into place, one row at a time:
//! the merge holds the frame and the maps, never a whole tile file. The joined maps must
//! give the design hash the sets name.

use std::io::Read;
use std::ops::Range;
use std::path::{Path, PathBuf};

use tofprobe_design::ResolvedDesign;
use tofprobe_io::npy;

use crate::configuration_name;
use crate::error::ArrayError;
use crate::model::ArrayFrame;
use crate::output::{ArraySummary, SetLimits, open_set, write_set};
use crate::set_plan::{BACKGROUND_MAP, DETECTIONS, MANIFEST, MARKER, REGISTERS, SIGNAL_MAP};
use crate::shard::{KIND, TileManifest, VERSION, design_hash, tiles};

/// Largest manifest read: the design without its maps is a few kB (its configuration
/// document at most the 16 MiB a configuration may have).
const MAX_MANIFEST_BYTES: u64 = 32 << 20;

/// A tile set's refusal, naming the set.
fn refuse(dir: &Path, message: impl Into<String>) -> ArrayError {
    ArrayError::TileSet {
        path: dir.to_path_buf(),
        message: message.into(),
    }
}

/// The files a tile set's marker lists, sorted.
fn set_files() -> Vec<String> {
    let mut v: Vec<String> = [MANIFEST, REGISTERS, DETECTIONS, SIGNAL_MAP, BACKGROUND_MAP]
        .map(String::from)
        .to_vec();
    v.sort();
    v
}

/// The manifest's claims checked against the design it carries (no map, no file read).
fn check_manifest(m: &TileManifest) -> Result<(), String> {
    if m.kind != KIND {
        return Err(format!("{MANIFEST} is a `{}`, not a `{KIND}`", m.kind));
    }
    if m.version != VERSION {
        return Err(format!(
            "{MANIFEST} is of version {}; this tofprobe reads version {VERSION}: run its shard again",
            m.version
        ));
    }
    let d = &m.design;
    let a = d
        .array
        .as_ref()
        .ok_or_else(|| format!("the design in {MANIFEST} has no [array]"))?;
    a.check_shape(d.pixel.registers(), d.analysis_bins())
        .map_err(|e| format!("the design in {MANIFEST}: {e}"))?;
    if (m.array_rows, m.array_cols) != (a.rows, a.cols) {
        return Err(format!(
            "{MANIFEST} claims a {} × {} array, the design it carries is {} × {}",
            m.array_rows, m.array_cols, a.rows, a.cols
        ));
    }
    if m.registers_per_pixel != d.pixel.registers() {
        return Err(format!(
            "{MANIFEST} claims {} registers per pixel, its design's pixel has {}",
            m.registers_per_pixel,
            d.pixel.registers()
        ));
    }
    let inside = |r: &Range<usize>, n: usize| r.start < r.end && r.end <= n;
    if !inside(&m.rows, a.rows) || !inside(&m.cols, a.cols) {
        return Err(format!(
            "tile rows {:?} × cols {:?} is not a non-empty part of the {} × {} array",
            m.rows, m.cols, a.rows, a.cols
        ));
    }
    if m.shard.count == 0 || m.shard.index >= m.shard.count {
        return Err(format!("{MANIFEST} names shard {}", m.shard));
    }
    if !a.signal_rate.is_empty() || !a.background_rate.is_empty() {
        return Err(format!(
            "the design in {MANIFEST} carries rate maps: a tile set keeps them in {SIGNAL_MAP} and {BACKGROUND_MAP}"
        ));
    }
    if !(m.model_seconds.is_finite() && m.model_seconds >= 0.0) {
        return Err(format!(
            "{MANIFEST} claims a model time of {} s",
            m.model_seconds
        ));
    }
    Ok(())
}

/// The shape of each `.npy` file of a tile of `rt` × `ct` pixels, `k` registers each, of
/// G × G SPADs.
fn npy_shapes(rt: usize, ct: usize, k: usize, g: usize) -> [(&'static str, Vec<usize>); 4] {
    [
        (REGISTERS, vec![rt, ct, k]),
        (DETECTIONS, vec![rt, ct]),
        (SIGNAL_MAP, vec![rt * g, ct * g]),
        (BACKGROUND_MAP, vec![rt * g, ct * g]),
    ]
}

/// Each data file's hash in the (checked) marker against the one the manifest carries: a
/// file changed after the shard wrote it, with the marker re-sealed to match, is named.
fn check_data_hashes(dir: &Path, m: &TileManifest) -> Result<(), ArrayError> {
    // The marker was just checked whole by check_set (each listed file has its hash), and it
    // is a small text (its files are the tile set's five).
    let text = std::fs::read_to_string(dir.join(MARKER))
        .map_err(|e| refuse(dir, format!("{MARKER}: {e}")))?;
    let marked = tofprobe_io::marker::marker_files(&text)
        .ok_or_else(|| refuse(dir, format!("{MARKER} has no [files] table")))?;
    for name in crate::shard::DATA_FILES {
        let file = marked.get(name).map(|h| format!("{h:016x}"));
        let wrote = m.files.get(name);
        if file.as_ref() != wrote {
            return Err(refuse(
                dir,
                format!(
                    "{name} is not the file its shard wrote (hash {} in {MANIFEST}, {} now): changed since; run its shard again",
                    wrote.map_or("none", String::as_str),
                    file.as_deref().unwrap_or("none")
                ),
            ));
        }
    }
    if m.files.len() != crate::shard::DATA_FILES.len() {
        return Err(refuse(
            dir,
            format!(
                "{MANIFEST} lists the hashes of {} file(s), not of the tile set's {}",
                m.files.len(),
                crate::shard::DATA_FILES.join(", ")
            ),
        ));
    }
    Ok(())
}

/// Reads and checks the manifest of the tile set in `dir` (steps 1–4 of the module
/// header): a set whole and unchanged, whose manifest agrees with the design it carries
/// and whose files have the lengths their shapes give. Every refusal names the set.
pub fn read_manifest(dir: &Path) -> Result<TileManifest, ArrayError> {
    if !dir.is_dir() {
        return Err(refuse(
            dir,
            "not a directory (a tile set of `simulate --shard i/n --out SET`)",
        ));
    }
    if !dir.join(MARKER).exists() {
        let why = match tofprobe_io::check_set(dir, MARKER) {
            Err(e) => e.to_string(),
            Ok(_) => format!("its completion marker {MARKER} is missing"),
        };
        let old = if dir.join("tile.json").exists() {
            "; it holds tile.json, the layout of tofprobe before tile sets carried a marker: run its shard again"
        } else {
            "; rerun its --shard if it did not finish"
        };
        return Err(refuse(dir, format!("{why}{old}")));
    }
    let mpath = dir.join(MANIFEST);
    let len = std::fs::metadata(&mpath)
        .map_err(|e| refuse(dir, format!("{MANIFEST}: {e}")))?
        .len();
    if len > MAX_MANIFEST_BYTES {
        return Err(refuse(
            dir,
            format!("{MANIFEST} has {len} bytes: a manifest has at most {MAX_MANIFEST_BYTES}"),
        ));
    }
    let file = std::fs::File::open(&mpath).map_err(|e| refuse(dir, format!("{MANIFEST}: {e}")))?;
    let m: TileManifest =
        serde_json::from_reader(std::io::BufReader::new(file.take(MAX_MANIFEST_BYTES)))
            .map_err(|e| refuse(dir, format!("{MANIFEST}: {e}")))?;
    check_manifest(&m).map_err(|e| refuse(dir, e))?;
    let g = m.design.array.as_ref().map_or(1, |a| a.superpixel);
    for (name, shape) in npy_shapes(m.rows.len(), m.cols.len(), m.registers_per_pixel, g) {
        let want = npy::file_bytes(&shape);
        let got = std::fs::metadata(dir.join(name))
            .map_err(|e| refuse(dir, format!("{name}: {e}")))?
            .len();
        if got != want {
            return Err(refuse(
                dir,
                format!(
                    "{name} has {got} bytes; the int64/float64 array {shape:?} its manifest gives has {want}"
                ),
            ));
        }
    }
    let listed = tofprobe_io::check_set(dir, MARKER).map_err(|e| refuse(dir, e.to_string()))?;
    if listed != set_files() {
        return Err(refuse(
            dir,
            format!(
                "its {MARKER} lists {}, not the files of a tile set ({})",
                listed.join(", "),
                set_files().join(", ")
            ),
        ));
    }
    check_data_hashes(dir, &m)?;
    Ok(m)
}

/// Streams the `.npy` file `dir/name`, which must hold `descr` elements of `shape`
/// exactly, to `put` one row (the elements of `shape[1..]`, as little-endian bytes) at a
/// time.
fn read_rows(
    dir: &Path,
    name: &str,
    descr: &str,
    shape: &[usize],
    mut put: impl FnMut(usize, &[u8]) -> Result<(), String>,
) -> Result<(), ArrayError> {
    let bad = |m: String| refuse(dir, format!("{name}: {m}"));
    let f = std::fs::File::open(dir.join(name)).map_err(|e| bad(e.to_string()))?;
    let mut r = std::io::BufReader::new(f);
    let (d, s) = npy::read_header(&mut r).map_err(|e| bad(e.to_string()))?;
    if d != descr || s != shape {
        return Err(bad(format!(
            "holds {d} {s:?}; its manifest gives {descr} {shape:?}"
        )));
    }
    let mut row = vec![0u8; 8 * shape[1..].iter().product::<usize>()];
    for i in 0..shape[0] {
        r.read_exact(&mut row).map_err(|e| bad(e.to_string()))?;
        put(i, &row).map_err(bad)?;
    }
    Ok(())
}

fn words(bytes: &[u8]) -> impl Iterator<Item = [u8; 8]> + '_ {
    bytes
        .chunks_exact(8)
        .map(|c| c.try_into().unwrap_or([0; 8]))
}

/// Reads the tile `rows` × `cols` of the set in `dir` into the frame and its SPADs' rates
/// into the maps (`spad_cols` wide).
fn read_into(
    dir: &Path,
    (rows, cols_t): &(Range<usize>, Range<usize>),
    frame: &mut ArrayFrame,
    maps: [&mut Vec<f64>; 2],
    g: usize,
    spad_cols: usize,
) -> Result<(), ArrayError> {
    let (k, cols) = (frame.registers_per_pixel, frame.cols);
    let [regs, dets, sig, bg] = npy_shapes(rows.len(), cols_t.len(), k, g);
    let (r0, c0) = (rows.start, cols_t.start);
    read_rows(dir, regs.0, "<i8", &regs.1, |i, row| {
        let at = ((r0 + i) * cols + c0) * k;
        for (dst, w) in frame.registers[at..at + row.len() / 8]
            .iter_mut()
            .zip(words(row))
        {
            *dst = i64::from_le_bytes(w);
        }
        Ok(())
    })?;
    read_rows(dir, dets.0, "<i8", &dets.1, |i, row| {
        let at = (r0 + i) * cols + c0;
        for (dst, w) in frame.detections[at..at + row.len() / 8]
            .iter_mut()
            .zip(words(row))
        {
            *dst = u64::try_from(i64::from_le_bytes(w))
                .map_err(|_| "a negative detection count".to_string())?;
        }
        Ok(())
    })?;
    for ((name, shape), map) in [sig, bg].into_iter().zip(maps) {
        read_rows(dir, name, "<f8", &shape, |i, row| {
            let at = (r0 * g + i) * spad_cols + c0 * g;
            for (dst, w) in map[at..at + row.len() / 8].iter_mut().zip(words(row)) {
                *dst = f64::from_le_bytes(w);
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// Whether two paths name the same directory.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Merges tile sets into the array's output set in `out` (what `tofprobe simulate --out`
/// writes for the same configuration and seed). Refuses, naming the offending set: a
/// directory that is not a whole tile set or whose manifest does not hold, a different
/// design (maps included) or seed than the first set, a tile overlapping another set's,
/// and pixels in no set (naming the first pixel and the shares missing); `out` must not be
/// one of the sets. The output set is checked (size, lock, foreign files, disk) before any
/// tile's data is read.
pub fn merge_sets(
    dirs: &[PathBuf],
    out: &Path,
    limits: SetLimits,
) -> Result<ArraySummary, ArrayError> {
    let Some(first_dir) = dirs.first() else {
        return Err(ArrayError::Shape(
            "merge needs at least one tile set".into(),
        ));
    };
    if let Some(d) = dirs.iter().find(|d| same_dir(d, out)) {
        return Err(refuse(
            d,
            format!(
                "it is also --out {}: the merged set would replace the tile set it reads; write it elsewhere",
                out.display()
            ),
        ));
    }
    let first = read_manifest(first_dir)?;
    let bare0 = design_hash(&first.design)?;
    let a0 = first
        .design
        .array
        .clone()
        .ok_or_else(|| refuse(first_dir, "no [array]"))?;
    let (nr, nc) = (a0.rows, a0.cols);
    if dirs.len() > nr * nc {
        return Err(refuse(
            first_dir,
            format!(
                "{} sets for the {nr} × {nc} pixels of its array: some overlap",
                dirs.len()
            ),
        ));
    }
    // The first set's claims sized nothing until here: the coverage table is R × C of a
    // checked shape (≤ 4096², 4 bytes a pixel).
    let mut owner = vec![u32::MAX; nr * nc];
    // Each set's rectangle (its manifest checked and dropped: n sets hold n rectangles).
    let mut rects = Vec::with_capacity(dirs.len());
    let mut seconds = 0.0;
    for (i, dir) in dirs.iter().enumerate() {
        let m = if i == 0 {
            first.clone()
        } else {
            read_manifest(dir)?
        };
        if m.design_hash != first.design_hash || design_hash(&m.design)? != bare0 {
            return Err(refuse(
                dir,
                format!(
                    "a different design (hash {}) than {} (hash {}): the configuration, or a map \
                     image it reads, changed between the shards; merge sets of one design",
                    m.design_hash,
                    first_dir.display(),
                    first.design_hash
                ),
            ));
        }
        if m.seed != first.seed {
            return Err(refuse(
                dir,
                format!(
                    "seed {} differs from {}'s seed {}: merge sets of one seed",
                    m.seed,
                    first_dir.display(),
                    first.seed
                ),
            ));
        }
        let (name, name0) = (
            configuration_name(&m.design),
            configuration_name(&first.design),
        );
        if name != name0 {
            return Err(refuse(
                dir,
                format!(
                    "its configuration is named `{name}`, {}'s `{name0}` (the merged set names \
                     its configuration): merge the shards of one configuration file",
                    first_dir.display()
                ),
            ));
        }
        for r in m.rows.clone() {
            for c in m.cols.clone() {
                let cell = &mut owner[r * nc + c];
                if *cell != u32::MAX {
                    return Err(refuse(
                        dir,
                        format!(
                            "tile rows {:?} × cols {:?} overlaps {} at pixel ({r}, {c})",
                            m.rows,
                            m.cols,
                            dirs[*cell as usize].display()
                        ),
                    ));
                }
                *cell = i as u32;
            }
        }
        seconds += m.model_seconds;
        rects.push((m.rows, m.cols));
    }
    if let Some(p) = owner.iter().position(|&o| o == u32::MAX) {
        let count = usize::try_from(first.shard.count).unwrap_or(usize::MAX);
        let missing: Vec<String> = tiles(nr, nc, count)
            .map(|t| {
                t.iter()
                    .enumerate()
                    .filter(|(_, (rs, cs))| owner[rs.start * nc + cs.start] == u32::MAX)
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
    drop(owner);
    let mut design: ResolvedDesign = first.design.clone();
    let set = open_set(&design, out, limits)?;
    // The ROM before the frame: its construction's peak never meets the frame's.
    let rom = design.probe_rom()?;
    let k = first.registers_per_pixel;
    let mut frame = ArrayFrame {
        rows: nr,
        cols: nc,
        registers_per_pixel: k,
        registers: vec![0; nr * nc * k],
        detections: vec![0; nr * nc],
    };
    let spads = a0.spad_rows() * a0.spad_cols();
    let (mut signal, mut background) = (vec![0.0; spads], vec![0.0; spads]);
    for (dir, rect) in dirs.iter().zip(&rects) {
        read_into(
            dir,
            rect,
            &mut frame,
            [&mut signal, &mut background],
            a0.superpixel,
            a0.spad_cols(),
        )?;
    }
    if let Some(a) = design.array.as_mut() {
        a.signal_rate = signal;
        a.background_rate = background;
    }
    design.check_received()?;
    let joined = design_hash(&design)?;
    if joined != first.design_hash {
        return Err(refuse(
            first_dir,
            format!(
                "the rate maps the sets carry join into a design of hash {joined}, not the {} \
                 their manifests name: a map file was changed",
                first.design_hash
            ),
        ));
    }
    write_set(&design, rom.as_ref(), frame, seconds, set)
}
