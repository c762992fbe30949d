//! The Haar readout of a resolved design as a transient analysis (`simulate`, `flow`, the
//! trade-off): the pixel's registers (transaction model, cycle model or RTL readout — they
//! are equal, crates/pixel/tests/equivalence.rs and the co-simulation) → normalised
//! coefficients in mm (the scalogram) → per-scale thresholds from the closed-form noise of
//! the scene's static depth at a stated family-wise false-alarm rate → events (one per
//! transition: time, span, sign, the measured height, duration and mean rate — or a step's
//! bounds — and the paper's ramp-rate estimator, labelled as the paper's).
//!
//! Sign convention (the paper's): w > 0 when the depth is larger in the wavelet's first
//! half, i.e. a depth *decrease* gives a positive coefficient. Every rate is dδ/dt in m/s,
//! positive when the depth increases (`tofprobe_dsp::haar::events`).

use std::fmt::Write as _;
use std::time::Instant;

use serde::Serialize;
use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_dsp::haar::FAMILY_RATE;
use tofprobe_dsp::haar::checks::transient_span_s;
use tofprobe_dsp::haar::{EventReport, HaarNoise, Scalogram, Thresholds, detect_events};
use tofprobe_io::markdown::Table;
use tofprobe_pixel::fixed::sign_extend;
use tofprobe_pixel::{Mode, PixelError, PixelParams, TransactionModel};
use tofprobe_scene::PhotonSource;

use crate::error::ExperimentError;

/// Pulses per streamed chunk of the bit-true frame.
const CHUNK: usize = 1 << 16;

/// The threshold of one scale.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScaleThreshold {
    /// Scale u (0 = the whole frame).
    pub u: u32,
    /// Wavelet duration T/2^u (s).
    pub wavelet_s: f64,
    /// Largest sd(w) of the scale's coefficients (mm; equal over v for N = 2^k).
    pub sd_mm: f64,
    /// z·sd: |w| above this is significant (mm).
    pub threshold_mm: f64,
    /// Largest |w| of the scale (mm).
    pub max_abs_mm: f64,
}

/// One frame's transient analysis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HaarAnalysis {
    /// The coefficients with their times (register order).
    pub scalogram: Scalogram,
    /// The detected events and the stated false-alarm rate.
    pub events: EventReport,
    /// Per-scale thresholds.
    pub thresholds: Vec<ScaleThreshold>,
    /// Noise model: sd of one held depth sample (mm), quantisation included.
    pub noise_sample_sd_mm: f64,
    /// Noise model: probability that a pulse detects.
    pub noise_valid_rate: f64,
    /// The static depth the noise model assumes (the scene's δ0, mm).
    pub noise_depth_mm: f64,
    /// The scene's transients, [start, end] s (the truth the events are read against).
    pub scene_transients_s: Vec<[f64; 2]>,
}

/// The design's Haar pixel, or an error naming `pixel.mode`.
pub fn haar_params(design: &ResolvedDesign) -> Result<&PixelParams, ExperimentError> {
    if design.pixel.mode != Mode::Haar {
        return Err(DesignError::pixel(
            &design.origin,
            PixelError::mismatch("transient analysis mode", design.pixel.mode, "haar"),
        )
        .into());
    }
    Ok(&design.pixel)
}

/// Scalogram, thresholds and events of sign-extended registers read from a frame of
/// `pulses` pulses of the design's Haar pixel.
pub fn analyse_registers(
    design: &ResolvedDesign,
    registers: &[i64],
    pulses: u64,
) -> Result<HaarAnalysis, ExperimentError> {
    let p = haar_params(design)?;
    let sensor = design.sensor();
    let s = Scalogram::from_registers(
        registers,
        pulses,
        p.haar_scales,
        sensor.tdc_lsb_mm(),
        sensor.laser_rate_hz,
    )?;
    analyse_scalogram(design, s)
}

