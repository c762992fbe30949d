//! One array simulation as one output set (whole or absent, `tofprobe_io::OutputSet`,
//! `summary.json` written last as its completion file): the registers as `registers.npy`
//! (int64 [R, C, K]) and the detections (`detections.npy`, [R, C]); for a Fourier frame
//! `amplitude_um.npy` and `phase_deg.npy` ([B, R, C]), a heat map of amplitude and of phase
//! per bin, each pixel's strongest bin, the animated deflection shape at the dominant bin
//! and the Universal File Format file `vibration.uff`; for a Haar frame each pixel's
//! transition time (`event_time_ms.npy`, −1 where none, and its heat map) and the edge
//! velocity fitted from them; the summary with its figures, units
//! and file names.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_io::npy;

use crate::error::ArrayError;
use crate::events::{EventMap, event_map};
use crate::maps::{VibrationMaps, fourier_maps};
use crate::model::{ArrayFrame, run_array};
use crate::plot::{Scale, deflection_animation_svg, heat_map_svg};

/// One bin's figures over the array.
#[derive(Debug, Clone, Serialize)]
pub struct BinSummary {
    pub index: usize,
    pub frequency_hz: f64,
    pub mean_amplitude_um: f64,
    pub max_amplitude_um: f64,
}

/// The summary of an array run (`summary.json`, and `simulate --json`).
#[derive(Debug, Clone, Serialize)]
pub struct ArraySummary {
    pub configuration: String,
    pub mode: String,
    pub rows: usize,
    pub cols: usize,
    pub pitch_um: f64,
    pub mm_per_pixel: f64,
    /// G: a pixel is G × G SPADs whose detections it averages (1: one SPAD).
    pub superpixel: usize,
    pub frame_pulses: u64,
    pub registers_per_pixel: usize,
    pub mean_detections_per_pixel: f64,
    pub bins: Vec<BinSummary>,
    pub dominant_bin: Option<usize>,
    pub dominant_frequency_hz: Option<f64>,
    /// Haar: pixels with a transition, and the edge's speed (mm/s) and direction (degrees
    /// from +x towards +y) from the plane fit of their times (`events`).
    pub event_pixels: Option<usize>,
    pub edge_velocity_mm_per_s: Option<f64>,
    pub edge_direction_deg: Option<f64>,
    /// Wall time of the array model (all pixels), s, and its rate in pixel-pulses/s.
    pub model_seconds: f64,
    pub pixel_pulses_per_s: f64,
    /// The files of the set, `summary.json` last.
    pub files: Vec<String>,
}

/// Runs the array of `design` and returns the frame, the maps (Fourier) and the summary
/// (its `files` empty: nothing is written).
pub fn simulate(
    design: &ResolvedDesign,
) -> Result<(ArrayFrame, Option<VibrationMaps>, ArraySummary), ArrayError> {
    simulate_all(design).map(|(f, m, _, s)| (f, m, s))
}

/// A simulated frame with what is read from it: the registers, the vibration maps
/// (Fourier), the Haar event map and the summary.
pub type Simulated = (
    ArrayFrame,
    Option<VibrationMaps>,
    Option<EventMap>,
    ArraySummary,
);

/// [`simulate`] with the Haar event map.
fn simulate_all(design: &ResolvedDesign) -> Result<Simulated, ArrayError> {
    let rom = design.probe_rom()?;
    let t0 = Instant::now();
    let frame = run_array(design, rom.as_ref().map(|r| &r.image))?;
    finish(design, rom.as_ref(), frame, t0.elapsed().as_secs_f64())
}

