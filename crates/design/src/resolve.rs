//! The ONE resolution of a configuration document: [`resolve`] takes a [`Document`] to a
//! [`ResolvedDesign`] — the validated sensor, scene and acquisition, the pixel's parameters
//! (widths included), the Fourier bins and the stability-checked ΣΔ probe design. Every
//! command starts from a `ResolvedDesign`, so `tofprobe config FILE` accepts exactly what
//! the other commands accept and every refusal reads the same.

mod steps;

use std::path::Path;

use tofprobe_dsp::sd::{ProbeDesign, ProbeRom};
use tofprobe_pixel::{PixelContext, PixelError, PixelParams};
use tofprobe_scene::{PhotonSource, Scene};

use crate::adders::{AdderStatus, AdderTiming};
use crate::document::Document;
use crate::error::DesignError;
use crate::mode_decision::ModeDecision;
use crate::probe_cache::ProbeCache;

/// Longest frame a windowed ROM (L = N) may span: 2^24 pulses (1.68 s at 10 MHz).
pub const MAX_WINDOWED_FRAME: u64 = 1 << 24;

/// A configuration resolved once: everything a command needs, already validated. It
/// serialises (serde; [`ResolvedDesign::to_json`]), so a worker process receives the design
/// instead of resolving it again (no stability sweep: the probe design carries its limit).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// How A was set: explicit, `"auto"` still open (no tool ran), or chosen from timing.
    pub adders: AdderStatus,
    /// `[array]` resolved: the shape, the mapping onto the scene plane and the per-pixel
    /// rate maps; `None` for the single pixel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<crate::array::SensorArray>,
}

/// A design received as JSON that does not hold.
fn received_error(message: String) -> DesignError {
    DesignError::Toml {
        origin: "<serialised design>".to_string(),
        message,
    }
}

/// Reads `path` (or the embedded default) and resolves it.
pub fn load(path: Option<&Path>) -> Result<ResolvedDesign, DesignError> {
    let (document, origin) = Document::read(path)?;
    resolve(document, &origin)
}

/// Resolves a document; `origin` names it in every error. Pure: no tool runs
/// (`adders = "auto"` stays open, see [`crate::adders`]).
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
    resolve_timed(document, origin, cache, None)
}

/// The one resolution, with `adders = "auto"` decided by `timing` when one is given (the
/// hardware commands pass `tofprobe-flow`'s synthesis oracle) and left open otherwise.
pub fn resolve_timed(
    document: Document,
    origin: &str,
    cache: &mut ProbeCache,
    timing: Option<&dyn AdderTiming>,
) -> Result<ResolvedDesign, DesignError> {
    let d = &document;
    steps::check_scene(d, origin)?;
    let frame = steps::frame(d, origin)?;
    let mut r = steps::Resolution::new(d, origin, frame);
    r.check_probe()?;
    r.rom_depth()?;
    let adders = r.adders(timing)?;
    let parts = r.finish(cache)?;
    Ok(ResolvedDesign {
        origin: origin.to_string(),
        document,
        context: parts.context,
        pixel: parts.pixel,
        bins: parts.bins,
        probe_design: parts.probe_design,
        mode: parts.mode,
        notes: parts.notes,
        adders,
        array: parts.array,
    })
}

/// A `[pixel]` refusal of a quantity the document did not set in `[pixel]` says which keys it
/// was derived from, so the message names a field the user wrote.
fn derived_from(e: PixelError, d: &Document) -> PixelError {
    let PixelError::Invalid {
        field,
        value,
        reason,
        nearest,
    } = e
    else {
        return e;
    };
    let source = match field {
        "frame_pulses" if d.pixel.frame_pulses.is_none() => {
            "N comes from acquisition.pulses, or acquisition.duration_s × sensor.laser_rate_hz; \
             change those or set pixel.frame_pulses"
        }
        "tdc_bits" if d.pixel.tdc_bits.is_none() => {
            "T comes from sensor.window_length_ps / sensor.tdc_lsb_ps"
        }
        "rom_depth" if d.pixel.rom_depth.is_none() => {
            "L comes from probe.rom_depth (periodic) or the frame (windowed)"
        }
        _ => "",
    };
    let reason = if source.is_empty() {
        reason
    } else {
        format!("{reason} ({source})")
    };
    PixelError::Invalid {
        field,
        value,
        reason,
        nearest,
    }
}

