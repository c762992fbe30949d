//! Timing per liberty and corner at the clock the configuration needs (C·f_laser): f_max,
//! slack, the critical path's ends, and the paper's question — how many registers one
//! adder serves at the laser rate — beside the paper's "≥ 16" claim.
//!
//! A netlist is mapped once, on the typical corner (ABC's delay-driven script), and the
//! same netlist is timed on every corner, as sign-off does: the cells are the same, only
//! their characterisation changes.

use crate::error::{EdaError, Result};
use crate::fsutil::cached_json;
use crate::pdk::{Sky130Pdk, plain_copy};
use crate::sta::{Timing, time_netlist};
use crate::synth::Synthesis;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The paper's claim: the adder is shared over at least 16 bins' registers at 10 MHz.
pub const PAPER_REGISTERS_PER_ADDER_MIN: u64 = 16;

/// The slack a corner must keep, as a percentage of the period, to count as closed.
pub const MARGIN_PERCENT: f64 = 10.0;

/// One liberty/corner's verdict (JSON: `timing_corners[]`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CornerTiming {
    /// `library (NAME)` of the liberty, e.g. `osu018_stdcells`, `sky130_fd_sc_hd__ss_n40C_1v40`.
    pub library: String,
    /// Corner name (`tt_025C_1v80`, ...; `typical` for a single-corner library).
    pub corner: String,
    /// The liberty file timed with.
    pub liberty: PathBuf,
    /// Register-to-register critical path (ns).
    pub critical_path_ns: f64,
    /// 1000 / critical_path_ns.
    pub f_max_mhz: f64,
    /// The clock the configuration needs, C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Clock period − critical path (ns); negative when the corner fails.
    pub slack_ns: f64,
    /// slack ≥ 0.
    pub meets_clock: bool,
    /// Slack as a percentage of the clock period (one decimal).
    pub slack_percent: f64,
    /// slack ≥ [`MARGIN_PERCENT`] % of the period: closed with the margin a design keeps
    /// for placement, routing and clock skew, which this synthesis-only timing omits.
    pub meets_margin: bool,
    /// Start of the critical path.
    pub startpoint: String,
    /// End of the critical path.
    pub endpoint: String,
    /// Cells on the critical path.
    pub path_cells: u32,
    /// ⌊f_max / f_laser⌋: registers one adder serves per laser pulse at this corner.
    pub registers_per_adder: u64,
    /// The paper's claim, [`PAPER_REGISTERS_PER_ADDER_MIN`], for comparison.
    pub paper_registers_per_adder_min: u64,
}

impl CornerTiming {
    /// The verdict of `sta` at `clock_mhz` for a laser at `laser_rate_hz`.
    pub fn new(
        library: &str,
        corner: &str,
        liberty: &Path,
        sta: &Timing,
        clock_mhz: f64,
        laser_rate_hz: f64,
    ) -> Self {
        let period = 1e3 / clock_mhz;
        // 4-digit rounding as OpenSTA prints: no binary noise in the JSON.
        let slack = ((period - sta.critical_path_ns) * 1e4).round() / 1e4;
        Self {
            library: library.to_string(),
            corner: corner.to_string(),
            liberty: liberty.to_path_buf(),
            critical_path_ns: sta.critical_path_ns,
            f_max_mhz: sta.f_max_mhz,
            clock_mhz,
            slack_ns: slack,
            meets_clock: slack >= 0.0,
            slack_percent: (slack / period * 1e3).round() / 10.0,
            meets_margin: slack >= period * MARGIN_PERCENT / 100.0,
            startpoint: sta.startpoint.clone(),
            endpoint: sta.endpoint.clone(),
            path_cells: sta.path_cells,
            registers_per_adder: (sta.f_max_mhz * 1e6 / laser_rate_hz).floor() as u64,
            paper_registers_per_adder_min: PAPER_REGISTERS_PER_ADDER_MIN,
        }
    }

