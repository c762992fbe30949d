//! The `[probe]` configuration section: which ΣΔ modulator designs the probe bitstreams,
//! the window, the probe amplitude and how the ROM is organised.

use super::ntf::validate_design;
use crate::error::DspError;
use crate::window::Window;
use serde::{Deserialize, Serialize};

/// How the ROM spans a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RomMode {
    /// One windowed period per frame: depth L = N, bins f_k = k·f_s/N.
    #[default]
    Windowed,
    /// A rectangular periodic bitstream of depth L, bins f_k = k·f_s/L, a frame = M·L.
    Periodic,
}

impl RomMode {
    /// Name as used in configuration files and manifests.
    pub fn name(self) -> &'static str {
        match self {
            RomMode::Windowed => "windowed",
            RomMode::Periodic => "periodic",
        }
    }
}

/// How the probe waveform A·w\[n\]·cos/sin(2πkn/L) is written down (docs/probe.md). The
/// modulator is the same under both; only the input samples differ, by rounding and by
/// the window's symmetry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ProbeConvention {
    /// tofprobe's own (the default, which the committed RTL and vectors use): the
    /// periodic window w = f(2πn/L), whose L-point DFT leaks exactly like a periodic
    /// frame's, and Q = cos(θ − π/2), so I and Q share one rotator (its first Q sample is
    /// ≈ −4·10⁻³⁴, not 0).
    #[default]
    Tofprobe,
    /// The standard ΣΔ toolbox's (python-deltasigma / numpy): the symmetric window
    /// (`np.blackman(L)`, `np.hanning(L)`: f(2πn/(L − 1))) and Q = sin θ, exactly 0 at
    /// θ = 0; every sample evaluated directly, for a bit-for-bit comparison.
    Toolbox,
}

impl ProbeConvention {
    /// Name as used in configuration files and manifests.
    pub fn name(self) -> &'static str {
        match self {
            ProbeConvention::Tofprobe => "tofprobe",
            ProbeConvention::Toolbox => "toolbox",
        }
    }

    /// The values `probe.convention` accepts, for messages.
    pub const ALLOWED: &'static str = "\"tofprobe\" (the default) or \"toolbox\"";

    /// The convention named `name`, or an error naming the field, the value and the
    /// allowed values.
    pub fn parse(name: &str) -> Result<Self, DspError> {
        match name {
            "tofprobe" => Ok(ProbeConvention::Tofprobe),
            "toolbox" => Ok(ProbeConvention::Toolbox),
            _ => Err(DspError::out_of_range(
                "probe.convention",
                format!("{:?}", tofprobe_io::text::clip(name, 60)),
                Self::ALLOWED,
            )),
        }
    }

    /// w\[n\] of an L-point window under this convention: periodic (tofprobe) or symmetric
    /// as numpy evaluates it (toolbox).
    pub fn window_value(self, window: Window, n: usize, len: usize) -> f64 {
        match self {
            ProbeConvention::Tofprobe => window.value(n, len),
            ProbeConvention::Toolbox => window.symmetric_value(n, len),
        }
    }

    fn is_default(&self) -> bool {
        *self == ProbeConvention::default()
    }
}

impl<'de> Deserialize<'de> for ProbeConvention {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        ProbeConvention::parse(&name).map_err(serde::de::Error::custom)
    }
}

/// `[probe]`: the ΣΔ probe design.
///
/// The struct's default is the paper's windowed frame (L = N, Blackman), which
/// `reproduce` and the float references use; the embedded default configuration
/// (scenes/default.toml) stores the chip's periodic ROM instead (L = 20,000, rectangular).
///
/// `amplitude` is the probe amplitude A_p relative to the quantiser level ±1. The default
/// 0.5 is 65% of the default modulator's measured maximum stable amplitude (≈ 0.77), well
/// inside the accepted limit of 0.9 × that maximum (see `modulator::SAFETY_MARGIN`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProbeConfig {
    /// Modulator order Θ (1..=6).
    pub order: usize,
    /// Oversampling ratio: probes must lie below f_s / (2·OSR).
    pub osr: f64,
    /// Out-of-band NTF gain (1 < H_inf < 2^order; 1.5 is the Lee criterion).
    pub h_inf: f64,
    /// NTF zeros spread over the band (toolbox opt = 1) instead of all at DC.
    pub optimised_zeros: bool,
    /// Probe window (windowed mode; periodic mode is rectangular).
    pub window: Window,
    /// Probe amplitude A_p (0 < A_p < 1, and below 0.9 × the max stable amplitude).
    pub amplitude: f64,
    /// ROM organisation.
    pub rom_mode: RomMode,
    /// ROM depth L for the periodic mode (windowed mode uses L = N and ignores it).
    pub rom_depth: usize,
    /// How the probe waveform is written down (window symmetry, the sine's phase); not
    /// written out at its default, so documents and manifests without it stay as they were.
    #[serde(skip_serializing_if = "ProbeConvention::is_default")]
    pub convention: ProbeConvention,
}

