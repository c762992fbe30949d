//! The timed sky130 PDK (sky130_fd_sc_hd): where its liberties and cell models are, and
//! plain copies of its gzipped liberties in the cache (yosys and OpenSTA read plain text).
//!
//! Search order, first hit wins (documented in docs/size-report-schema.md):
//! 1. an explicit directory (the CLI's `--sky130-pdk DIR`);
//! 2. `$TOFPROBE_SKY130_PDK`;
//! 3. [`VENDORED`], `third_party/sky130_fd_sc_hd` in this checkout (the liberties, cell
//!    models and layout files the code uses, gzipped, Apache-2.0: its README.md says where
//!    they come from), so a fresh clone times, signs off and lays out on sky130;
//! 4. `/usr/share/pdk/sky130A/libs.ref/sky130_fd_sc_hd/lib` (an open_pdks install: what a
//!    build whose checkout has moved away, e.g. an installed wheel, can still find).
//!
//! A directory qualifies when it holds `sky130_fd_sc_hd__tt_025C_1v80.lib` (or `.lib.gz`).
//! When none does, the area-only liberty of [`crate::sky130`] is the fallback.

use crate::error::{EdaError, Result};
use crate::fsutil::{Fnv64, write_atomic};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The environment variable naming the PDK directory.
pub const PDK_ENV: &str = "TOFPROBE_SKY130_PDK";

/// The corners the report times, typical first (the one the netlist is mapped for).
pub const CORNERS: [&str; 3] = ["tt_025C_1v80", "ss_n40C_1v40", "ff_100C_1v95"];

/// One timing corner of the library.
#[derive(Debug, Clone, PartialEq)]
pub struct Corner {
    /// `tt_025C_1v80`, `ss_n40C_1v40`, ...
    pub name: String,
    /// The liberty as found (maybe gzipped).
    pub source: PathBuf,
}

/// A located sky130_fd_sc_hd PDK directory.
#[derive(Debug, Clone, PartialEq)]
pub struct Sky130Pdk {
    /// The directory.
    pub dir: PathBuf,
    /// Corners found, typical first.
    pub corners: Vec<Corner>,
    /// Cell Verilog models (`sky130_fd_sc_hd.v` or `.v.gz`), if present.
    pub cell_models: Option<PathBuf>,
    /// The UDPs the cell models instantiate (`primitives.v`), if present.
    pub primitives: Option<PathBuf>,
}

/// The vendored PDK's directory, relative to the project root.
pub const VENDORED: &str = "third_party/sky130_fd_sc_hd";

/// The project root (the workspace directory of this checkout).
pub fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The PDK vendored in this checkout ([`VENDORED`] under [`project_root`]).
pub fn vendored() -> PathBuf {
    project_root().join(VENDORED)
}

/// The directories searched after an explicit one and the environment variable.
pub fn search_path() -> Vec<PathBuf> {
    vec![
        vendored(),
        PathBuf::from("/usr/share/pdk/sky130A/libs.ref/sky130_fd_sc_hd/lib"),
    ]
}

fn either(dir: &Path, stem: &str) -> Option<PathBuf> {
    [dir.join(stem), dir.join(format!("{stem}.gz"))]
        .into_iter()
        .find(|p| p.is_file())
}

impl Sky130Pdk {
    /// Reads the PDK in `dir`; None when it holds no typical-corner liberty.
    pub fn at(dir: &Path) -> Option<Self> {
        let corners: Vec<Corner> = CORNERS
            .iter()
            .filter_map(|c| {
                either(dir, &format!("sky130_fd_sc_hd__{c}.lib")).map(|source| Corner {
                    name: (*c).to_string(),
                    source,
                })
            })
            .collect();
        if corners.first().is_none_or(|c| c.name != CORNERS[0]) {
            return None;
        }
        let models_dir = dir.join("../verilog");
        Some(Self {
            dir: dir.to_path_buf(),
            corners,
            cell_models: either(dir, "sky130_fd_sc_hd.v")
                .or_else(|| either(&models_dir, "sky130_fd_sc_hd.v")),
            primitives: either(dir, "primitives.v").or_else(|| either(&models_dir, "primitives.v")),
        })
    }

