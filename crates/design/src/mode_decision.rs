//! The pixel's analysis mode as the resolution decides it: `[pixel] mode = "auto"` picked
//! from the scene (`tofprobe_dsp::scene_analysis::mode_for_scene`: periodic motions →
//! Fourier, transients → Haar), U chosen when Haar is auto-picked, and the Haar frame's
//! checks (N a power of two, U ≤ log₂N − 1, no Fourier bin frequencies, transients inside
//! the frame) with errors and notes that name the field. Part of the one resolution, so
//! every command refuses or notes the same.

use tofprobe_dsp::haar::checks::{check_frame_pulses, check_scales, transients_outside_frame};
use tofprobe_dsp::scene_analysis::{AnalysisMode, ModeChoice, mode_for_scene};
use tofprobe_dsp::sd::ProbeConfig;
use tofprobe_pixel::config::{Choice, DEFAULT_HAAR_SCALES};
use tofprobe_pixel::{Mode, PixelConfig};

use crate::document::Document;
use crate::error::DesignError;

/// Finest scale an auto-picked Haar pixel gets when N allows it (127 registers, the
/// paper's Fig. 3 and Fig. 12).
pub const AUTO_HAAR_SCALES: u32 = 6;

/// How the mode was decided: the choice of `mode = "auto"` (why, and a note for a mixed
/// scene), or `None` when the document names the mode.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ModeDecision {
    /// The mode the pixel runs in.
    pub mode: Mode,
    /// `Some` when `mode = "auto"` decided it.
    pub auto: Option<ModeChoice>,
}

impl ModeDecision {
    /// One line for `simulate` and `config`: the mode and, when picked, why.
    pub fn line(&self) -> String {
        match &self.auto {
            None => format!("{} (pixel.mode)", self.mode),
            Some(c) => format!("{} (pixel.mode = \"auto\": {})", self.mode, c.reason),
        }
    }
}

/// Decides the mode and fills `px` with it; when Haar is auto-picked and U is not given,
/// U = min([`AUTO_HAAR_SCALES`], log₂N − 1) (N a power of two; other N are refused by
/// [`check_haar`] naming the nearest powers).
pub fn decide_mode(d: &Document, px: &mut PixelConfig, frame: u64) -> ModeDecision {
    let auto = match px.mode {
        Choice::Value(_) => None,
        Choice::Auto(_) => Some(mode_for_scene(&d.scene)),
    };
    let mode = match (&px.mode, &auto) {
        (Choice::Value(m), _) => *m,
        (_, Some(c)) if c.mode == AnalysisMode::Haar => Mode::Haar,
        _ => Mode::Fourier,
    };
    px.mode = Choice::Value(mode);
    if auto.is_some() && mode == Mode::Haar && px.haar_scales.is_none() && frame >= 4 {
        px.haar_scales = Some(AUTO_HAAR_SCALES.min(frame.ilog2() - 1));
    }
    ModeDecision { mode, auto }
}

/// The warning for a `[probe]` section in a Haar design: Haar mode reads no ΣΔ probe ROM, so
/// the section is accepted, not validated against the frame, and ignored (README). `None`
/// in Fourier mode or without the section. The commands print it on stderr
/// ([`crate::load`]).
pub fn ignored_probe_warning(d: &Document, mode: Mode) -> Option<String> {
    (mode == Mode::Haar && d.probe != ProbeConfig::default()).then(|| {
        "[probe] is set but pixel.mode is Haar, which reads no ΣΔ probe ROM: the probe section is ignored".to_string()
    })
}

/// Where N comes from, for the messages.
fn frame_field(d: &Document) -> &'static str {
    if d.pixel.frame_pulses.is_some() {
        "pixel.frame_pulses"
    } else if d.acquisition.pulses.is_some() {
        "acquisition.pulses (pixel.frame_pulses not set)"
    } else {
        "acquisition.duration_s × sensor.laser_rate_hz (pixel.frame_pulses not set)"
    }
}

/// The Haar frame's checks: errors for N not a power of two (the nearest powers), U beyond
/// log₂N − 1 (the largest U that works), Fourier bin frequencies given and a scene without
/// detections (its noise model fails, naming the keys); notes for transients outside the
/// frame. A `[probe]` section is ignored in Haar mode ([`ignored_probe_warning`]).
pub fn check_haar(
    d: &Document,
    px: &PixelConfig,
    decision: &ModeDecision,
    frame: u64,
    origin: &str,
) -> Result<Vec<String>, DesignError> {
    let how = if decision.auto.is_some() {
        " picked by pixel.mode = \"auto\""
    } else {
        ""
    };
    let err = |context: String, source| DesignError::Haar {
        place: format!("`{origin}`: [pixel] {context}"),
        source: Box::new(source),
    };
    check_frame_pulses(frame)
        .map_err(|e| err(format!("Haar mode{how}, N from {}", frame_field(d)), e))?;
    let u = px.haar_scales.unwrap_or(DEFAULT_HAAR_SCALES);
    check_scales(frame, u).map_err(|e| {
        err(
            format!(
                "Haar mode{how}, U from {}",
                if px.haar_scales.is_some() {
                    "pixel.haar_scales"
                } else {
                    "the default (pixel.haar_scales not set)"
                }
            ),
            e,
        )
    })?;
    if !px.frequencies_hz.is_empty() {
        return Err(DesignError::pixel(
            origin,
            tofprobe_pixel::PixelError::invalid(
                "frequencies_hz",
                format!("{} frequencies", px.frequencies_hz.len()),
                format!(
                    "Haar mode{how} has no frequency bins (its registers hold wavelet coefficients)"
                ),
                "leave pixel.frequencies_hz out, or set pixel.mode = \"fourier\"",
            ),
        ));
    }
    // The Haar analysis judges its coefficients against the noise of the static scene: a
    // scene that yields no detections (or no jitter) has none, and `simulate` could not run
    // it, so every command refuses it here, naming the keys (it used to pass `config`, `rtl`
    // and `vectors` and fail in `simulate` naming none).
    tofprobe_dsp::haar::HaarNoise::for_static_scene(&d.sensor, d.scene.depth_mm).map_err(|e| {
        err(
            format!(
                "Haar mode{how} judges its coefficients against the noise of the static scene, \
                 and that noise model (from sensor.signal_rate, sensor.background_rate, \
                 sensor.jitter_ps and the window around scene.depth_mm = {} mm) fails: it needs \
                 detections (sensor.signal_rate > 0 with the target in the window) and jitter \
                 (sensor.jitter_ps > 0); or set pixel.mode = \"fourier\"",
                d.scene.depth_mm
            ),
            e,
        )
    })?;
    let mut notes = Vec::new();
    let frame_s = frame as f64 / d.sensor.laser_rate_hz;
    notes.extend(transients_outside_frame(&d.scene, frame_s));
    Ok(notes)
}
