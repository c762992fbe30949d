//! The pixel's analysis mode as the resolution decides it: `[pixel] mode = "auto"` picked
//! from the scene (`tofprobe_dsp::analysis_mode::mode_for_scene`: periodic motions →
//! Fourier, transients → Haar), U chosen when Haar is auto-picked, and the Haar frame's
//! checks (N a power of two, U ≤ log₂N − 1, no Fourier bin frequencies, transients inside
//! the frame) with errors and notes that name the field. Part of the one resolution, so
//! every command refuses or notes the same.

use tofprobe_dsp::analysis_mode::{AnalysisMode, ModeChoice, mode_for_scene};
use tofprobe_dsp::haar::checks::{check_frame_pulses, check_scales, transients_outside_frame};
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

/// Where N comes from, for the messages.
fn frame_field(d: &Document) -> &'static str {
    if d.pixel.frame_pulses.is_some() {
        "pixel.frame_pulses"
    } else {
        "acquisition.pulses (pixel.frame_pulses not set)"
    }
}

/// The Haar frame's checks: errors for N not a power of two (the nearest powers), U beyond
/// log₂N − 1 (the largest U that works) and Fourier bin frequencies given; notes for a
/// `[probe]` section that Haar does not read and for transients outside the frame.
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
    let mut notes = Vec::new();
    if d.probe != ProbeConfig::default() {
        notes.push(
            "[probe] is set but Haar mode reads no ΣΔ probe ROM: the section is ignored".into(),
        );
    }
    let frame_s = frame as f64 / d.sensor.laser_rate_hz;
    notes.extend(transients_outside_frame(&d.scene, frame_s));
    Ok(notes)
}
