//! The `[pixel]` configuration section and its validation into [`PixelParams`].
//!
//! Every key has a default, so an empty `[pixel]` (or none) gives the reference pixel:
//! Fourier, B = 16 bins, A = 2 adders (one per lane I and Q), C = 16 cycles per pulse,
//! S = 5 (α = 1/32), F = [`crate::DEFAULT_FRAC_BITS`], T from the sensor, N from the
//! acquisition, L = N (one windowed ROM period per frame), W from the sizing. Haar: U = 4.

use serde::{Deserialize, Serialize};

use crate::error::PixelError;
use crate::params::{MAX_WIDTH, Mode, PixelParams, ceil_log2};
use crate::sizing;

/// The `[pixel]` section as written in a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PixelConfig {
    /// `"fourier"` (default) or `"haar"`.
    pub mode: Mode,
    /// B: Fourier bins (default 16).
    pub bins: usize,
    /// Bin frequencies in Hz, one per bin; empty (default) = chosen from the scene by the
    /// probe design.
    pub frequencies_hz: Vec<f64>,
    /// U: finest Haar scale, registers 2^(U+1) − 1 (default 4: 31 registers).
    pub haar_scales: u32,
    /// A: adders shared over the registers (default 2).
    pub adders: usize,
    /// C: clock cycles per laser pulse (default 16).
    pub cycles_per_pulse: usize,
    /// T: TDC width in bits; default: the smallest that codes the sensor's window.
    pub tdc_bits: Option<u32>,
    /// Z: timing-window start in TDC codes, subtracted from every code (default 0).
    pub zoom: u32,
    /// S: prefilter shift, α = 2^−S (default 5).
    pub shift: u32,
    /// F: prefilter fraction bits (default [`crate::DEFAULT_FRAC_BITS`]).
    pub frac_bits: u32,
    /// W: register width in bits; default: the width the sizing requires.
    pub width: Option<u32>,
    /// N: pulses per frame; default: the whole acquisition.
    pub frame_pulses: Option<u64>,
    /// L: ROM depth in entries; default N.
    pub rom_depth: Option<usize>,
}

impl Default for PixelConfig {
    fn default() -> Self {
        PixelConfig {
            mode: Mode::Fourier,
            bins: 16,
            frequencies_hz: Vec::new(),
            haar_scales: 4,
            adders: 2,
            cycles_per_pulse: 16,
            tdc_bits: None,
            zoom: 0,
            shift: 5,
            frac_bits: crate::DEFAULT_FRAC_BITS,
            width: None,
            frame_pulses: None,
            rom_depth: None,
        }
    }
}

/// What the rest of the configuration tells the pixel: the sensor's window and rate, the
/// acquisition length and, if known, the codes the depth can take.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelContext {
    /// TDC codes in the timing window (the sensor's `tdc_codes()`).
    pub tdc_codes: u32,
    /// Laser pulse rate in Hz (bounds the bin frequencies).
    pub laser_rate_hz: f64,
    /// Pulses in the acquisition (the default frame length).
    pub pulses: u64,
    /// Codes the detections can take, inclusive; `None` = the whole window (the safe
    /// choice whenever background photons or jitter tails can land anywhere).
    pub code_range: Option<(u32, u32)>,
}

impl PixelConfig {
    /// Validates against the context and fills the defaults. Every error names the key, the
    /// reason and the nearest value that would work.
    pub fn resolve(&self, ctx: &PixelContext) -> Result<PixelParams, PixelError> {
        if ctx.tdc_codes == 0 {
            return Err(PixelError::mismatch(
                "sensor TDC codes in the window",
                0,
                "at least 1",
            ));
        }
        let t_min = ceil_log2(u64::from(ctx.tdc_codes)).max(1);
        let tdc_bits = match self.tdc_bits {
            None => t_min,
            Some(t) if t < t_min => {
                return Err(PixelError::invalid(
                    "tdc_bits",
                    t,
                    format!("the sensor's window has {} codes", ctx.tdc_codes),
                    t_min,
                ));
            }
            Some(t) => t,
        };
        let frame_pulses = self.frame_pulses.unwrap_or(ctx.pulses);
        let rom_depth = match self.rom_depth {
            Some(l) => l,
            None => usize::try_from(frame_pulses).unwrap_or(usize::MAX),
        };
        if self.mode == Mode::Fourier && !self.frequencies_hz.is_empty() {
            if self.frequencies_hz.len() != self.bins {
                return Err(PixelError::invalid(
                    "frequencies_hz",
                    format!("{} frequencies", self.frequencies_hz.len()),
                    format!("one frequency per bin (bins = {})", self.bins),
                    format!("bins = {}", self.frequencies_hz.len()),
                ));
            }
            let nyq = ctx.laser_rate_hz / 2.0;
            for &f in &self.frequencies_hz {
                if !(f.is_finite() && f > 0.0 && f < nyq) {
                    return Err(PixelError::invalid(
                        "frequencies_hz",
                        f,
                        format!("a bin must lie in (0, f_s/2 = {nyq} Hz)"),
                        if f.is_finite() {
                            f.clamp(0.0, nyq)
                        } else {
                            0.0
                        },
                    ));
                }
            }
        }
        let mut params = PixelParams {
            mode: self.mode,
            bins: self.bins,
            haar_scales: self.haar_scales,
            adders: self.adders,
            cycles_per_pulse: self.cycles_per_pulse,
            tdc_bits,
            zoom: self.zoom,
            shift: self.shift,
            frac_bits: self.frac_bits,
            width: MAX_WIDTH,
            frame_pulses,
            rom_depth,
        };
        // Everything but the width first, so the sizing below sees valid parameters.
        params.validate()?;
        let (lo, hi) = ctx.code_range.unwrap_or((0, ctx.tdc_codes - 1));
        let needed = sizing::required_width(&params, lo, hi, None);
        if needed > MAX_WIDTH {
            return Err(PixelError::invalid(
                "width",
                needed,
                format!(
                    "codes {lo}..={hi} over N = {frame_pulses} pulses need {needed}-bit registers, more than {MAX_WIDTH}; shorten the frame, lower frac_bits or zoom/centre the window"
                ),
                MAX_WIDTH,
            ));
        }
        params.width = match self.width {
            None => needed,
            Some(w) if w < needed => {
                return Err(PixelError::invalid(
                    "width",
                    w,
                    format!(
                        "codes {lo}..={hi} (zoom {}) over N = {frame_pulses} pulses can reach a final value that needs {needed} bits",
                        self.zoom
                    ),
                    needed,
                ));
            }
            Some(w) => w,
        };
        params.validate()?;
        Ok(params)
    }
}

impl PixelContext {
    /// The context of a sensor and an acquisition of `pulses` pulses: the window's codes
    /// and the laser rate; the code range is the whole window (background photons and
    /// jitter tails can land anywhere in it).
    pub fn from_sensor(sensor: &tofprobe_scene::SensorConfig, pulses: u64) -> Self {
        PixelContext {
            tdc_codes: sensor.tdc_codes(),
            laser_rate_hz: sensor.laser_rate_hz,
            pulses,
            code_range: None,
        }
    }
}
