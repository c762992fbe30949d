//! The stages the simulator skips when the scene does not exercise them (issue 8, point 2),
//! each timed with the skip and without it on the same frame, the median of several runs:
//!
//! - background sampling: the photon source at ρ_b = 0 against ρ_b = 10^−12 (which forces
//!   the Poisson background draw per pulse while changing the record negligibly);
//! - the hold: the bit-true model at ρ_s = 1 (every pulse detects, the hold never engages)
//!   against ρ_s = 1 − 10^−7;
//! - only the configured bins: the streamed B-bin DFT against the full N-point FFT, both
//!   on the same held record;
//! - no full DFT unless asked: the bit-true model alone (what `tofprobe simulate` runs)
//!   against the bit-true model plus the held record and its full FFT.

use serde::Serialize;
use tofprobe_dsp::dft::amplitude_spectrum;
use tofprobe_dsp::selected_bins::SelectedBins;
use tofprobe_io::markdown::Table;
use tofprobe_pixel::spectrum::bit_true_spectrum;

use super::overrides::{shortened, with_overrides};
use super::timing::median_seconds;
use crate::references::dft_bins;
use tofprobe_design::{DesignError, ProbeCache, ResolvedDesign};

use crate::error::ExperimentError;
use crate::records::{detection_record, held_record};
use crate::spectrum::{BitTrueSetup, setup};

/// ρ_b that forces the background path while adding ~10^−5 photons to a 10^7-pulse frame.
pub const TINY_BACKGROUND: f64 = 1e-12;
/// ρ_s just below 1: the hold path is live, ~1 missed pulse per 10^7.
pub const ALMOST_ONE_SIGNAL: f64 = 1.0 - 1e-7;

/// One skipped stage: wall seconds per frame with the skip and without it.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SkipRow {
    /// The stage skipped.
    pub stage: String,
    /// What is compared (with the skip vs without it).
    pub comparison: String,
    /// Median wall seconds per frame with the stage skipped.
    pub seconds_with_skip: f64,
    /// Median wall seconds per frame with the stage run.
    pub seconds_without_skip: f64,
    /// seconds_without_skip / seconds_with_skip (> 1: the skip pays).
    pub speedup_ratio: f64,
}

/// The skip measurements of one scene.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SkipReport {
    /// Where the scene came from.
    pub origin: String,
    /// Pulses per timed frame.
    pub pulses: u64,
    /// True when the frame is shorter than the scene's.
    pub shortened: bool,
    /// Runs per timing (the median is reported).
    pub reps: usize,
    /// One row per stage.
    pub stages: Vec<SkipRow>,
}

fn row(stage: &str, comparison: &str, with: f64, without: f64) -> SkipRow {
    SkipRow {
        stage: stage.to_string(),
        comparison: comparison.to_string(),
        seconds_with_skip: with,
        seconds_without_skip: without,
        speedup_ratio: if with > 0.0 { without / with } else { 1.0 },
    }
}