impl Default for ProbeConfig {
    fn default() -> Self {
        ProbeConfig {
            order: 3,
            osr: 32.0,
            h_inf: 1.5,
            optimised_zeros: false,
            window: Window::Blackman,
            amplitude: 0.5,
            rom_mode: RomMode::Windowed,
            rom_depth: 1 << 16,
            convention: ProbeConvention::Tofprobe,
        }
    }
}

/// Deepest periodic ROM (2^21 entries), capped from the memory it needs as the windowed
/// ROM is (`tofprobe_design::MAX_WINDOWED_FRAME`, ≈ 400 MB): the periodic ROM is generated
/// whole with its wrap search, and `simulate` peaks at ≈ 160 bytes per entry (measured:
/// 168 MB at 2^20, 341 MB at 2^21, 543 MB at 2^22; 2^24 took 2 GB and 2^26 aborted out of
/// memory after 5 minutes). Bins 2^21 deep are f_s/2^21 apart (4.8 Hz at 10 MHz); finer
/// bins are a windowed ROM's (L = N).
pub const MAX_PERIODIC_ROM_DEPTH: usize = 1 << 21;

/// Smallest probe amplitude A_p accepted: 1 % of full scale, 40 dB down, where an order-1
/// OSR-4 design (the coarsest allowed) still keeps the probe above its in-band
/// quantisation noise.
pub const MIN_AMPLITUDE: f64 = 0.01;

impl ProbeConfig {
    /// Checks every field against its range (the amplitude against the modulator's
    /// measured stability limit is checked when a ROM is generated).
    pub fn validate(&self) -> Result<(), DspError> {
        validate_design(self.order, self.osr, self.h_inf)?;
        // The readout is divided by A_p: below MIN_AMPLITUDE the probe sinks into the
        // modulator's own in-band quantisation noise and the division blows that noise up
        // (1e-300 printed 10^300 µm, 5e-324 inf/NaN).
        if !(self.amplitude >= MIN_AMPLITUDE && self.amplitude < 1.0) {
            return Err(DspError::out_of_range(
                "probe.amplitude",
                tofprobe_io::text::number(self.amplitude),
                format!("{MIN_AMPLITUDE} <= amplitude < 1"),
            )
            .with_hint("0.5 suits the default order-3 design"));
        }
        if self.rom_mode == RomMode::Periodic && self.rom_depth < 16 {
            return Err(DspError::out_of_range(
                "probe.rom_depth",
                self.rom_depth,
                ">= 16 in periodic mode",
            ));
        }
        Ok(())
    }

    /// A periodic ROM restarts at address 0 every frame (docs/pixel-contract.md), so a frame
    /// must be a whole number of periods: otherwise every frame boundary is a phase jump
    /// of the probe and its bins are no longer orthogonal over the frame. The error gives
    /// the largest depth ≤ L that divides N and the nearest whole-period frame.
    ///
    /// First, a periodic ROM deeper than [`MAX_PERIODIC_ROM_DEPTH`] is refused with the
    /// deepest one that fits and divides N (so the divisor search below is bounded too).
    pub fn check_frame(&self, frame_pulses: u64) -> Result<(), DspError> {
        let l = self.rom_depth as u64;
        if self.rom_mode != RomMode::Periodic {
            return Ok(());
        }
        let largest_divisor = |at_most: u64| {
            (16..=at_most.min(frame_pulses))
                .rev()
                .find(|&d| frame_pulses.is_multiple_of(d))
        };
        if self.rom_depth > MAX_PERIODIC_ROM_DEPTH {
            let cap = MAX_PERIODIC_ROM_DEPTH as u64;
            let hint = match largest_divisor(cap) {
                Some(d) => format!(
                    "rom_depth = {d} (the deepest that fits and divides N = {frame_pulses})"
                ),
                None => format!("rom_depth <= {cap}"),
            };
            return Err(DspError::out_of_range(
                "probe.rom_depth",
                self.rom_depth,
                format!(
                    "16 <= rom_depth <= {cap} in periodic mode (the ROM is built whole: \
                     ≈ 160 bytes per entry, ≈ 340 MB at the limit)"
                ),
            )
            .with_hint(hint));
        }
        if l == 0 || frame_pulses.is_multiple_of(l) {
            return Ok(());
        }
        let divisor = largest_divisor(l);
        let periods = ((frame_pulses as f64 / l as f64).round() as u64).max(1);
        let mut hint = format!("a frame of {} pulses ({periods} period(s))", periods * l);
        if let Some(d) = divisor {
            hint = format!("rom_depth = {d} (divides N), or {hint}");
        }
        Err(DspError::out_of_range(
            "probe.rom_depth",
            self.rom_depth,
            format!(
                "a divisor of the frame N = {frame_pulses} pulses in periodic mode (the ROM address restarts every frame)"
            ),
        )
        .with_hint(hint))
    }