/// The maps, the Haar events and the summary of a frame that took `model_seconds` to run
/// (one run, or merged tiles); `rom` is the design's probe ROM (`None` in Haar mode).
pub fn finish(
    design: &ResolvedDesign,
    rom: Option<&ProbeRom>,
    frame: ArrayFrame,
    model_seconds: f64,
) -> Result<Simulated, ArrayError> {
    let Some(a) = &design.array else {
        return Err(ArrayError::Shape(format!(
            "`{}` has no [array] section",
            design.origin
        )));
    };
    if (frame.rows, frame.cols) != (a.rows, a.cols) {
        return Err(ArrayError::Shape(format!(
            "a {} × {} frame for the {} × {} array of `{}`",
            frame.rows, frame.cols, a.rows, a.cols, design.origin
        )));
    }
    let maps = match rom {
        Some(rom) => Some(fourier_maps(design, rom, &frame)?),
        None => None,
    };
    let events = maps.is_none().then(|| event_map(design, &frame));
    let pixels = (frame.rows * frame.cols) as f64;
    let bins = maps
        .as_ref()
        .map(|m| {
            (0..m.bins())
                .map(|b| BinSummary {
                    index: b,
                    frequency_hz: m.frequencies_hz[b],
                    mean_amplitude_um: m.mean_amplitude(b),
                    max_amplitude_um: m.amplitude(b).iter().copied().fold(0.0, f64::max),
                })
                .collect()
        })
        .unwrap_or_default();
    let summary = ArraySummary {
        configuration: design.origin.clone(),
        mode: design.pixel.mode.to_string(),
        rows: a.rows,
        cols: a.cols,
        pitch_um: a.pitch_um,
        mm_per_pixel: a.mm_per_pixel,
        superpixel: a.superpixel,
        frame_pulses: design.pixel.frame_pulses,
        registers_per_pixel: frame.registers_per_pixel,
        mean_detections_per_pixel: frame.detections.iter().sum::<u64>() as f64 / pixels,
        bins,
        dominant_bin: maps.as_ref().map(|m| m.dominant_bin),
        dominant_frequency_hz: maps.as_ref().map(|m| m.frequencies_hz[m.dominant_bin]),
        event_pixels: events.as_ref().map(|e| e.pixels),
        edge_velocity_mm_per_s: events.as_ref().and_then(|e| e.velocity_mm_per_s),
        edge_direction_deg: events.as_ref().and_then(|e| e.direction_deg),
        model_seconds,
        pixel_pulses_per_s: pixels * design.pixel.frame_pulses as f64 / model_seconds.max(1e-9),
        files: Vec::new(),
    };
    Ok((frame, maps, events, summary))
}

