//! One array simulation as one output set (whole or absent, `tofprobe_io::OutputSet`; the
//! project's completion marker `tofprobe-set.toml` written last, after `summary.json`, so
//! `tofprobe check-set` checks it and a later set replaces only the files it lists): the
//! registers as `registers.npy` (int64 [R, C, K]) and the detections (`detections.npy`,
//! [R, C]); the level each pixel ran at (`level.npy`, int64 [R, C]: 0 bit-true, 1
//! statistical, 2 closed-form — under `[array] level = "auto"` a mix — and its map
//! `level.svg`); for a Fourier frame `amplitude_um.npy` and `phase_deg.npy` ([B, R, C]), a heat
//! map of amplitude and of phase per bin, each pixel's strongest bin, the animated
//! deflection shape at the dominant bin and the Universal File Format file `vibration.uff`;
//! for a Haar frame each pixel's transition time (`event_time_ms.npy`, −1 where none, and
//! its heat map), the fit's sd of that time (`event_time_sd_ms.npy`, −1 where none) and
//! the edge velocity fitted from them; the summary with its figures,
//! units and file names. Every file is streamed into the set as it is made (bounded
//! buffers), and the set's size, directory and disk are checked before the model runs
//! ([`crate::set_plan`]).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_io::{OutputSet, npy};

use crate::configuration_name;
use crate::error::ArrayError;
use crate::events::{EventMap, event_map};
use crate::maps::{VibrationMaps, fourier_maps};
use crate::model::{ArrayFrame, run_array};
use crate::plot::{Scale, write_deflection_animation, write_heat_map};
use crate::set_plan::{MARKER, SUMMARY};
use crate::statistical::auto::{level_code, level_map};
use tofprobe_design::ArrayLevel;

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
    /// The `[array] level` the pixels ran at (bit-true, statistical, closed-form, auto).
    pub level: String,
    /// Pixels per level that ran (every level named, 0 where none; under `"auto"` the
    /// bit-true and statistical pixels of `level.npy`).
    pub level_pixels: BTreeMap<String, usize>,
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
    let levels = level_map(design)?;
    let level_pixels = ArrayLevel::ALL
        .iter()
        .map(|&l| {
            (
                l.name().to_string(),
                levels.iter().filter(|&&x| x == l).count(),
            )
        })
        .collect();
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
        configuration: configuration_name(design),
        mode: design.pixel.mode.to_string(),
        level: a.level.name().to_string(),
        level_pixels,
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

/// Streams the files of the set (all but the summary) into `set`, each written as it is
/// made through a bounded buffer; returns their names in order.
fn stream_files(
    set: &mut OutputSet,
    design: &ResolvedDesign,
    frame: &ArrayFrame,
    maps: Option<&VibrationMaps>,
    events: Option<&EventMap>,
) -> Result<Vec<String>, ArrayError> {
    let (r, c) = (frame.rows, frame.cols);
    let dir = set.target().to_path_buf();
    let mut names = Vec::new();
    let mut add = |set: &mut OutputSet,
                   name: &str,
                   write: &mut dyn FnMut(&mut dyn Write) -> std::io::Result<()>|
     -> Result<(), ArrayError> {
        set.add_streamed(name, |w| write(w))
            .map_err(|e| ArrayError::Output {
                path: dir.join(name),
                message: e.to_string(),
            })?;
        names.push(name.to_string());
        Ok(())
    };
    add(set, "registers.npy", &mut |w| {
        npy::write(w, &[r, c, frame.registers_per_pixel], &frame.registers)
    })?;
    add(set, "detections.npy", &mut |w| {
        npy::write_iter(w, &[r, c], frame.detections.iter().map(|&d| d as i64))
    })?;
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    let levels: Vec<i64> = level_map(design)?.into_iter().map(level_code).collect();
    add(set, "level.npy", &mut |w| npy::write(w, &[r, c], &levels))?;
    add(set, "level.svg", &mut |w| {
        write_heat_map(
            w,
            "level per pixel (0 bit-true, 1 statistical, 2 closed-form)",
            "level",
            &|i| levels[i] as f64,
            r,
            c,
            mm,
            Scale::Index,
        )
    })?;
    if let Some(e) = events {
        add(set, "event_time_ms.npy", &mut |w| {
            npy::write(w, &[r, c], &e.time_ms)
        })?;
        add(set, "event_time_sd_ms.npy", &mut |w| {
            npy::write(w, &[r, c], &e.time_sd_ms)
        })?;
        add(set, "event_time.svg", &mut |w| {
            // Pixels without a transition (−1) drawn as 0 ms.
            let shown = |i: usize| e.time_ms[i].max(0.0);
            write_heat_map(
                w,
                "transition time per pixel",
                "time (ms)",
                &shown,
                r,
                c,
                mm,
                Scale::Amplitude,
            )
        })?;
    }
    let Some(m) = maps else {
        return Ok(names);
    };
    let b = m.bins();
    add(set, "amplitude_um.npy", &mut |w| {
        npy::write(w, &[b, r, c], &m.amplitude_um)
    })?;
    add(set, "phase_deg.npy", &mut |w| {
        npy::write(w, &[b, r, c], &m.phase_deg)
    })?;
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
            add(set, &format!("{kind}_bin{k:02}.svg"), &mut |w| {
                write_heat_map(
                    w,
                    &format!("{kind} at {f:.1} Hz (bin {k})"),
                    unit,
                    &|i| values[i],
                    r,
                    c,
                    mm,
                    scale,
                )
            })?;
        }
    }
    add(set, "strongest_bin.svg", &mut |w| {
        write_heat_map(
            w,
            "strongest bin per pixel",
            "bin index",
            &|i| m.strongest_bin[i] as f64,
            r,
            c,
            mm,
            Scale::Index,
        )
    })?;
    let d = m.dominant_bin;
    add(set, "deflection.svg", &mut |w| {
        write_deflection_animation(
            w,
            &format!(
                "deflection shape at {:.1} Hz (bin {d}), one period per second",
                m.frequencies_hz[d]
            ),
            m.amplitude(d),
            m.phase(d),
            r,
            c,
        )
    })?;
    let name = configuration_name(design);
    let level = design.array.as_ref().map_or("bit-true", |a| a.level.name());
    add(set, "vibration.uff", &mut |w| {
        crate::uff::write_to(w, &name, level, mm, m)
    })?;
    Ok(names)
}

