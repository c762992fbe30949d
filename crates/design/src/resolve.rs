//! The ONE resolution of a configuration document: [`resolve`] takes a [`Document`] to a
//! [`ResolvedDesign`] — the validated sensor, scene and acquisition, the pixel's parameters
//! (widths included), the Fourier bins and the stability-checked ΣΔ probe design. Every
//! command starts from a `ResolvedDesign`, so `tofprobe config FILE` accepts exactly what
//! the other commands accept and every refusal reads the same.

use std::path::Path;

use tofprobe_dsp::sd::{ProbeDesign, ProbeRom, RomMode};
use tofprobe_pixel::{Mode, PixelContext, PixelError, PixelParams};
use tofprobe_scene::{PhotonSource, Scene};

use crate::analysis_mode::{ModeDecision, check_haar, decide_mode};
use crate::bins::bin_indices;
use crate::document::Document;
use crate::error::DesignError;
use crate::probe_cache::ProbeCache;

/// A configuration resolved once: everything a command needs, already validated.
#[derive(Debug, Clone)]
pub struct ResolvedDesign {
    /// The file path, or [`crate::DEFAULT_ORIGIN`].
    pub origin: String,
    /// The document as written (sensor, scene, acquisition, `[pixel]`, `[probe]`).
    pub document: Document,
    /// What the sensor, acquisition, probe and scene tell the pixel.
    pub context: PixelContext,
    /// The resolved pixel: T, W from the sizing, N, L (the `[probe]` ROM's depth unless
    /// `pixel.rom_depth` is given).
    pub pixel: PixelParams,
    /// Fourier mode: the ROM bin indices k (f_k = k·f_s/L), ROM order; empty in Haar mode.
    pub bins: Vec<u64>,
    /// Fourier mode: the `[probe]` design, stability-checked at the lowest bin.
    pub probe_design: Option<ProbeDesign>,
    /// How the mode was decided (`pixel.mode = "auto"`: which and why).
    pub mode: ModeDecision,
    /// Notes every command prints: a mixed scene under `mode = "auto"`, a `[probe]` a Haar
    /// pixel ignores, transients outside the Haar frame.
    pub notes: Vec<String>,
}

/// Reads `path` (or the embedded default) and resolves it.
pub fn load(path: Option<&Path>) -> Result<ResolvedDesign, DesignError> {
    let (document, origin) = Document::read(path)?;
    resolve(document, &origin)
}

/// Resolves a document; `origin` names it in every error.
pub fn resolve(document: Document, origin: &str) -> Result<ResolvedDesign, DesignError> {
    resolve_with(document, origin, &mut ProbeCache::default())
}

/// [`resolve`] with the probe designs of earlier resolutions reused (a knob sweep resolves
/// many documents that share one `[probe]`; the stability sweep is the expensive part).
pub fn resolve_with(
    document: Document,
    origin: &str,
    cache: &mut ProbeCache,
) -> Result<ResolvedDesign, DesignError> {
    let scene_err = |e| DesignError::scene(origin, e);
    let probe_err = |e| DesignError::probe(origin, e);
    let pixel_err = |e| DesignError::pixel(origin, e);
    let d = &document;
    d.sensor.validate().map_err(scene_err)?;
    let scene = Scene::new(&d.scene).map_err(scene_err)?;
    d.acquisition
        .validate(d.sensor.laser_rate_hz)
        .map_err(scene_err)?;
    PhotonSource::new(&d.sensor, &scene, d.acquisition.seed).map_err(scene_err)?;
    d.probe.validate().map_err(probe_err)?;
    let frame = d.pixel.frame_pulses.unwrap_or(d.pulses());
    d.probe.check_frame(frame).map_err(probe_err)?;

    // The pixel reads the ROM the probe design generates: its depth defaults to the
    // `[probe]` design's (L = N windowed, `probe.rom_depth` periodic).
    // A Fourier pixel addresses exactly that ROM: another `pixel.rom_depth` would read the
    // generated ROM on the wrong bin grid (it used to be replaced silently by `rtl`).
    let context = d.pixel_context();
    let mut px = d.pixel.clone();
    let mode = decide_mode(d, &mut px, frame);
    let mut notes: Vec<String> = mode.auto.iter().filter_map(|c| c.note.clone()).collect();
    if mode.mode == Mode::Haar {
        notes.extend(check_haar(d, &px, &mode, frame, origin)?);
    }
    let probe_depth = d.probe.depth(frame);
    match px.rom_depth {
        None => px.rom_depth = Some(probe_depth),
        Some(l) if l != probe_depth && mode.mode == Mode::Fourier => {
            return Err(pixel_err(PixelError::invalid(
                "rom_depth",
                l,
                format!(
                    "the pixel reads the [probe] ROM, which is L = {probe_depth} deep ({})",
                    match d.probe.rom_mode {
                        RomMode::Periodic => "probe.rom_depth, periodic mode",
                        RomMode::Windowed => "one frame, windowed mode",
                    }
                ),
                format!("{probe_depth} (or leave pixel.rom_depth out)"),
            )));
        }
        Some(_) => {}
    }
    let pixel = px.resolve(&context).map_err(pixel_err)?;

    let (bins, probe_design) = if pixel.mode == Mode::Fourier {
        let bins = bin_indices(d, pixel.bins, pixel.rom_depth as u64).map_err(pixel_err)?;
        // The modulator's stability limit is lowest towards DC: check at the lowest bin.
        let lowest = bins.iter().copied().min().unwrap_or(1).max(1);
        let f_norm = lowest as f64 / pixel.rom_depth as f64;
        let design = cache.design(&d.probe, f_norm).map_err(probe_err)?;
        (bins, Some(design))
    } else {
        (Vec::new(), None)
    };
    Ok(ResolvedDesign {
        origin: origin.to_string(),
        document,
        context,
        pixel,
        bins,
        probe_design,
        mode,
        notes,
    })
}

impl ResolvedDesign {
    /// The number of pulses N of the acquisition.
    pub fn pulses(&self) -> u64 {
        self.document.pulses()
    }

    /// The sensor.
    pub fn sensor(&self) -> &tofprobe_scene::SensorConfig {
        &self.document.sensor
    }

    /// The scene's tones (frequency Hz, amplitude mm).
    pub fn tones(&self) -> &[(f64, f64)] {
        &self.context.tones
    }

    /// The photon source of the design (validated by the resolution).
    pub fn photon_source(&self) -> Result<PhotonSource, DesignError> {
        self.document
            .photon_source()
            .map_err(|e| DesignError::scene(&self.origin, e))
    }

    /// The ΣΔ probe ROM the pixel reads over one frame (Fourier mode: the design at the
    /// resolved bins, N = the pixel's frame, L = its ROM depth); `None` in Haar mode.
    pub fn probe_rom(&self) -> Result<Option<ProbeRom>, DesignError> {
        let Some(design) = &self.probe_design else {
            return Ok(None);
        };
        ProbeRom::generate(
            design,
            self.sensor().laser_rate_hz,
            self.pixel.frame_pulses,
            &self.bins,
        )
        .map(Some)
        .map_err(|e| DesignError::probe(&self.origin, e))
    }
}
