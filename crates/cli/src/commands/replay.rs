//! `tofprobe replay FILE [CONFIG] [--json]`: a real time-tagged record (PicoQuant PTU T2/T3,
//! Becker & Hickl SPC) through the pixel (`tofprobe_experiments::replay`): the record's photon
//! count and rates, the detected depth's mean and σ, and the bit-true spectrum beside its
//! float twin, with the measured noise floor against the closed form the record implies.

use std::path::PathBuf;

use clap::Args;
use tofprobe_experiments::replay::{ReplayOutcome, ReplayRequest, replay};

use crate::error::CliError;

/// Arguments of `tofprobe replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The record: a PicoQuant `.ptu` (T2 or T3) or a Becker & Hickl `.spc` file.
    pub file: PathBuf,
    /// Configuration (TOML): its sensor window, TDC LSB and frame quantise the record.
    /// Without it the sensor is fitted to the record (peak ± 8σ in 80 codes).
    pub config: Option<PathBuf>,
    /// T2 records: the channel whose events are the laser syncs (default: channel 0 on
    /// PicoHarp, the sync records on HydraHarp/TimeHarp).
    #[arg(long)]
    pub sync_channel: Option<u8>,
    /// Only photons of this channel (default: all).
    #[arg(long)]
    pub photon_channel: Option<u8>,
    /// The delay bin (T3) / time unit (T2) in seconds instead of the header's; required
    /// for SPC files (TAC range / ADC bins, from the `.set` file).
    #[arg(long)]
    pub resolution_s: Option<f64>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `tofprobe replay`.
pub fn run(a: &ReplayArgs) -> Result<(), CliError> {
    if let Some(r) = a.resolution_s
        && !(r.is_finite() && r > 0.0 && r <= 1.0)
    {
        return Err(CliError::option(
            "resolution-s",
            r,
            "0 < s ≤ 1 (seconds per bin)",
        ));
    }
    let design = match &a.config {
        Some(c) => {
            let d = crate::commands::load_design(Some(c))?;
            d.single_pixel("replay")?;
            Some(d)
        }
        None => None,
    };
    let req = ReplayRequest {
        sync_channel: a.sync_channel,
        photon_channel: a.photon_channel,
        resolution_s: a.resolution_s,
    };
    let out = replay(&a.file, design.as_ref(), &req)?;
    if a.json {
        println!("{}", serde_json::to_string(&json(&out)?)?);
    } else {
        print_text(&a.file, &out);
    }
    Ok(())
}

/// The JSON object: `ReplayOutcome` as is, except that a frame without detections has
/// no spectrum: each bin's `amplitude_um`, `float_amplitude_um` and `phase_deg` and the
/// `measured_floor_um` are `null` (0 would read as a measured amplitude).
fn json(o: &ReplayOutcome) -> Result<serde_json::Value, CliError> {
    let mut v = serde_json::to_value(o)?;
    if o.counts.detections == 0 {
        if let Some(bins) = v.get_mut("bins").and_then(|b| b.as_array_mut()) {
            for b in bins {
                for k in ["amplitude_um", "float_amplitude_um", "phase_deg"] {
                    b[k] = serde_json::Value::Null;
                }
            }
        }
        v["measured_floor_um"] = serde_json::Value::Null;
    }
    Ok(v)
}

fn opt(v: Option<f64>, unit: &str, digits: usize) -> String {
    v.map_or_else(|| "n/a".to_string(), |x| format!("{x:.digits$} {unit}"))
}

fn print_text(file: &std::path::Path, o: &ReplayOutcome) {
    let r = &o.record;
    println!("record: {} ({:?})", file.display(), r.format);
    println!(
        "  {} records, {} photons, {} syncs, {} markers, {} overflow records",
        r.counts.records,
        r.counts.photons,
        r.counts.syncs,
        r.counts.markers,
        r.counts.overflow_records
    );
    if let Some(f) = &o.fitted {
        println!(
            "  fitted: sync {:.6} MHz, {} pulses, return peak {:.1} ps after the sync, σ {:.1} ps (FWHM), photon per pulse {:.4}",
            f.sync_rate_hz / 1e6,
            f.pulses,
            f.peak_ps,
            f.sigma_ps,
            f.detection_rate_any
        );
    }
    println!("configuration: {}", o.configuration);
    println!(
        "window: {:.1} .. {:.1} ps, LSB {:.3} ps; frame {} pulses",
        o.window.window_start_ps,
        o.window.window_start_ps + o.window.window_length_ps,
        o.window.tdc_lsb_ps,
        o.frame_pulses
    );
    println!(
        "detections: {} in the window ({:.4} per pulse, ρ), {} photons outside it; depth mean {}, σ {}",
        o.counts.detections,
        o.detection_rate,
        o.counts.outside_window,
        opt(o.mean_depth_mm, "mm", 4),
        opt(o.sigma_depth_mm, "mm", 4)
    );
    if o.counts.detections == 0 {
        println!("bit-true spectrum: none (no detections in the window)");
        println!("noise floor: none (no detections)");
        return;
    }
    println!("bit-true spectrum (float twin and the closed-form floor at the bin beside):");
    for b in &o.bins {
        println!(
            "  {:>10.1} Hz  {:>10.4} µm  {:>8.2}°   float {:>10.4} µm   floor {}",
            b.frequency_hz,
            b.amplitude_um,
            b.phase_deg,
            b.float_amplitude_um,
            opt(b.closed_form_floor_um, "µm", 4)
        );
    }
    println!(
        "noise floor: measured (median over bins) {:.4} µm, closed form from ρ and σ (median over bins) {}; measured/closed form bin by bin, median over bins: {} (≈ 1 when the detections are independent per pulse and the bins hold no signal)",
        o.measured_floor_um,
        opt(o.closed_form_floor_um, "µm", 4),
        o.floor_ratio
            .map_or("n/a".to_string(), |x| format!("{x:.3}"))
    );
}
