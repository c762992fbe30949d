//! `tofprobe simulate [CONFIG] [--json] [--svg PATH]`: run the photon/TDC Monte Carlo and
//! summarise the record (pulses, detections, background wins, mean and σ of the measured
//! depth, run time), then run one frame through the bit-true pixel (transaction model) and
//! print its spectrum at the configured bins (amplitude µm, phase, the noise estimate);
//! `--svg` plots that spectrum. On a Haar pixel the frame's registers become the transient
//! analysis instead (`tofprobe_experiments::transients`): coefficients, per-scale thresholds at a
//! stated false-alarm rate, events; `--json` carries the scalogram and the events, `--svg`
//! draws the scalogram.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use tofprobe_pixel::spectrum::BitTrueSpectrum;
use tofprobe_scene::{FillCounts, PhotonSource};

use tofprobe_design::ResolvedDesign;
use tofprobe_experiments::spectrum::{run_spectrum, setup, write_svg};
use tofprobe_experiments::transients::{HaarAnalysis, bit_true_haar};

use crate::error::CliError;

/// Pulses per streamed chunk (a multiple of the source's block, so nothing is regenerated).
const CHUNK: usize = 1 << 18;

/// Arguments of `tofprobe simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML); without it the embedded default (paper Fig. 8) is used.
    config: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Write an SVG plot of the bit-true spectrum (Haar: the scalogram) here (atomically).
    #[arg(long, value_name = "PATH")]
    svg: Option<PathBuf>,
}

/// One bin of the bit-true spectrum, as printed.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BinOut {
    /// Probe frequency, Hz.
    pub frequency_hz: f64,
    /// Amplitude, µm; `null` when the frame has no detections (an empty record has no
    /// spectrum, and 0 would read as a measured amplitude).
    pub amplitude_um: Option<f64>,
    /// Phase, degrees; `null` when the frame has no detections.
    pub phase_deg: Option<f64>,
}

/// The bit-true part of the output.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BitTrueOut {
    /// Register width W used.
    pub width_bits: u32,
    /// Pulses in the frame.
    pub frame_pulses: u64,
    /// One entry per bin, ROM order.
    pub bins: Vec<BinOut>,
    /// Median amplitude over the bins, µm (noise estimate when most bins hold no tone);
    /// `null` when the frame has no detections.
    pub noise_estimate_um: Option<f64>,
    /// Wall time of ROM generation (s).
    pub rom_seconds: f64,
    /// ROM organisation: "windowed" or "periodic".
    pub rom_mode: String,
    /// ROM depth L.
    pub rom_depth: usize,
    /// Periodic ROM: worst stream's in-band wrap error over its in-band quantisation
    /// error (0 for windowed; clean at ≤ 0.05).
    pub rom_wrap_error_ratio: f64,
    /// Whether the wrap is clean (always true for windowed).
    pub rom_wrap_clean: bool,
    /// The ROM's wrap phrase for the text output (`ProbeRom::wrap_summary`).
    #[serde(skip)]
    pub rom_wrap_summary: Option<String>,
    /// Wall time of the transaction-model frame (s).
    pub model_seconds: f64,
}

/// The JSON object of `simulate --json`: the record summary plus the bit-true spectrum.
#[derive(Debug, Clone, Serialize)]
struct Output<'a> {
    #[serde(flatten)]
    summary: &'a Summary,
    /// "fourier" or "haar", and why when `pixel.mode = "auto"` picked it.
    mode: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    mode_reason: Option<&'a str>,
    notes: &'a [String],
    #[serde(skip_serializing_if = "Option::is_none")]
    bit_true: Option<&'a BitTrueOut>,
    /// Haar mode: the frame's transient analysis (scalogram, thresholds, events).
    #[serde(skip_serializing_if = "Option::is_none")]
    haar: Option<&'a HaarOut>,
}

/// The Haar part of the output.
#[derive(Debug, Clone, Serialize)]
struct HaarOut {
    width_bits: u32,
    frame_pulses: u64,
    model_seconds: f64,
    #[serde(flatten)]
    analysis: HaarAnalysis,
}

