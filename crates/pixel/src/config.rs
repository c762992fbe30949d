//! The `[pixel]` configuration section and its validation into [`PixelParams`].
//!
//! Every key has a default, so an empty `[pixel]` (or none) gives the reference pixel:
//! Fourier, B = 16 bins, A = 2 adders (one per lane I and Q), C = 16 cycles per pulse,
//! S = 5 (α = 1/32), F = [`crate::DEFAULT_FRAC_BITS`], T from the sensor, N from the
//! acquisition, L = N (one windowed ROM period per frame), W from the sizing. Haar: U =
//! [`DEFAULT_HAAR_SCALES`]. `mode = "auto"` is decided from the scene by the design's
//! resolution (`tofprobe_dsp::scene_analysis::mode_for_scene`) before this section resolves.

use serde::{Deserialize, Serialize};

use crate::autobins::choose_bins;
use crate::error::PixelError;
use crate::params::{MAX_WIDTH, Mode, PixelParams, RegisterFile, Rounding, ceil_log2};
use crate::sizing;

/// The keyword `"auto"` of a `[pixel]` key that can be chosen from the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AutoWord {
    /// Chosen from the scene.
    Auto,
}

/// A `[pixel]` value given explicitly (`bins = 16`) or chosen from the scene
/// (`bins = "auto"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Choice<T> {
    /// An explicit value.
    Value(T),
    /// `"auto"`: chosen from the scene.
    Auto(AutoWord),
}

impl<T> Choice<T> {
    /// The keyword form.
    pub const AUTO: Choice<T> = Choice::Auto(AutoWord::Auto);
}

/// The `[pixel]` section as written in a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PixelConfig {
    /// `"fourier"` (default), `"haar"`, or `"auto"`: Fourier for periodic motions, Haar
    /// for transients (decided by the design's resolution, which sees the scene).
    pub mode: Choice<Mode>,
    /// B: Fourier bins (default 16), or `"auto"`: the scene's in-band tones plus
    /// [`crate::autobins::AUTO_NOISE_BINS`] noise bins.
    pub bins: Choice<usize>,
    /// Bin frequencies in Hz, one per bin; empty (default) = chosen from the scene by the
    /// probe design.
    pub frequencies_hz: Vec<f64>,
    /// U: finest Haar scale, registers 2^(U+1) − 1 (default [`DEFAULT_HAAR_SCALES`]: 31
    /// registers; with `mode = "auto"` picking Haar, the design's resolution chooses).
    pub haar_scales: Option<u32>,
    /// A: adders shared over the registers (default 2), or `"auto"`: the fewest adders
    /// whose pixel meets the laser rate on `timing_liberty`, with C = ⌈P/A⌉ cycles per
    /// pulse, decided by the design's resolution from a measured f_max
    /// (`tofprobe_design::adders`); this section alone refuses it.
    pub adders: Choice<usize>,
    /// The liberty `adders = "auto"` times on: `"osu018"` (default, Debian's
    /// qflow-tech-osu018), `"sky130"` (the timed sky130_fd_sc_hd PDK's tt corner, found as
    /// `tofprobe size` finds it), `"sky130:ss"` / `"sky130:ff"` (its other corners; ss is
    /// the slowest) or a path to a liberty with timing.
    pub timing_liberty: Option<String>,
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
    /// How the prefilter's shift rounds: `"floor"` (default) or `"nearest"` (no bias,
    /// same widths).
    pub prefilter_rounding: Rounding,
    /// G: fraction bits of x kept in the registers' operand (default: all F); fewer
    /// narrow every register by F − G bits.
    pub register_frac_bits: Option<u32>,
    /// What the register file is built of: `"flops"` (default), `"clock_gated"` or `"latch"`.
    pub register_file: RegisterFile,
    /// W: register width in bits; default: what the whole timing window needs (safe with
    /// any background); `"auto"`: what the scene's code range needs.
    pub width: Option<Choice<u32>>,
    /// N: pulses per frame; default: the whole acquisition.
    pub frame_pulses: Option<u64>,
    /// L: ROM depth in entries; default N.
    pub rom_depth: Option<usize>,
}

impl Default for PixelConfig {
    fn default() -> Self {
        PixelConfig {
            mode: Choice::Value(Mode::Fourier),
            bins: Choice::Value(16),
            frequencies_hz: Vec::new(),
            haar_scales: None,
            adders: Choice::Value(2),
            timing_liberty: None,
            cycles_per_pulse: 16,
            tdc_bits: None,
            zoom: 0,
            shift: 5,
            frac_bits: crate::DEFAULT_FRAC_BITS,
            prefilter_rounding: Rounding::Floor,
            register_frac_bits: None,
            register_file: RegisterFile::Flops,
            width: None,
            frame_pulses: None,
            rom_depth: None,
        }
    }
}

/// U when `haar_scales` is not given (31 registers).
pub const DEFAULT_HAAR_SCALES: u32 = 4;

/// The ΣΔ OSR assumed when the context does not name one (the default `[probe]`).
pub const DEFAULT_OSR: f64 = 32.0;

