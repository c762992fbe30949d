//! How many registers one adder can serve: each adder does one accumulate per clock, a
//! pulse leaves C = f_clk / f_laser cycles, so at f_max an adder serves ⌊f_max / f_laser⌋
//! registers. The configured schedule fits when C·f_laser ≤ f_max and ⌈P/A⌉ ≤ C.

use crate::error::{EdaError, Result};
use serde::{Deserialize, Serialize};

/// The throughput verdict.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Throughput {
    /// Laser rate (Hz).
    pub laser_rate_hz: f64,
    /// Maximum clock (MHz), from OpenSTA.
    pub f_max_mhz: f64,
    /// Cycles per pulse available at f_max: ⌊f_max / f_laser⌋ (= registers per adder).
    pub max_cycles_per_pulse: u64,
    /// Registers (operations per pulse) one adder can serve.
    pub registers_per_adder: u64,
    /// Adders needed for the configuration's P operations: ⌈P / max_cycles⌉ (0 if none fit).
    pub min_adders: u64,
    /// Configured cycles per pulse C.
    pub cycles_per_pulse: u64,
    /// Clock the configuration needs: C·f_laser (MHz).
    pub required_clock_mhz: f64,
    /// C·f_laser ≤ f_max and the schedule ⌈P/A⌉ fits in C.
    pub fits: bool,
    /// Human-readable verdict ("fits …" / "does not fit …").
    pub verdict: String,
}

/// Computes the verdict for P operations per pulse on A adders with C cycles per pulse.
pub fn throughput(
    f_max_mhz: f64,
    laser_rate_hz: f64,
    ops_per_pulse: u64,
    adders: u64,
    cycles_per_pulse: u64,
) -> Result<Throughput> {
    if !(laser_rate_hz.is_finite() && laser_rate_hz > 0.0) {
        return Err(EdaError::OutOfRange {
            field: "laser_rate_hz",
            value: laser_rate_hz.to_string(),
            allowed: "finite, > 0".into(),
        });
    }
    if !(f_max_mhz.is_finite() && f_max_mhz > 0.0) || adders == 0 || cycles_per_pulse == 0 {
        return Err(EdaError::OutOfRange {
            field: "f_max_mhz / adders / cycles_per_pulse",
            value: format!("{f_max_mhz} / {adders} / {cycles_per_pulse}"),
            allowed: "f_max > 0, A ≥ 1, C ≥ 1".into(),
        });
    }
    let max_cycles = (f_max_mhz * 1e6 / laser_rate_hz).floor() as u64;
    let required_clock_mhz = cycles_per_pulse as f64 * laser_rate_hz / 1e6;
    let slots = ops_per_pulse.div_ceil(adders);
    let clock_ok = required_clock_mhz <= f_max_mhz;
    let schedule_ok = slots <= cycles_per_pulse;
    let min_adders = if max_cycles == 0 {
        0
    } else {
        ops_per_pulse.div_ceil(max_cycles)
    };
    let verdict = if clock_ok && schedule_ok {
        format!(
            "fits: C = {cycles_per_pulse} cycles at {:.1} MHz need {required_clock_mhz:.1} MHz ≤ f_max {f_max_mhz:.1} MHz",
            laser_rate_hz / 1e6
        )
    } else if !clock_ok && max_cycles == 0 {
        format!(
            "does not fit: f_laser = {:.1} MHz exceeds f_max = {f_max_mhz:.1} MHz, not even one clock per pulse (C·f_laser = {required_clock_mhz:.1} MHz); no number of adders fits",
            laser_rate_hz / 1e6
        )
    } else if !clock_ok {
        format!(
            "does not fit: C·f_laser = {cycles_per_pulse} × {:.1} MHz = {required_clock_mhz:.1} MHz exceeds f_max = {f_max_mhz:.1} MHz; at most C = {max_cycles} cycles per pulse, so ≥ {} adders for {ops_per_pulse} operations",
            laser_rate_hz / 1e6,
            min_adders
        )
    } else {
        format!(
            "does not fit: {ops_per_pulse} operations on {adders} adders need {slots} cycles per pulse, C = {cycles_per_pulse}"
        )
    };
    Ok(Throughput {
        laser_rate_hz,
        f_max_mhz,
        max_cycles_per_pulse: max_cycles,
        registers_per_adder: max_cycles,
        min_adders,
        cycles_per_pulse,
        required_clock_mhz,
        fits: clock_ok && schedule_ok,
        verdict,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_16_bins_per_adder_at_10_mhz() {
        // Default: 32 registers on 2 adders, C = 16 at 10 MHz → 160 MHz clock. With
        // f_max = 288 MHz an adder serves ⌊288/10⌋ = 28 registers (≥ 16: the paper's claim).
        let t = throughput(288.0, 10e6, 32, 2, 16).unwrap();
        assert!(t.fits, "{}", t.verdict);
        assert_eq!(t.registers_per_adder, 28);
        assert_eq!(t.min_adders, 2);
        assert!((t.required_clock_mhz - 160.0).abs() < 1e-9);
    }

    #[test]
    fn too_slow_clock_does_not_fit() {
        let t = throughput(150.0, 10e6, 32, 2, 16).unwrap();
        assert!(!t.fits);
        assert!(t.verdict.starts_with("does not fit"), "{}", t.verdict);
        assert_eq!(t.max_cycles_per_pulse, 15);
        assert_eq!(t.min_adders, 3); // ⌈32/15⌉
        // Schedule too long even with a fast clock.
        let t = throughput(1000.0, 10e6, 32, 1, 16).unwrap();
        assert!(
            !t.fits && t.verdict.contains("need 32 cycles"),
            "{}",
            t.verdict
        );
        assert!(throughput(100.0, 0.0, 1, 1, 1).is_err());
    }
}