    /// `Err(TimingFailed)` naming the corner, the violation and the path when it fails.
    pub fn require_met(&self) -> Result<()> {
        if self.meets_clock {
            return Ok(());
        }
        Err(EdaError::TimingFailed(Box::new(
            crate::error::TimingFailure {
                library: self.library.clone(),
                corner: self.corner.clone(),
                clock_mhz: self.clock_mhz,
                period_ns: 1e3 / self.clock_mhz,
                violation_ns: -self.slack_ns,
                critical_path_ns: self.critical_path_ns,
                f_max_mhz: self.f_max_mhz,
                startpoint: self.startpoint.clone(),
                endpoint: self.endpoint.clone(),
            },
        )))
    }
}

/// The first failing corner's error, if any (sign-off: every corner must meet the clock).
pub fn require_all_met(corners: &[CornerTiming]) -> Result<()> {
    corners.iter().try_for_each(CornerTiming::require_met)
}

/// Times `synthesis` (mapped on `liberty`) with OpenSTA, cached beside the netlist.
pub fn time_cached(
    synthesis: &Synthesis,
    liberty: &Path,
    corner: &str,
    clock: &str,
) -> Result<Timing> {
    let dir = synthesis
        .netlist_verilog
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let cached = dir.join(format!("timing-v3-{corner}.json"));
    cached_json(&cached, || {
        time_netlist(
            liberty,
            &synthesis.netlist_verilog,
            &synthesis.top,
            clock,
            &dir,
        )
    })
}

/// Every corner of `pdk` on a netlist mapped onto its typical corner. `typical` is the
/// typical corner's timing when the caller already has it.
pub fn sky130_corners(
    pdk: &Sky130Pdk,
    synthesis: &Synthesis,
    typical: Option<&Timing>,
    clock: &str,
    cache: &Path,
    clock_mhz: f64,
    laser_rate_hz: f64,
) -> Result<Vec<CornerTiming>> {
    let mut out = Vec::new();
    for (i, c) in pdk.corners.iter().enumerate() {
        let lib = plain_copy(&c.source, cache)?;
        let sta = match typical {
            Some(t) if i == 0 => t.clone(),
            _ => time_cached(synthesis, &lib, &c.name, clock)?,
        };
        out.push(CornerTiming::new(
            &format!("sky130_fd_sc_hd__{}", c.name),
            &c.name,
            &lib,
            &sta,
            clock_mhz,
            laser_rate_hz,
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sta(critical: f64) -> Timing {
        Timing {
            critical_path_ns: critical,
            f_max_mhz: 1e3 / critical,
            startpoint: "slot_reg".into(),
            endpoint: "y[7]_reg".into(),
            path_cells: 12,
        }
    }

    #[test]
    fn slack_and_registers_per_adder_follow_from_the_critical_path() {
        // 6.5317 ns → 153.1 MHz; at 160 MHz (6.25 ns) the slack is −0.2817 ns, and an
        // adder serves ⌊153.1 / 10⌋ = 15 registers per 10 MHz pulse: short of the paper's 16.
        let c = CornerTiming::new(
            "osu018",
            "typical",
            Path::new("x.lib"),
            &sta(6.5317),
            160.0,
            10e6,
        );
        assert!((c.slack_ns + 0.2817).abs() < 1e-12, "{}", c.slack_ns);
        assert!(!c.meets_clock);
        assert_eq!(c.registers_per_adder, 15);
        let msg = c.require_met().unwrap_err().to_string();
        for part in [
            "osu018",
            "typical",
            "0.282 ns",
            "slot_reg -> y[7]_reg",
            "160.0 MHz",
        ] {
            assert!(msg.contains(part), "`{part}` missing: {msg}");
        }
        // 4 ns → 250 MHz: meets 160 MHz with 2.25 ns to spare, 25 registers per adder.
        let ok = CornerTiming::new("sky", "ff", Path::new("y.lib"), &sta(4.0), 160.0, 10e6);
        assert!(ok.meets_clock && (ok.slack_ns - 2.25).abs() < 1e-12);
        assert_eq!(ok.registers_per_adder, 25);
        require_all_met(std::slice::from_ref(&ok)).unwrap();
        assert!(require_all_met(&[ok, c]).is_err());
    }
}