/// What the rest of the configuration tells the pixel: the sensor's window and rate, the
/// acquisition length and, if known, the codes the depth can take.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PixelContext {
    /// TDC codes in the timing window (the sensor's `tdc_codes()`).
    pub tdc_codes: u32,
    /// Laser pulse rate in Hz (bounds the bin frequencies).
    pub laser_rate_hz: f64,
    /// Pulses in the acquisition (the default frame length).
    pub pulses: u64,
    /// Codes the detections can take, inclusive, for `width = "auto"`; `None` = unknown
    /// (then `"auto"` is refused: it needs the scene).
    pub code_range: Option<(u32, u32)>,
    /// The scene's tones (frequency Hz, amplitude mm), for `bins = "auto"`.
    pub tones: Vec<(f64, f64)>,
    /// The ΣΔ oversampling ratio: auto bins lie below f_s/(2·OSR).
    pub osr: f64,
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
        let mode = match self.mode {
            Choice::Value(m) => m,
            Choice::Auto(_) => {
                return Err(PixelError::invalid(
                    "mode",
                    "auto",
                    "choosing the mode needs the scene (the configuration's resolution decides it)",
                    "\"fourier\" or \"haar\"",
                ));
            }
        };
        let frame_pulses = self.frame_pulses.unwrap_or(ctx.pulses);
        let rom_depth = match self.rom_depth {
            Some(l) => l,
            None => usize::try_from(frame_pulses).unwrap_or(usize::MAX),
        };
        let bins = match self.bins {
            Choice::Value(b) => b,
            Choice::Auto(_) if mode == Mode::Haar => 1,
            Choice::Auto(_) => choose_bins(
                &ctx.tones,
                ctx.laser_rate_hz,
                rom_depth as u64,
                ctx.osr,
                None,
            )?
            .all()
            .len(),
        };
        if mode == Mode::Fourier && !self.frequencies_hz.is_empty() {
            if self.frequencies_hz.len() != bins {
                return Err(PixelError::invalid(
                    "frequencies_hz",
                    format!("{} frequencies", self.frequencies_hz.len()),
                    format!("one frequency per bin (bins = {bins})"),
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
        let adders = match self.adders {
            Choice::Value(a) => a,
            Choice::Auto(_) => {
                return Err(PixelError::invalid(
                    "adders",
                    "\"auto\"",
                    "\"auto\" is chosen from a synthesis of the pixel on a liberty: the design's \
                     resolution (tofprobe_design::resolve) decides it, the [pixel] section alone cannot",
                    "a number of adders, e.g. 2",
                ));
            }
        };
        if mode == Mode::Haar && self.prefilter_rounding != Rounding::Floor {
            return Err(PixelError::invalid(
                "prefilter_rounding",
                format!("\"{}\"", self.prefilter_rounding),
                "Haar mode has no prefilter (it accumulates the held depth itself)",
                "\"floor\" (or leave it out)",
            ));
        }
        if mode == Mode::Haar
            && let Some(g) = self.register_frac_bits
        {
            return Err(PixelError::invalid(
                "register_frac_bits",
                g,
                "Haar mode has no prefilter fraction: it accumulates the held depth itself",
                "leave it out",
            ));
        }
        let mut params = PixelParams {
            mode,
            bins,
            haar_scales: self.haar_scales.unwrap_or(DEFAULT_HAAR_SCALES),
            adders,
            cycles_per_pulse: self.cycles_per_pulse,
            tdc_bits,
            zoom: self.zoom,
            shift: self.shift,
            frac_bits: self.frac_bits,
            width: MAX_WIDTH,
            frame_pulses,
            rom_depth,
            prefilter_rounding: self.prefilter_rounding,
            register_frac_bits: self.register_frac_bits,
            register_file: self.register_file,
        };
        // Everything but the width first, so the sizing below sees valid parameters.
        params.validate()?;
        let (lo, hi) = match self.width {
            Some(Choice::Auto(_)) => ctx.code_range.ok_or_else(|| {
                PixelError::invalid(
                    "width",
                    "auto",
                    "sizing W from the scene needs the scene's code range",
                    "an explicit width, or leave it out to size for the whole window",
                )
            })?,
            _ => (0, ctx.tdc_codes - 1),
        };
        let needed = sizing::required_width(&params, lo, hi, None);
        if needed > MAX_WIDTH {
            return Err(PixelError::invalid(
                "width",
                needed,
                format!(
                    "codes {lo}..={hi} over N = {frame_pulses} pulses need {needed}-bit registers, more than {MAX_WIDTH}; shorten the frame, lower frac_bits or register_frac_bits, or zoom/centre the window"
                ),
                MAX_WIDTH,
            ));
        }
        params.width = match self.width {
            None | Some(Choice::Auto(_)) => needed,
            Some(Choice::Value(w)) if w < needed => {
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
            Some(Choice::Value(w)) => w,
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
            tones: Vec::new(),
            osr: DEFAULT_OSR,
        }
    }

    /// Adds what the scene tells: its tones, the ΣΔ OSR and the codes its detections can
    /// take (for `bins = "auto"` and `width = "auto"`).
    pub fn with_scene(mut self, tones: Vec<(f64, f64)>, osr: f64, codes: (u32, u32)) -> Self {
        self.tones = tones;
        self.osr = osr;
        self.code_range = Some(codes);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx() -> PixelContext {
        PixelContext {
            tdc_codes: 80,
            laser_rate_hz: 10e6,
            pulses: 10_000_000,
            code_range: None,
            tones: Vec::new(),
            osr: DEFAULT_OSR,
        }
    }

    /// `"auto"` parses for bins and width; explicit values still do; anything else is a
    /// parse error.
    /// `adders = "auto"` parses, and only the design's resolution (which can synthesise)
    /// decides it: the section alone refuses it naming the key and what works.
    #[test]
    fn auto_adders_parse_and_need_the_design() {
        let c: PixelConfig =
            toml::from_str("adders = \"auto\"\ntiming_liberty = \"sky130\"").unwrap();
        assert_eq!(c.adders, Choice::AUTO);
        assert_eq!(c.timing_liberty.as_deref(), Some("sky130"));
        let ctx = PixelContext {
            tdc_codes: 80,
            laser_rate_hz: 10e6,
            pulses: 4096,
            code_range: None,
            tones: vec![],
            osr: DEFAULT_OSR,
        };
        let msg = c.resolve(&ctx).unwrap_err().to_string();
        assert!(msg.contains("adders") && msg.contains("design"), "{msg}");
        let c: PixelConfig = toml::from_str("adders = 1").unwrap();
        assert_eq!(c.adders, Choice::Value(1));
        assert!(toml::from_str::<PixelConfig>("adders = \"many\"").is_err());
    }

    #[test]
    fn auto_and_explicit_values_parse() {
        let c: PixelConfig = toml::from_str("bins = \"auto\"\nwidth = \"auto\"").unwrap();
        assert_eq!((c.bins, c.width), (Choice::AUTO, Some(Choice::AUTO)));
        let c: PixelConfig = toml::from_str("bins = 8\nwidth = 40").unwrap();
        assert_eq!(
            (c.bins, c.width),
            (Choice::Value(8), Some(Choice::Value(40)))
        );
        assert!(toml::from_str::<PixelConfig>("bins = \"many\"").is_err());
        assert!(toml::from_str::<PixelConfig>("width = -3").is_err());
    }

    /// Fig. 8's tone (4.5 kHz, 30 mm ± 0.1 mm, no background) with σ = 0.75 mm: auto bins
    /// are the tone plus 4 noise bins; auto width sizes codes 35..44 (±4σ at 0.75 mm)
    /// instead of 0..79: 10^7·44·256 = 1.13·10^11 < 2^37 → 38 bits, one less than the
    /// whole window's 39 (10^7·79·256 = 2.02·10^11 > 2^37).
    #[test]
    fn auto_bins_and_width_from_the_scene() {
        let codes = crate::sizing::scene_code_range(29.9, 30.1, 0.75, 4.0, 0.0, 0.75, 80, false);
        assert_eq!(codes, (35, 44));
        let ctx = ctx().with_scene(vec![(4500.0, 0.1)], 32.0, codes);
        let c = PixelConfig {
            bins: Choice::AUTO,
            cycles_per_pulse: 16,
            width: Some(Choice::AUTO),
            ..PixelConfig::default()
        };
        let p = c.resolve(&ctx).unwrap();
        assert_eq!((p.bins, p.width), (5, 38));
        let whole = PixelConfig::default().resolve(&ctx).unwrap();
        assert_eq!(whole.width, 39);
        // Without the scene, "auto" width is refused with what to do instead.
        let e = c.resolve(&super::tests::ctx()).unwrap_err().to_string();
        assert!(
            e.contains("width = auto") && e.contains("explicit width"),
            "{e}"
        );
    }

    /// N = 2^27 through the sizing: codes 0..79 at F = 8 reach ±2^27·79·256 = ±2.7·10^12
    /// < 2^42 = 4.4·10^12 → 43 bits; 42 is refused naming 43; 2^50 pulses need more than
    /// the 63-bit maximum and are refused, never wrapped silently.
    #[test]
    fn n_2_27_sizes_and_one_bit_below_is_refused() {
        let mut ctx = ctx();
        ctx.pulses = 1 << 27;
        assert_eq!(PixelConfig::default().resolve(&ctx).unwrap().width, 43);
        let c = PixelConfig {
            width: Some(Choice::Value(42)),
            ..PixelConfig::default()
        };
        let e = c.resolve(&ctx).unwrap_err().to_string();
        assert!(
            e.contains("pixel.width = 42") && e.contains("nearest valid value: 43"),
            "{e}"
        );
        ctx.pulses = 1 << 50;
        // A periodic ROM (a windowed one, L = N = 2^50, is refused first: L ≤ 2^32).
        let periodic = PixelConfig {
            rom_depth: Some(1 << 16),
            ..PixelConfig::default()
        };
        let e = periodic.resolve(&ctx).unwrap_err().to_string();
        assert!(e.contains("more than 63"), "{e}");
        let e = PixelConfig::default()
            .resolve(&ctx)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rom_depth") && e.contains("4294967296"), "{e}");
    }
}
