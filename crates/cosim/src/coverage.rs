//! Line coverage of the RTL under the co-simulation's stimuli: a Verilator build
//! with `--coverage-line` replays the same vectors, writes its counts (`harness --coverage
//! FILE`), and `verilator_coverage --annotate` marks every line holding a coverage point
//! that was never hit (`%000000`, with `--annotate-min 1`). Toggle coverage is not
//! counted: a reset input or a constant-width counter's top bits never toggle both ways. The pixel module's lines are reported: how many points'
//! lines were hit, and the text of each line that was not.

use crate::error::CosimError;
use crate::tools::require;
use crate::verilator::{self, BuildProfile};
use std::path::Path;
use std::process::Command;

/// Coverage of one generated file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Coverage {
    /// The annotated file (e.g. `tofprobe_pixel.v`).
    pub file: String,
    /// Lines holding at least one coverage point, and of those the ones all hit.
    pub lines: usize,
    pub covered: usize,
    /// (line number, source text) of every line with a point never hit.
    pub uncovered: Vec<(usize, String)>,
}

impl Coverage {
    pub fn percent(&self) -> f64 {
        if self.lines == 0 {
            100.0
        } else {
            100.0 * self.covered as f64 / self.lines as f64
        }
    }
}

/// Builds the coverage harness, replays `vec_dir` and annotates `file` of `rtl_dir`.
pub fn measure(
    rtl_dir: &Path,
    vec_dir: &Path,
    top: &str,
    work: &Path,
    x_seed: u64,
    file: &str,
) -> Result<Coverage, CosimError> {
    let tool = require("verilator_coverage")?;
    let b = verilator::build_with(rtl_dir, top, false, true, BuildProfile::Check)?;
    std::fs::create_dir_all(work).map_err(|e| CosimError::io(work, e))?;
    let dat = work.join("coverage.dat");
    let _ = std::fs::remove_file(&dat);
    let out = Command::new(&b.exe)
        .current_dir(rtl_dir)
        .arg(vec_dir)
        .arg("--coverage")
        .arg(&dat)
        .arg("+verilator+rand+reset+2")
        .arg(format!("+verilator+seed+{x_seed}"))
        .output()
        .map_err(|e| CosimError::io(&b.exe, e))?;
    if !dat.is_file() {
        return Err(CosimError::ToolFailed {
            tool: "verilator harness --coverage",
            status: out.status.to_string(),
            output: String::from_utf8_lossy(&out.stderr).into_owned(),
        });
    }
    let ann = work.join("annotated");
    let _ = std::fs::remove_dir_all(&ann);
    let out = Command::new(&tool)
        .arg("--annotate")
        .arg(&ann)
        .args(["--annotate-min", "1"])
        // A file whose every point was hit is written too (without it, 100% coverage
        // leaves no annotated file to read).
        .arg("--annotate-all")
        .arg(&dat)
        .output()
        .map_err(|e| CosimError::io(&tool, e))?;
    if !out.status.success() {
        return Err(CosimError::ToolFailed {
            tool: "verilator_coverage",
            status: out.status.to_string(),
            output: String::from_utf8_lossy(&out.stderr).into_owned(),
        });
    }
    let path = ann.join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| CosimError::io(&path, e))?;
    Ok(parse_annotated(file, &text))
}

/// Parses `verilator_coverage --annotate` output: a line with points starts with its
/// count, `%` marking one below the minimum (never hit), then the source text.
pub fn parse_annotated(file: &str, text: &str) -> Coverage {
    let mut c = Coverage {
        file: file.to_string(),
        lines: 0,
        covered: 0,
        uncovered: Vec::new(),
    };
    for (i, l) in text.lines().enumerate() {
        let head: String = l.chars().take(7).collect();
        let digits = head.trim_start_matches(['%', ' ', '~']);
        if head.len() < 7 || digits.is_empty() || !digits.chars().all(|ch| ch.is_ascii_digit()) {
            continue;
        }
        c.lines += 1;
        if head.starts_with('%') {
            c.uncovered.push((
                i + 1,
                l.chars().skip(7).collect::<String>().trim().to_string(),
            ));
        } else {
            c.covered += 1;
        }
    }
    c
}