/// The summary of one simulated record.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Pulses simulated.
    pub pulses: u64,
    /// Pulses with a detection.
    pub detections: u64,
    /// Detections won by a background photon.
    pub background_wins: u64,
    /// Detections / pulses.
    pub detection_rate: f64,
    /// Mean measured depth over detections (mm; code-bin centres); `null` without
    /// detections (an empty record has no mean, and 0 would read as a depth).
    pub mean_depth_mm: Option<f64>,
    /// Standard deviation of the measured depth (mm); `null` with fewer than two detections.
    pub sigma_depth_mm: Option<f64>,
    /// Wall-clock time of the simulation (s).
    pub seconds: f64,
}

/// Streams the record through a running sum; the progress bar appears on a terminal only
/// once the run has taken a second.
pub fn summarise(source: &PhotonSource, pulses: u64, progress: bool) -> Summary {
    let start = Instant::now();
    let bar = ProgressBar::with_draw_target(Some(pulses), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} pulses ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut shown = false;
    let mut counts = FillCounts::default();
    // Sums of code and code², exact in integers; depth is affine in the code.
    let (mut s1, mut s2) = (0u128, 0u128);
    let mut buf = vec![None; CHUNK];
    let mut first = 0u64;
    while first < pulses {
        let n = (pulses - first).min(CHUNK as u64) as usize;
        counts += source.fill_counted(first, &mut buf[..n]);
        for c in buf[..n].iter().flatten() {
            s1 += u128::from(*c);
            s2 += u128::from(*c) * u128::from(*c);
        }
        first += n as u64;
        if progress && !shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            shown = true;
        }
        bar.set_position(first);
    }
    bar.finish_and_clear();
    let d = counts.detections;
    let (mean_code, var_code) = if d == 0 {
        (0.0, 0.0)
    } else {
        let m = s1 as f64 / d as f64;
        let v = if d > 1 {
            // Integer form of the sum of squared deviations, then one division.
            let num = (d as u128 * s2 - s1 * s1) as f64;
            num / (d as f64 * (d - 1) as f64)
        } else {
            0.0
        };
        (m, v.max(0.0))
    };
    let lsb_mm = source.code_to_depth_mm(1) - source.code_to_depth_mm(0);
    Summary {
        pulses,
        detections: d,
        background_wins: counts.background_wins,
        detection_rate: d as f64 / pulses.max(1) as f64,
        mean_depth_mm: (d > 0).then(|| source.code_to_depth_mm(0) + mean_code * lsb_mm),
        sigma_depth_mm: (d > 1).then(|| var_code.sqrt() * lsb_mm),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let design = tofprobe_design::load(args.config.as_deref())?;
    let source = design.photon_source()?;
    let pulses = design.pulses();
    let progress = !args.json && std::io::stderr().is_terminal();
    let s = summarise(&source, pulses, progress);
    // The bit-true frame is the record's first N pulses (the same source and seed): a
    // record without detections leaves it empty too.
    let empty_frame = s.detections == 0 && design.pixel.frame_pulses <= s.pulses;
    let bit_true = bit_true(&design, &source, empty_frame)?;
    let haar = if design.pixel.mode == tofprobe_pixel::Mode::Haar {
        let (analysis, model_seconds) = bit_true_haar(&design)?;
        Some(HaarOut {
            width_bits: design.pixel.width,
            frame_pulses: design.pixel.frame_pulses,
            model_seconds,
            analysis,
        })
    } else {
        None
    };
    if let (Some(path), Some(h)) = (&args.svg, &haar) {
        tofprobe_experiments::scalogram::write_scalogram_svg(
            &h.analysis.scalogram,
            &format!("bit-true Haar scalogram: {}", design.origin),
            Some(&h.analysis.events),
            path,
        )?;
    } else if let (Some(path), Some((_, spectrum))) = (&args.svg, &bit_true) {
        write_svg(
            path,
            &format!("bit-true spectrum: {}", design.origin),
            spectrum,
        )?;
    } else if let Some(path) = &args.svg {
        return Err(CliError::output(
            path.clone(),
            "the spectrum plot needs pixel.mode = \"fourier\"".into(),
        ));
    }
    if args.json {
        let out = Output {
            summary: &s,
            mode: design.pixel.mode.to_string(),
            mode_reason: design.mode.auto.as_ref().map(|c| c.reason.as_str()),
            notes: &design.notes,
            bit_true: bit_true.as_ref().map(|b| &b.0),
            haar: haar.as_ref(),
        };
        println!("{}", serde_json::to_string(&out)?);
    } else {
        println!("configuration      {}", design.origin);
        println!("analysis mode      {}", design.mode.line());
        for n in &design.notes {
            println!("note               {n}");
        }
        println!("pulses             {}", s.pulses);
        println!(
            "detections         {} ({:.4} per pulse)",
            s.detections, s.detection_rate
        );
        println!("background wins    {}", s.background_wins);
        let stat =
            |x: Option<f64>, none: &str| x.map_or(none.to_string(), |v| format!("{v:.4} mm"));
        println!(
            "mean depth         {}",
            stat(s.mean_depth_mm, "none (no detections)")
        );
        println!(
            "sigma depth        {}",
            stat(s.sigma_depth_mm, "none (fewer than 2 detections)")
        );
        println!(
            "run time           {:.3} s ({:.1} M pulses/s)",
            s.seconds,
            s.pulses as f64 / s.seconds.max(1e-9) / 1e6
        );
        match (&bit_true, &haar) {
            (_, Some(h)) => {
                println!(
                    "bit-true Haar      W = {} bits, N = {} pulses, U = {} (model {:.2} s)",
                    h.width_bits, h.frame_pulses, h.analysis.scalogram.scales, h.model_seconds
                );
                print!("{}", h.analysis.text());
            }
            (None, None) => {}
            (Some((b, _)), None) => {
                println!(
                    "bit-true spectrum  W = {} bits, N = {} pulses (ROM {:.2} s, model {:.2} s)",
                    b.width_bits, b.frame_pulses, b.rom_seconds, b.model_seconds
                );
                let wrap = b
                    .rom_wrap_summary
                    .as_ref()
                    .map(|w| format!(", {w}"))
                    .unwrap_or_default();
                println!("  probe ROM {} L = {}{wrap}", b.rom_mode, b.rom_depth);
                match b.noise_estimate_um {
                    None => println!("  spectrum           none (no detections in the frame)"),
                    Some(noise) => {
                        println!("  frequency Hz   amplitude um    phase deg");
                        for bin in &b.bins {
                            println!(
                                "  {:>12.2} {:>14.4} {:>12.2}",
                                bin.frequency_hz,
                                bin.amplitude_um.unwrap_or(0.0),
                                bin.phase_deg.unwrap_or(0.0)
                            );
                        }
                        println!("  noise estimate {noise:.4} um (median over bins)");
                    }
                }
            }
        }
        if let Some(p) = &args.svg {
            if haar.is_some() {
                println!("scalogram plot     {}", p.display());
            } else {
                println!("spectrum plot      {}", p.display());
            }
        }
    }
    Ok(())
}