impl ResolvedDesign {
    /// What the document sets that this design ignores (a `[probe]` section in Haar
    /// mode), as `ORIGIN: …`: the front ends show it (the CLI on stderr as `warning: …`,
    /// Python as a `UserWarning`); the library only decides it.
    pub fn ignored_warning(&self) -> Option<String> {
        crate::mode_decision::ignored_probe_warning(&self.document, self.pixel.mode)
            .map(|w| format!("{}: {w}", self.origin))
    }

    /// The document with a decided `adders = "auto"` written out as the chosen A and C, so
    /// a variant re-resolved from it (an architecture option, a knob) keeps the measured
    /// choice instead of reopening it; the document as written otherwise.
    pub fn document_with_decided_adders(&self) -> Document {
        let mut d = self.document.clone();
        if let AdderStatus::Chosen(c) = &self.adders {
            d.pixel.adders = tofprobe_pixel::config::Choice::Value(c.adders);
            d.pixel.cycles_per_pulse = c.cycles_per_pulse;
        }
        d
    }

    /// The number of pulses N of the acquisition.
    pub fn pulses(&self) -> u64 {
        self.document.pulses()
    }

    /// The design as JSON (floats round-trip exactly: serde_json's `float_roundtrip`).
    pub fn to_json(&self) -> Result<String, DesignError> {
        serde_json::to_string(self).map_err(|e| DesignError::Toml {
            origin: self.origin.clone(),
            message: format!("the resolved design does not serialise: {e}"),
        })
    }

    /// A design sent as [`Self::to_json`]; errors name what does not fit.
    /// An `[array]` is checked as [`crate::array::SensorArray::check_received`] does: its
    /// shape against its maps and the memory cap, before anything is sized from it.
    pub fn from_json(text: &str) -> Result<ResolvedDesign, DesignError> {
        Self::received(serde_json::from_str(text))
    }

    /// [`Self::from_json`] from a reader (a file streamed, never held whole as text).
    pub fn from_json_reader(r: impl std::io::Read) -> Result<ResolvedDesign, DesignError> {
        Self::received(serde_json::from_reader(std::io::BufReader::new(r)))
    }

    fn received(d: serde_json::Result<ResolvedDesign>) -> Result<ResolvedDesign, DesignError> {
        let d = d.map_err(|e| received_error(e.to_string()))?;
        d.check_received()?;
        Ok(d)
    }

    /// The checks of a design received whole rather than resolved here: its `[array]`
    /// ([`crate::array::SensorArray::check_received`]).
    pub fn check_received(&self) -> Result<(), DesignError> {
        if let Some(a) = &self.array {
            a.check_received(self.pixel.registers(), self.analysis_bins())
                .map_err(|m| received_error(format!("its [array]: {m}")))?;
        }
        Ok(())
    }

    /// The bins read from each pixel's registers: B in Fourier mode, 0 in Haar mode (the
    /// memory accounting's `bins`, [`crate::array::SensorArray::bytes_per_pixel`]).
    pub fn analysis_bins(&self) -> usize {
        match self.pixel.mode {
            tofprobe_pixel::Mode::Fourier => self.pixel.bins,
            tofprobe_pixel::Mode::Haar => 0,
        }
    }

    /// The sensor.
    pub fn sensor(&self) -> &tofprobe_scene::SensorConfig {
        &self.document.sensor
    }

    /// The scene's tones (frequency Hz, amplitude mm).
    pub fn tones(&self) -> &[(f64, f64)] {
        &self.context.tones
    }