/// Thresholds and events of a scalogram of the design's scene (any level's: the float
/// Haar's too), under the closed-form noise of its static depth.
pub fn analyse_scalogram(
    design: &ResolvedDesign,
    s: Scalogram,
) -> Result<HaarAnalysis, ExperimentError> {
    let depth = design.document.scene.depth_mm;
    let noise = HaarNoise::for_static_scene(design.sensor(), depth)?;
    let n = usize::try_from(s.pulses).unwrap_or(usize::MAX);
    let t = Thresholds::new(&noise, n, s.scales, FAMILY_RATE)?;
    let events = detect_events(&s, &t)?;
    let thresholds = per_scale(&s, &t);
    Ok(HaarAnalysis {
        scalogram: s,
        events,
        thresholds,
        noise_sample_sd_mm: noise.sample_sd_mm,
        noise_valid_rate: noise.valid_rate,
        noise_depth_mm: depth,
        scene_transients_s: true_transients(design)
            .into_iter()
            .map(|(a, b)| [a, b])
            .collect(),
    })
}

/// [`analyse_registers`] of raw W-bit readout words (the cycle model's or the RTL's bus).
pub fn analyse_words(
    design: &ResolvedDesign,
    words: &[u64],
    width: u32,
    pulses: u64,
) -> Result<HaarAnalysis, ExperimentError> {
    let regs: Vec<i64> = words.iter().map(|&w| sign_extend(w, width)).collect();
    analyse_registers(design, &regs, pulses)
}

fn per_scale(s: &Scalogram, t: &Thresholds) -> Vec<ScaleThreshold> {
    (0..=s.scales)
        .map(|u| {
            let cs = s.scale(u);
            let sd = cs.iter().map(|c| t.sd_mm[c.register()]).fold(0.0, f64::max);
            ScaleThreshold {
                u,
                wavelet_s: s.wavelet_duration_s(u),
                sd_mm: sd,
                threshold_mm: t.z * sd,
                max_abs_mm: cs.iter().map(|c| c.value_mm.abs()).fold(0.0, f64::max),
            }
        })
        .collect()
}

/// The transaction model's Haar registers after one frame of `pulses` pulses of `source`
/// (streamed), and the model's wall time (s).
pub fn bit_true_registers(
    p: &PixelParams,
    source: &PhotonSource,
    pulses: u64,
) -> Result<(Vec<i64>, f64), PixelError> {
    let t = Instant::now();
    let mut tm = TransactionModel::new(p)?;
    let mut result = Ok(());
    source.for_each_chunk(pulses, CHUNK, |first, chunk| {
        if result.is_ok() {
            result = tm.run(chunk, None, first);
        }
    });
    result?;
    let words = tm.readout().words;
    Ok((words, t.elapsed().as_secs_f64()))
}

/// One frame of the design's photon source through the bit-true Haar pixel, analysed;
/// also the model's wall time (s).
pub fn bit_true_haar(design: &ResolvedDesign) -> Result<(HaarAnalysis, f64), ExperimentError> {
    let p = haar_params(design)?;
    let source = design.photon_source()?;
    let (regs, secs) = bit_true_registers(p, &source, p.frame_pulses)
        .map_err(|e| DesignError::pixel(&design.origin, e))?;
    Ok((analyse_registers(design, &regs, p.frame_pulses)?, secs))
}

/// The scene's transients as (start, end) s, in scene order (a step has start = end).
pub fn true_transients(design: &ResolvedDesign) -> Vec<(f64, f64)> {
    design
        .document
        .scene
        .motions
        .iter()
        .filter_map(transient_span_s)
        .collect()
}

impl HaarAnalysis {
    /// Text lines for `simulate`: the coefficients' summary, the thresholds and the events.
    pub fn text(&self) -> String {
        let s = &self.scalogram;
        let mut out = String::new();
        let big = s.largest();
        let _ = writeln!(
            out,
            "  {} coefficients, scales 0..{} ({:.1}x compression of {} pulses); sign: w > 0 = depth decreases (the paper's convention)",
            s.coefficients.len(),
            s.scales,
            s.compression_ratio(),
            s.pulses
        );
        let _ = writeln!(
            out,
            "  largest |w|: w({},{}) = {:+.4} mm over {:.3}–{:.3} ms",
            big.u,
            big.v,
            big.value_mm,
            big.start_s * 1e3,
            big.end_s * 1e3
        );
        let _ = writeln!(
            out,
            "  noise model: static depth {} mm, sample sd {:.4} mm, detection rate {:.4}; false-alarm probability {} per frame (z = {:.2})",
            self.noise_depth_mm,
            self.noise_sample_sd_mm,
            self.noise_valid_rate,
            self.events.family_rate,
            self.events.z
        );
        let _ = writeln!(
            out,
            "  scale  wavelet ms      max |w| mm   sd(w) mm   threshold mm"
        );
        for c in self.threshold_rows() {
            let _ = writeln!(
                out,
                "  {:>5} {:>11} {:>14} {:>10} {:>14}",
                c[0], c[1], c[2], c[3], c[4]
            );
        }
        for line in self.events.text().lines() {
            let _ = writeln!(out, "  {line}");
        }
        let _ = writeln!(out, "  scene transients: {}", self.scene_line());
        out
    }