/// The files of the set, in order, without the summary.
pub fn files(
    design: &ResolvedDesign,
    frame: &ArrayFrame,
    maps: Option<&VibrationMaps>,
    events: Option<&EventMap>,
) -> Result<Vec<(String, Vec<u8>)>, ArrayError> {
    let (r, c) = (frame.rows, frame.cols);
    let io = |name: &str, e: String| ArrayError::Output {
        path: name.into(),
        message: e,
    };
    let mut out = vec![
        (
            "registers.npy".to_string(),
            npy::to_bytes(&[r, c, frame.registers_per_pixel], &frame.registers)
                .map_err(|e| io("registers.npy", e.to_string()))?,
        ),
        (
            "detections.npy".to_string(),
            npy::to_bytes(
                &[r, c],
                &frame
                    .detections
                    .iter()
                    .map(|&d| d as i64)
                    .collect::<Vec<_>>(),
            )
            .map_err(|e| io("detections.npy", e.to_string()))?,
        ),
    ];
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    if let Some(e) = events {
        out.push((
            "event_time_ms.npy".into(),
            npy::to_bytes(&[r, c], &e.time_ms)
                .map_err(|x| io("event_time_ms.npy", x.to_string()))?,
        ));
        // Pixels without a transition (−1) drawn as 0 ms.
        let shown: Vec<f64> = e.time_ms.iter().map(|&t| t.max(0.0)).collect();
        out.push((
            "event_time.svg".into(),
            heat_map_svg(
                "transition time per pixel",
                "time (ms)",
                &shown,
                r,
                c,
                mm,
                Scale::Amplitude,
            )
            .map_err(|x| io("event_time.svg", x))?
            .into_bytes(),
        ));
    }
    let Some(m) = maps else {
        return Ok(out);
    };
    let b = m.bins();
    out.push((
        "amplitude_um.npy".into(),
        npy::to_bytes(&[b, r, c], &m.amplitude_um)
            .map_err(|e| io("amplitude_um.npy", e.to_string()))?,
    ));
    out.push((
        "phase_deg.npy".into(),
        npy::to_bytes(&[b, r, c], &m.phase_deg).map_err(|e| io("phase_deg.npy", e.to_string()))?,
    ));
    for k in 0..b {
        let f = m.frequencies_hz[k];
        for (kind, unit, values, scale) in [
            (
                "amplitude",
                "amplitude (µm)",
                m.amplitude(k),
                Scale::Amplitude,
            ),
            ("phase", "phase (degrees)", m.phase(k), Scale::Phase),
        ] {
            let name = format!("{kind}_bin{k:02}.svg");
            let svg = heat_map_svg(
                &format!("{kind} at {f:.1} Hz (bin {k})"),
                unit,
                values,
                r,
                c,
                mm,
                scale,
            )
            .map_err(|e| io(&name, e))?;
            out.push((name, svg.into_bytes()));
        }
    }
    let strongest: Vec<f64> = m.strongest_bin.iter().map(|&k| k as f64).collect();
    out.push((
        "strongest_bin.svg".into(),
        heat_map_svg(
            "strongest bin per pixel",
            "bin index",
            &strongest,
            r,
            c,
            mm,
            Scale::Index,
        )
        .map_err(|e| io("strongest_bin.svg", e))?
        .into_bytes(),
    ));
    let d = m.dominant_bin;
    out.push((
        "deflection.svg".into(),
        deflection_animation_svg(
            &format!(
                "deflection shape at {:.1} Hz (bin {d}), one period per second",
                m.frequencies_hz[d]
            ),
            m.amplitude(d),
            m.phase(d),
            r,
            c,
        )
        .into_bytes(),
    ));
    out.push((
        "vibration.uff".into(),
        crate::uff::write(design, m).into_bytes(),
    ));
    Ok(out)
}

/// Runs the array and writes its set into `dir` (whole or absent); returns the summary.
pub fn run_and_write(design: &ResolvedDesign, dir: &Path) -> Result<ArraySummary, ArrayError> {
    let rom = design.probe_rom()?;
    let t0 = Instant::now();
    let frame = run_array(design, rom.as_ref().map(|r| &r.image))?;
    write_set(design, rom.as_ref(), frame, t0.elapsed().as_secs_f64(), dir)
}

/// Writes the set of a frame that took `model_seconds` to run (one run, or merged tiles:
/// `shard::merge_sets`) into `dir` (whole or absent); returns the summary.
pub fn write_set(
    design: &ResolvedDesign,
    rom: Option<&ProbeRom>,
    frame: ArrayFrame,
    model_seconds: f64,
    dir: &Path,
) -> Result<ArraySummary, ArrayError> {
    let (frame, maps, events, mut summary) = finish(design, rom, frame, model_seconds)?;
    let files = files(design, &frame, maps.as_ref(), events.as_ref())?;
    let out_err = |e: std::io::Error| ArrayError::Output {
        path: dir.to_path_buf(),
        message: e.to_string(),
    };
    let mut set = tofprobe_io::OutputSet::begin(dir).map_err(out_err)?;
    summary.files = files.iter().map(|(n, _)| n.clone()).collect();
    summary.files.push("summary.json".into());
    for (name, bytes) in &files {
        set.add(name, bytes).map_err(out_err)?;
    }
    let json = serde_json::to_string_pretty(&summary).map_err(|e| ArrayError::Output {
        path: dir.join("summary.json"),
        message: e.to_string(),
    })?;
    set.add("summary.json", json.as_bytes()).map_err(out_err)?;
    set.commit(Some("summary.json")).map_err(out_err)?;
    Ok(summary)
}
