//! The flow's sign-off (`tofprobe flow --signoff`): the co-simulated RTL synthesised on each
//! library found (osu018 always; sky130_fd_sc_hd when its PDK is found), the netlist replayed
//! through the same golden vectors at gate level (Icarus, the library's cell models) and
//! proven equivalent to the RTL (yosys). A gate-level mismatch or a failed proof is a FAIL
//! verdict; a missing tool is an error.

use std::path::Path;

use tofprobe_eda::EdaError;
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::signoff::{SignoffLibrary, SignoffRequest, sign_off};
use tofprobe_pixel::PixelParams;

use crate::error::FlowError;

/// Longest trace the gate-level replay takes (cycles): Icarus runs a 30k-cell netlist at a
/// few thousand cycles per second, so a 10^5-cycle trace is already tens of seconds per
/// library; the committed short frame (N = 64, 2 frames) is 2,119 cycles.
pub const MAX_SIGNOFF_CYCLES: u64 = 100_000;

/// One library's sign-off, or why it failed.
#[derive(Debug, Clone, PartialEq)]
pub struct SignoffLine {
    /// Library name (`osu018`, `sky130_fd_sc_hd`).
    pub library: String,
    /// Whether gate-level replay and equivalence both passed.
    pass: bool,
    /// One line for the report and the terminal.
    pub text: String,
}

impl SignoffLine {
    /// Whether gate-level replay and equivalence both passed.
    pub fn pass(&self) -> bool {
        self.pass
    }
}

/// Refuses a sign-off on a trace longer than [`MAX_SIGNOFF_CYCLES`], before any simulation:
/// `frames` frames of `p` take about frames·(N·C + R + 2) cycles.
pub fn check_length(p: &PixelParams, frames: u64) -> Result<(), FlowError> {
    let per_frame = p.frame_pulses * p.cycles_per_pulse as u64 + p.registers() as u64 + 2;
    let cycles = frames.saturating_mul(per_frame) + 3;
    if cycles > MAX_SIGNOFF_CYCLES {
        return Err(FlowError::option(
            "signoff",
            format!(
                "a {cycles}-cycle trace (N = {}, {frames} frame(s))",
                p.frame_pulses
            ),
            &format!(
                "at most {MAX_SIGNOFF_CYCLES} cycles of gate-level simulation: a short frame, e.g. --frame-pulses 64 --frames 2"
            ),
        ));
    }
    Ok(())
}

/// Signs off the RTL in `rtl_dir` (modules `tofprobe_top`, `tofprobe_pixel`) against the
/// vectors in `vec_dir` on every library found; synthesis and proofs under `work`.
pub fn sign_off_all(
    p: &PixelParams,
    laser_rate_hz: f64,
    rtl_dir: &Path,
    vec_dir: &Path,
    work: &Path,
) -> Result<Vec<SignoffLine>, FlowError> {
    // The simulator runs in the RTL directory ($readmemh finds the ROM image there), so
    // every path it is given must not depend on the caller's working directory.
    let abs = |d: &Path| {
        std::path::absolute(d).map_err(|e| FlowError::output(d.to_path_buf(), e.to_string()))
    };
    let (rtl_dir, vec_dir, work) = (&abs(rtl_dir)?, &abs(vec_dir)?, &abs(work)?);
    let mut libraries = vec![SignoffLibrary::osu018()];
    if let Some(pdk) = Sky130Pdk::discover(None)? {
        libraries.push(SignoffLibrary::sky130(&pdk, &work.join("pdk"))?);
    }
    // The clock the configuration needs: C·f_laser, as `size` maps.
    let delay_ps = 1e12 / (p.cycles_per_pulse as f64 * laser_rate_hz);
    let mut lines = Vec::new();
    for lib in &libraries {
        // A directory name yosys's script parser takes as one word ("sky130_fd_sc_hd
        // tt_025C_1v80" has a space).
        let cache = work.join(
            lib.name
                .replace(|c: char| !(c.is_ascii_alphanumeric() || c == '_'), "_"),
        );
        let req = SignoffRequest {
            rtl_dir,
            vec_dir,
            chip_top: "tofprobe_top",
            pixel: "tofprobe_pixel",
            library: lib,
            delay_target_ps: Some(delay_ps),
            cache: &cache,
        };
        let line = match sign_off(&req) {
            Ok(s) => SignoffLine {
                library: lib.name.clone(),
                pass: true,
                text: format!(
                    "{}: PASS: {} cells, {:.0} µm²; gate-level replay {} cycles, {} frame(s) bit-exact; equivalence proven on {} of {} points ({})",
                    lib.name,
                    s.cell_count,
                    s.total_area_um2,
                    s.gate_level.cycles,
                    s.gate_level.frames,
                    s.equivalence.proven,
                    s.equivalence.points,
                    tofprobe_io::text::sanitize(&s.netlist.display().to_string())
                ),
            },
            // A verdict, not an error: the netlist was checked and differs.
            Err(e @ (EdaError::GateLevelMismatch(_) | EdaError::NotEquivalent(_))) => SignoffLine {
                library: lib.name.clone(),
                pass: false,
                text: format!(
                    "{}: FAIL: {}",
                    lib.name,
                    tofprobe_io::text::sanitize(&e.to_string())
                ),
            },
            Err(e) => return Err(e.into()),
        };
        lines.push(line);
    }
    Ok(lines)
}