    /// ROM depth L for a frame of `frame_pulses` pulses.
    pub fn depth(&self, frame_pulses: u64) -> usize {
        match self.rom_mode {
            RomMode::Windowed => frame_pulses as usize,
            RomMode::Periodic => self.rom_depth,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_periodic_frame_must_be_whole_periods() {
        let c = ProbeConfig {
            rom_mode: RomMode::Periodic,
            rom_depth: 20_000,
            ..ProbeConfig::default()
        };
        c.check_frame(10_000_000).unwrap();
        c.check_frame(60_000).unwrap();
        let e = c.check_frame(65_536).unwrap_err().to_string();
        // 65536 = 2^16: its largest divisor ≤ 20000 is 16384; 65536/20000 ≈ 3 periods.
        assert!(e.contains("probe.rom_depth = 20000"), "{e}");
        assert!(
            e.contains("rom_depth = 16384") && e.contains("60000 pulses"),
            "{e}"
        );
        // Windowed ROMs are one frame deep by construction.
        ProbeConfig::default().check_frame(65_536).unwrap();
    }

    #[test]
    fn defaults_parse_and_unknown_fields_are_rejected() {
        let c: ProbeConfig = toml::from_str("").unwrap();
        assert_eq!(c, ProbeConfig::default());
        c.validate().unwrap();
        let c: ProbeConfig =
            toml::from_str("rom_mode = \"periodic\"\nrom_depth = 4096\nwindow = \"hann\"").unwrap();
        assert_eq!(c.rom_mode, RomMode::Periodic);
        assert_eq!(c.depth(10_000_000), 4096);
        assert!(toml::from_str::<ProbeConfig>("ordr = 3").is_err());
    }

    #[test]
    fn convention_parses_and_a_bad_one_names_field_value_and_allowed() {
        let c: ProbeConfig = toml::from_str("convention = \"toolbox\"").unwrap();
        assert_eq!(c.convention, ProbeConvention::Toolbox);
        assert_eq!(
            toml::from_str::<ProbeConfig>("").unwrap().convention,
            ProbeConvention::Tofprobe
        );
        let e = toml::from_str::<ProbeConfig>("convention = \"numpy\"")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("probe.convention = \"numpy\"")
                && e.contains("\"tofprobe\" (the default) or \"toolbox\""),
            "{e}"
        );
        // The default is not written out: documents and manifests keep their text.
        let text = toml::to_string(&ProbeConfig::default()).unwrap();
        assert!(!text.contains("convention"), "{text}");
        let text = toml::to_string(&ProbeConfig {
            convention: ProbeConvention::Toolbox,
            ..ProbeConfig::default()
        })
        .unwrap();
        assert!(text.contains("convention = \"toolbox\""), "{text}");
    }

    #[test]
    fn validation_names_field_value_and_range() {
        let bad = ProbeConfig {
            amplitude: 1.2,
            ..ProbeConfig::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("probe.amplitude = 1.2") && e.contains("0.01 <= amplitude < 1"),
            "{e}"
        );
        // The readout is divided by A_p: a vanishing amplitude is refused, not divided by.
        for tiny in [1e-300, 5e-324, 0.0099] {
            let e = ProbeConfig {
                amplitude: tiny,
                ..ProbeConfig::default()
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("probe.amplitude"), "{e}");
        }
        let bad = ProbeConfig {
            h_inf: 0.9,
            ..ProbeConfig::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("probe.h_inf = 0.9") && e.contains("1 < h_inf < 2^order = 8"),
            "{e}"
        );
    }
}
