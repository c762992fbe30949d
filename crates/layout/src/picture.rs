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

/// Draws `gds` into `png` (`size` × `size` pixels); the script is written to `dir`.
pub fn draw(gds: &Path, png: &Path, size: u32, dir: &Path) -> Result<()> {
    let klayout = Tool::Klayout.locate()?;
    let script = dir.join("picture.py");
    std::fs::write(&script, SCRIPT).map_err(|e| LayoutError::io("writing", &script, e))?;
    let out = Command::new(&klayout)
        .env("QT_QPA_PLATFORM", "offscreen")
        .arg("-zz")
        .arg("-rd")
        .arg(format!("gds={}", gds.display()))
        .arg("-rd")
        .arg(format!("png={}", png.display()))
        .arg("-rd")
        .arg(format!("size={size}"))
        .arg("-r")
        .arg(&script)
        .output()
        .map_err(|e| LayoutError::io("running", &klayout, e))?;
    let ok = out.status.success()
        && std::fs::read(png).is_ok_and(|b| b.starts_with(b"\x89PNG\r\n\x1a\n"));
    if !ok {
        return Err(LayoutError::ToolFailed {
            step: "picture",
            tool: "klayout",
            status: out
                .status
                .code()
                .map_or("killed".into(), |c| format!("exit {c}")),
            log: script,
            tail: tail(&String::from_utf8_lossy(&out.stderr), 10),
        });
    }
    Ok(())
}