/// How an array set is written: the largest set allowed (`--max-out-gib`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SetLimits {
    pub max_set_bytes: u64,
}

impl Default for SetLimits {
    fn default() -> Self {
        SetLimits {
            max_set_bytes: crate::set_plan::DEFAULT_MAX_SET_BYTES,
        }
    }
}

/// Starts the array set of `design` in `dir` after every check that needs no work
/// ([`crate::set_plan::open`]: size, lock, foreign files, disk); the model runs after.
pub fn open_set(
    design: &ResolvedDesign,
    dir: &Path,
    limits: SetLimits,
) -> Result<OutputSet, ArrayError> {
    let files = crate::set_plan::array_set(design)?;
    crate::set_plan::open(design, dir, &files, limits.max_set_bytes)
}

/// Runs the array and writes its set into `dir` (whole or absent); returns the summary.
/// Everything that can be checked before the model runs is checked first
/// ([`open_set`]).
pub fn run_and_write(
    design: &ResolvedDesign,
    dir: &Path,
    limits: SetLimits,
) -> Result<ArraySummary, ArrayError> {
    let set = open_set(design, dir, limits)?;
    let rom = design.probe_rom()?;
    let t0 = Instant::now();
    let frame = run_array(design, rom.as_ref().map(|r| &r.image))?;
    write_set(design, rom.as_ref(), frame, t0.elapsed().as_secs_f64(), set)
}

/// Writes the set of a frame that took `model_seconds` to run (one run, or merged tiles:
/// `shard::merge_sets`) into `set` (from [`open_set`]), each file streamed, the summary
/// and then the completion marker last; returns the summary.
pub fn write_set(
    design: &ResolvedDesign,
    rom: Option<&ProbeRom>,
    frame: ArrayFrame,
    model_seconds: f64,
    mut set: OutputSet,
) -> Result<ArraySummary, ArrayError> {
    let dir = set.target().to_path_buf();
    let (frame, maps, events, mut summary) = finish(design, rom, frame, model_seconds)?;
    let mut files = stream_files(&mut set, design, &frame, maps.as_ref(), events.as_ref())?;
    files.push(SUMMARY.into());
    summary.files = files;
    let out_err = |e: std::io::Error| ArrayError::Output {
        path: dir.clone(),
        message: e.to_string(),
    };
    let json = serde_json::to_string_pretty(&summary).map_err(|e| ArrayError::Output {
        path: dir.join(SUMMARY),
        message: e.to_string(),
    })?;
    set.add(SUMMARY, json.as_bytes()).map_err(out_err)?;
    let preamble = format!(
        "# Generated by tofprobe {}: the completion marker of an array set (each file's \
         FNV-1a-64), written last; check it with `tofprobe check-set`.\n",
        env!("CARGO_PKG_VERSION")
    );
    set.commit_marked(MARKER, &preamble).map_err(out_err)?;
    Ok(summary)
}