    /// Finds the PDK: `explicit` (an error if it is not a PDK directory), then
    /// `$TOFPROBE_SKY130_PDK` (likewise), then [`search_path`]. `Ok(None)`: not installed.
    pub fn discover(explicit: Option<&Path>) -> Result<Option<Self>> {
        let named = explicit
            .map(|p| (p.to_path_buf(), "--sky130-pdk"))
            .or_else(|| std::env::var_os(PDK_ENV).map(|p| (PathBuf::from(p), PDK_ENV)));
        if let Some((dir, origin)) = named {
            return Self::at(&dir).map(Some).ok_or_else(|| EdaError::OutOfRange {
                field: "sky130 PDK directory",
                value: format!("{} (from {origin})", dir.display()),
                allowed: format!(
                    "a directory holding sky130_fd_sc_hd__{}.lib or .lib.gz (e.g. the vendored {})",
                    CORNERS[0],
                    vendored().display()
                ),
            });
        }
        Ok(search_path().iter().find_map(|d| Self::at(d)))
    }

    /// The typical corner's plain liberty (decompressed into `cache` if gzipped).
    pub fn typical(&self, cache: &Path) -> Result<PathBuf> {
        plain_copy(&self.corners[0].source, cache)
    }

    /// The plain liberty of the corner whose name starts with `prefix` (`tt`, `ss`, `ff`,
    /// or a whole name such as `ss_n40C_1v40`); `Ok(None)` when this PDK has no such corner.
    pub fn corner(&self, prefix: &str, cache: &Path) -> Result<Option<PathBuf>> {
        match self.corners.iter().find(|c| c.name.starts_with(prefix)) {
            Some(c) if !prefix.is_empty() => plain_copy(&c.source, cache).map(Some),
            _ => Ok(None),
        }
    }

    /// The names of the corners this PDK holds, typical first.
    pub fn corner_names(&self) -> Vec<&str> {
        self.corners.iter().map(|c| c.name.as_str()).collect()
    }
}

/// `path` itself when it is plain text, else its decompressed copy under
/// `cache/pdk/<hash>/<name>` (made once, atomically; `gzip -dc` does the work).
pub fn plain_copy(path: &Path, cache: &Path) -> Result<PathBuf> {
    if path.extension().is_none_or(|e| e != "gz") {
        return Ok(path.to_path_buf());
    }
    let meta = std::fs::metadata(path).map_err(|e| EdaError::LibertyUnreadable {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "liberty".into());
    // Keyed by the file's path, size and mtime: cheap, and a replaced file gets a new copy.
    let mut h = Fnv64::default();
    h.feed(path.as_os_str().as_encoded_bytes())
        .feed(&meta.len().to_le_bytes());
    if let Ok(t) = meta.modified()
        && let Ok(d) = t.duration_since(std::time::UNIX_EPOCH)
    {
        h.feed(&d.as_nanos().to_le_bytes());
    }
    let out = cache.join("pdk").join(h.hex()).join(&name);
    if out.is_file() {
        return Ok(out);
    }
    let run = Command::new("gzip")
        .arg("-dc")
        .arg(path)
        .output()
        .map_err(|e| EdaError::io("running gzip -dc on", path, e))?;
    if !run.status.success() {
        return Err(EdaError::LibertyUnreadable {
            path: path.to_path_buf(),
            reason: format!(
                "gzip -dc failed: {}",
                String::from_utf8_lossy(&run.stderr).trim()
            ),
        });
    }
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).map_err(|e| EdaError::io("creating", dir, e))?;
    }
    write_atomic(&out, &run.stdout)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_without_the_typical_corner_is_not_a_pdk() {
        let dir = std::env::temp_dir().join(format!("tofprobe-pdk-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(Sky130Pdk::at(&dir).is_none());
        let msg = Sky130Pdk::discover(Some(&dir)).unwrap_err().to_string();
        assert!(
            msg.contains(&dir.display().to_string()) && msg.contains("tt_025C_1v80"),
            "{msg}"
        );
        std::fs::write(
            dir.join("sky130_fd_sc_hd__tt_025C_1v80.lib"),
            "library (x) {}",
        )
        .unwrap();
        let pdk = Sky130Pdk::at(&dir).unwrap();
        assert_eq!(pdk.corners.len(), 1);
        assert_eq!(pdk.typical(&dir).unwrap(), pdk.corners[0].source);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
