//! A PNG of the routed macro: klayout in batch mode draws the GDS, every layer in its own
//! colour, on a white background, zoomed to the die.

use crate::error::{LayoutError, Result};
use crate::tools::{Tool, tail};
use std::path::Path;
use std::process::Command;

/// klayout's Python macro: `gds`, `png` and `size` come from `-rd`.
pub const SCRIPT: &str = "import pya
lv = pya.LayoutView()
lv.set_config('background-color', '#ffffff')
lv.set_config('grid-visible', 'false')
lv.load_layout(gds, 0)
lv.max_hier()
lv.add_missing_layers()
lv.zoom_fit()
lv.save_image(png, int(size), int(size))
";

/// Runs klayout in batch mode (Qt offscreen) on the Python macro `script` (written to
/// `path`) with `vars` given as `-rd NAME=VALUE`; `step` names the flow step in an error.
pub fn klayout(
    step: &'static str,
    script: &str,
    path: &Path,
    vars: &[(&str, String)],
) -> Result<std::process::Output> {
    let klayout = Tool::Klayout.locate()?;
    std::fs::write(path, script).map_err(|e| LayoutError::io("writing", path, e))?;
    let mut cmd = Command::new(&klayout);
    cmd.env("QT_QPA_PLATFORM", "offscreen").arg("-zz");
    for (k, v) in vars {
        cmd.arg("-rd").arg(format!("{k}={v}"));
    }
    let out = cmd
        .arg("-r")
        .arg(path)
        .output()
        .map_err(|e| LayoutError::io("running", &klayout, e))?;
    if !out.status.success() {
        return Err(LayoutError::ToolFailed {
            step,
            tool: "klayout",
            status: out
                .status
                .code()
                .map_or("killed".into(), |c| format!("exit {c}")),
            log: path.to_path_buf(),
            tail: tail(&String::from_utf8_lossy(&out.stderr), 10),
        });
    }
    Ok(out)
}

/// Draws `gds` into `png` (`size` × `size` pixels); the script is written to `dir`.
pub fn draw(gds: &Path, png: &Path, size: u32, dir: &Path) -> Result<()> {
    let out = klayout(
        "picture",
        SCRIPT,
        &dir.join("picture.py"),
        &[
            ("gds", gds.display().to_string()),
            ("png", png.display().to_string()),
            ("size", size.to_string()),
        ],
    )?;
    if !std::fs::read(png).is_ok_and(|b| b.starts_with(b"\x89PNG\r\n\x1a\n")) {
        return Err(LayoutError::ToolFailed {
            step: "picture",
            tool: "klayout",
            status: "no PNG written".into(),
            log: dir.join("picture.py"),
            tail: tail(&String::from_utf8_lossy(&out.stderr), 10),
        });
    }
    Ok(())
}