/// Times each skip on `design` shortened to at most `pulses`, `reps` runs per timing.
/// The scene's own ρ_s and ρ_b are replaced by the pair compared.
pub fn measure_skips(
    design: &ResolvedDesign,
    pulses: u64,
    reps: usize,
) -> Result<SkipReport, ExperimentError> {
    let (config, origin) = (&design.document, design.origin.as_str());
    let base = shortened(config, pulses);
    let n = base.pulses();
    let mut cache = ProbeCache::default();
    let mut rate = |rho_s: f64, rho_b: f64| -> Result<ResolvedDesign, ExperimentError> {
        with_overrides(
            &base,
            &format!("{origin} with rho_s = {rho_s}, rho_b = {rho_b}"),
            &[
                ("sensor.signal_rate", &format!("{rho_s:e}")),
                ("sensor.background_rate", &format!("{rho_b:e}")),
            ],
            &mut cache,
        )
    };
    let clean = rate(1.0, 0.0)?;
    let with_bg = rate(1.0, TINY_BACKGROUND)?;
    let with_hold = rate(ALMOST_ONE_SIGNAL, 0.0)?;
    let mut stages = Vec::new();

    // Background sampling: the photon source alone.
    let fill = |c: &ResolvedDesign| -> Result<f64, ExperimentError> {
        let src = c.photon_source()?;
        let mut codes = vec![None; usize::try_from(n).unwrap_or(usize::MAX)];
        median_seconds(reps, || {
            src.fill_counted(0, &mut codes);
            Ok::<(), ExperimentError>(())
        })
    };
    stages.push(row(
        "background sampling",
        "photon source at rho_b = 0 vs rho_b = 1e-12",
        fill(&clean)?,
        fill(&with_bg)?,
    ));

    // The hold: the bit-true model on the same ROM.
    let su: BitTrueSetup = setup(&clean)?;
    let lsb = clean.sensor().tdc_lsb_mm();
    let bit_true = |c: &ResolvedDesign| -> Result<f64, ExperimentError> {
        let src = c.photon_source()?;
        median_seconds(reps, || {
            bit_true_spectrum(&su.params, &su.rom, &src, lsb)
                .map(|_| ())
                .map_err(|source| ExperimentError::from(DesignError::pixel(origin, source)))
        })
    };
    let bt_clean = bit_true(&clean)?;
    stages.push(row(
        "hold (every pulse detects)",
        "bit-true model at rho_s = 1 vs rho_s = 1 - 1e-7",
        bt_clean,
        bit_true(&with_hold)?,
    ));

    // Only the configured bins: B-bin streamed DFT vs the full FFT on one record.
    let src = clean.photon_source()?;
    let codes = detection_record(&src, n);
    let depths = held_record(&src, &codes, 0.0)?;
    let bins = dft_bins(&su.rom.bin_indices, n, su.params.rom_depth);
    let window = su.rom.window;
    let dsp_err = |source| ExperimentError::from(DesignError::probe(origin, source));
    let selected = median_seconds(reps, || {
        let mut sel = SelectedBins::new(n, &bins, window).map_err(dsp_err)?;
        for chunk in depths.chunks(1 << 16) {
            sel.push(chunk).map_err(dsp_err)?;
        }
        sel.amplitudes().map(|_| ()).map_err(dsp_err)
    })?;
    let full = median_seconds(reps, || {
        amplitude_spectrum(&depths, window)
            .map(|_| ())
            .map_err(dsp_err)
    })?;
    stages.push(row(
        "only the configured bins",
        &format!(
            "float DFT at the B = {} ROM bins vs full N-point FFT",
            bins.len()
        ),
        selected,
        full,
    ));

    // No full DFT unless asked: the record and the FFT on top of the bit-true model.
    let record = median_seconds(reps, || {
        let d = held_record(&src, &detection_record(&src, n), 0.0)?;
        amplitude_spectrum(&d, window).map(|_| ()).map_err(dsp_err)
    })?;
    stages.push(row(
        "full DFT (not asked)",
        "bit-true model alone vs bit-true + held record + full FFT",
        bt_clean,
        bt_clean + record,
    ));

    Ok(SkipReport {
        origin: origin.to_string(),
        pulses: n,
        shortened: n < config.pulses(),
        reps: reps.max(1),
        stages,
    })
}

/// The Markdown table of the skips.
pub fn markdown(r: &SkipReport) -> String {
    let mut t = Table::left([
        "stage skipped",
        "compared",
        "with skip s",
        "without s",
        "speedup",
    ]);
    for s in &r.stages {
        t.row([
            s.stage.to_string(),
            s.comparison.to_string(),
            format!("{:.4}", s.seconds_with_skip),
            format!("{:.4}", s.seconds_without_skip),
            format!("{:.2}×", s.speedup_ratio),
        ]);
    }
    format!(
        "### Skipped stages: {} (N = {}{}, median of {} runs)\n\n{t}",
        r.origin,
        r.pulses,
        if r.shortened { ", shortened frame" } else { "" },
        r.reps
    )
}