/// Runs the bit-true pixel over one frame (Fourier mode; `None` in Haar mode);
/// `empty_frame`: the frame has no detections, and its figures are absent, not 0.
fn bit_true(
    design: &ResolvedDesign,
    source: &PhotonSource,
    empty_frame: bool,
) -> Result<Option<(BitTrueOut, BitTrueSpectrum)>, CliError> {
    if design.pixel.mode != tofprobe_pixel::Mode::Fourier {
        return Ok(None);
    }
    let t0 = Instant::now();
    let setup = setup(design)?;
    let rom_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let lsb_mm = design.sensor().tdc_lsb_mm();
    let spectrum = run_spectrum(&setup, source, lsb_mm, &design.origin)?;
    let model_seconds = t1.elapsed().as_secs_f64();
    let out = BitTrueOut {
        width_bits: setup.params.width,
        frame_pulses: setup.params.frame_pulses,
        bins: spectrum
            .bins
            .iter()
            .map(|b| BinOut {
                frequency_hz: b.frequency_hz,
                amplitude_um: (!empty_frame).then_some(b.amplitude_um),
                phase_deg: (!empty_frame).then_some(b.phase_deg),
            })
            .collect(),
        noise_estimate_um: (!empty_frame).then_some(spectrum.median_amplitude_um),
        rom_seconds,
        rom_mode: setup.rom.mode.name().to_string(),
        rom_depth: setup.rom.depth(),
        rom_wrap_error_ratio: setup.rom.wrap_error_ratio,
        rom_wrap_clean: setup.rom.wrap_clean(),
        rom_wrap_summary: setup.rom.wrap_summary(),
        model_seconds,
    };
    Ok(Some((out, spectrum)))
}