    /// The per-scale threshold table's cells (scale, wavelet ms, max |w|, sd(w), threshold
    /// mm), formatted once for both the terminal and the Markdown table.
    fn threshold_rows(&self) -> impl Iterator<Item = [String; 5]> + '_ {
        self.thresholds.iter().map(|t| {
            [
                t.u.to_string(),
                format!("{:.4}", t.wavelet_s * 1e3),
                format!("{:.4}", t.max_abs_mm),
                format!("{:.5}", t.sd_mm),
                format!("{:.5}", t.threshold_mm),
            ]
        })
    }

    fn scene_line(&self) -> String {
        if self.scene_transients_s.is_empty() {
            return "none".into();
        }
        self.scene_transients_s
            .iter()
            .map(|[a, b]| {
                format!(
                    "{:.3}–{:.3} ms (centre {:.3} ms)",
                    a * 1e3,
                    b * 1e3,
                    0.5 * (a + b) * 1e3
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The flow report's section (Markdown).
    pub fn markdown(&self, svg: Option<&str>) -> String {
        let mut md = String::from("## Haar transient analysis (frame 0)\n\n");
        let _ = writeln!(
            md,
            "Registers normalised to coefficients w(u,v) in mm (register / wavelet length × TDC LSB); w > 0 = depth decreases (the paper's convention). Thresholds z·sd(w) from the closed-form noise of a static {} mm depth (sample sd {:.4} mm, detection rate {:.4}), family-wise false-alarm probability {} per frame (z = {:.2}).\n",
            self.noise_depth_mm,
            self.noise_sample_sd_mm,
            self.noise_valid_rate,
            self.events.family_rate,
            self.events.z
        );
        let mut t = Table::left([
            "scale",
            "wavelet (ms)",
            "max abs(w) (mm)",
            "sd(w) (mm)",
            "threshold (mm)",
        ]);
        for c in self.threshold_rows() {
            t.row(c);
        }
        md += &t.render();
        let _ = writeln!(md, "\n### Events\n");
        for line in self.events.text().lines() {
            let _ = writeln!(md, "- {line}");
        }
        let _ = writeln!(md, "\nScene transients: {}.", self.scene_line());
        if let Some(svg) = svg {
            let _ = writeln!(md, "\nScalogram: ![scalogram]({svg})");
        }
        md.push('\n');
        md
    }

    /// One line: the events (or none) and the largest coefficient.
    pub fn headline(&self) -> String {
        let big = self.scalogram.largest();
        format!(
            "{} Haar coefficients, {} event(s) at false-alarm probability {}; largest w({},{}) = {:+.4} mm",
            self.scalogram.coefficients.len(),
            self.events.events.len(),
            self.events.family_rate,
            big.u,
            big.v,
            big.value_mm
        )
    }
}

/// The flow report's Haar section from the co-simulated readout of frame 0 (raw W-bit
/// words, equal to the model's), with `scalogram.svg` written into `out`; returns the
/// headline.
pub fn flow_section(
    md: &mut String,
    design: &ResolvedDesign,
    p: &PixelParams,
    words: &[u64],
    out: &std::path::Path,
) -> Result<String, ExperimentError> {
    let regs = &words[..p.registers().min(words.len())];
    let a = analyse_words(design, regs, p.width, p.frame_pulses)?;
    let svg = out.join("scalogram.svg");
    crate::scalogram::write_scalogram_svg(
        &a.scalogram,
        &format!("Haar scalogram (co-simulated frame 0): {}", design.origin),
        Some(&a.events),
        &svg,
    )?;
    md.push_str(&a.markdown(Some("scalogram.svg")));
    Ok(a.headline())
}