    /// The photon source of pixel (r, c) of the array: the sensor with that pixel's ρ_s and
    /// ρ_b, the scene at its centre on the plane, and its own seed
    /// ([`crate::array::pixel_seed`]). Refused for a single-pixel design, a pixel outside,
    /// or a superpixel (G > 1: [`Self::pixel_sources`]).
    pub fn pixel_source(&self, r: usize, c: usize) -> Result<PhotonSource, DesignError> {
        let a = self.array_or_refuse()?;
        if r >= a.rows || c >= a.cols {
            return Err(DesignError::array(
                &self.origin,
                format!(
                    "pixel ({r}, {c}) is outside the {} × {} array",
                    a.rows, a.cols
                ),
            ));
        }
        if a.superpixel > 1 {
            return Err(DesignError::array(
                &self.origin,
                format!(
                    "pixel ({r}, {c}) is a superpixel of {g} × {g} SPADs (array.superpixel = {g}): \
                     its streams are `pixel_sources`, averaged by the superpixel front end",
                    g = a.superpixel
                ),
            ));
        }
        self.spad_source(r, c)
    }

    /// The photon sources of pixel (r, c)'s G² SPADs, row-major within the pixel
    /// ([`crate::SensorArray::spads_of`]); one source when G = 1, `pixel_source(r, c)`.
    pub fn pixel_sources(&self, r: usize, c: usize) -> Result<Vec<PhotonSource>, DesignError> {
        let a = self.array_or_refuse()?;
        if r >= a.rows || c >= a.cols {
            return Err(DesignError::array(
                &self.origin,
                format!(
                    "pixel ({r}, {c}) is outside the {} × {} array",
                    a.rows, a.cols
                ),
            ));
        }
        a.spads_of(r, c)
            .map(|(sr, sc)| self.spad_source(sr, sc))
            .collect()
    }

    /// The photon source of SPAD (r, c) (the SPAD grid: rows·G × cols·G): its rates, the
    /// scene at its centre, the seed of (seed, r, c).
    pub fn spad_source(&self, r: usize, c: usize) -> Result<PhotonSource, DesignError> {
        let a = self.array_or_refuse()?;
        let (rows, cols) = (a.spad_rows(), a.spad_cols());
        if r >= rows || c >= cols {
            return Err(DesignError::array(
                &self.origin,
                format!("SPAD ({r}, {c}) is outside the {rows} × {cols} SPADs"),
            ));
        }
        let mut sensor = self.document.sensor.clone();
        sensor.signal_rate = a.signal_rate[r * cols + c];
        sensor.background_rate = a.background_rate[r * cols + c];
        let scene =
            Scene::new(&self.document.scene).map_err(|e| DesignError::scene(&self.origin, e))?;
        let (x, y) = a.spad_centre_mm(r, c);
        let seed = crate::array::pixel_seed(self.document.acquisition.seed, r, c);
        PhotonSource::new(&sensor, &scene.at_point(x, y), seed)
            .map_err(|e| DesignError::scene(&self.origin, e))
    }

    /// The array, or the error of a design without one.
    fn array_or_refuse(&self) -> Result<&crate::SensorArray, DesignError> {
        self.array.as_ref().ok_or_else(|| {
            DesignError::array(
                &self.origin,
                "the design has no [array]: its one pixel is `photon_source()`",
            )
        })
    }

    /// Refuses an array design for a command that runs one pixel (`command` names it, and
    /// the message says what runs arrays).
    pub fn single_pixel(&self, command: &str) -> Result<(), DesignError> {
        match &self.array {
            None => Ok(()),
            Some(a) => Err(DesignError::array(
                &self.origin,
                format!(
                    "`{command}` runs one pixel, and [array] (array.rows = {}, array.cols = {}) makes this a {} × {} sensor: \
                     `tofprobe simulate CONFIG --out DIR` runs the array (remove [array] to {command} its pixel)",
                    a.rows, a.cols, a.rows, a.cols
                ),
            )),
        }
    }

    /// The readout of the array for the design's pixel (`None` for a single pixel); see
    /// [`crate::readout`]. [`crate::Chip`] resolves it again for the pixel it renders.
    pub fn readout(&self) -> Result<Option<crate::readout::Readout>, DesignError> {
        let Some(a) = &self.array else {
            return Ok(None);
        };
        crate::readout::resolve_readout(
            &a.readout,
            a.rows,
            a.cols,
            &self.pixel,
            self.sensor().laser_rate_hz,
            &self.origin,
        )
        .map(Some)
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
