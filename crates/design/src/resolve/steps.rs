//! The steps of [`super::resolve_timed`], in its order (so the first refusal a document
//! meets is the same): the scene, the frame, then over one [`Resolution`] — the mode, the
//! probe, the ROM's depth and band, the adders — and the parts of the resolved design.

use tofprobe_dsp::sd::{ProbeDesign, RomMode};
use tofprobe_pixel::{Mode, PixelConfig, PixelContext, PixelError, PixelParams};
use tofprobe_scene::{PhotonSource, Scene};

use super::{MAX_WINDOWED_FRAME, derived_from};
use crate::adders::{AdderStatus, AdderTiming};
use crate::bin_choice::bin_indices_in;
use crate::document::Document;
use crate::error::DesignError;
use crate::mode_decision::{ModeDecision, check_haar, decide_mode};
use crate::probe_cache::ProbeCache;

/// The sensor, the scene and the acquisition: an array checks the scene over the whole
/// plane (its spatial motions' bounds), each pixel's own scene being a point of it; one
/// pixel builds its photon source.
pub(super) fn check_scene(d: &Document, origin: &str) -> Result<(), DesignError> {
    let scene_err = |e| DesignError::scene(origin, e);
    d.sensor.validate().map_err(scene_err)?;
    let scene = Scene::new(&d.scene).map_err(scene_err)?;
    d.acquisition
        .validate(d.sensor.laser_rate_hz)
        .map_err(scene_err)?;
    match &d.array {
        Some(_) => tofprobe_scene::check_scene(&d.sensor, &scene).map_err(scene_err)?,
        None => {
            PhotonSource::new(&d.sensor, &scene, d.acquisition.seed).map_err(scene_err)?;
        }
    }
    Ok(())
}

/// The frame's pulses N. A frame is part of the acquisition (docs: "N: pulses per frame;
/// default: the whole acquisition"): a longer one would read pulses never simulated.
pub(super) fn frame(d: &Document, origin: &str) -> Result<u64, DesignError> {
    let frame = d.pixel.frame_pulses.unwrap_or(d.pulses());
    if frame > d.pulses() {
        return Err(DesignError::pixel(
            origin,
            PixelError::invalid(
                "frame_pulses",
                frame,
                format!(
                    "a frame is at most the acquisition's {} pulses (acquisition.pulses, or \
                     acquisition.duration_s × sensor.laser_rate_hz)",
                    d.pulses()
                ),
                format!("{} (or leave pixel.frame_pulses out)", d.pulses()),
            ),
        ));
    }
    Ok(frame)
}

/// The resolution under way: the document's `[pixel]` being completed, its mode, and the
/// notes gathered for the user.
pub(super) struct Resolution<'a> {
    d: &'a Document,
    origin: &'a str,
    frame: u64,
    context: PixelContext,
    px: PixelConfig,
    mode: ModeDecision,
    notes: Vec<String>,
}

/// What [`Resolution::finish`] hands [`super::ResolvedDesign`].
pub(super) struct Parts {
    pub(super) context: PixelContext,
    pub(super) pixel: PixelParams,
    pub(super) bins: Vec<u64>,
    pub(super) probe_design: Option<ProbeDesign>,
    pub(super) mode: ModeDecision,
    pub(super) notes: Vec<String>,
    pub(super) array: Option<crate::array::SensorArray>,
}

impl<'a> Resolution<'a> {
    /// The pixel's context and its mode (`mode = "auto"` decided from the scene).
    pub(super) fn new(d: &'a Document, origin: &'a str, frame: u64) -> Self {
        let context = d.pixel_context();
        let mut px = d.pixel.clone();
        let mode = decide_mode(d, &mut px, frame);
        let notes = mode.auto.iter().filter_map(|c| c.note.clone()).collect();
        Resolution {
            d,
            origin,
            frame,
            context,
            px,
            mode,
            notes,
        }
    }

    fn probe_err(&self, e: tofprobe_dsp::DspError) -> DesignError {
        DesignError::probe(self.origin, e)
    }

    fn pixel_err(&self, e: PixelError) -> DesignError {
        DesignError::pixel(self.origin, e)
    }

    /// The `[probe]` design of a Fourier pixel, and a windowed ROM's bound. Haar mode reads
    /// no ΣΔ probe ROM: a `[probe]` section is ignored (with a warning,
    /// `ignored_probe_warning`), neither validated nor checked against the frame; Haar's
    /// own checks add their notes.
    pub(super) fn check_probe(&mut self) -> Result<(), DesignError> {
        let (d, frame) = (self.d, self.frame);
        if self.mode.mode == Mode::Fourier {
            d.probe.validate().map_err(|e| self.probe_err(e))?;
            d.probe.check_frame(frame).map_err(|e| self.probe_err(e))?;
        }
        // A windowed ROM is one frame deep, and `simulate` builds it whole (≈ 24 bytes per
        // pulse): bounded here, once, as `rtl` and `vectors` bound theirs.
        if self.mode.mode == Mode::Fourier
            && d.probe.rom_mode == RomMode::Windowed
            && frame > MAX_WINDOWED_FRAME
        {
            return Err(self.probe_err(
                tofprobe_dsp::DspError::out_of_range(
                    "probe.rom_mode",
                    "\"windowed\"",
                    format!(
                        "a windowed ROM is one frame deep (L = N = {frame} pulses from acquisition or \
                         pixel.frame_pulses); at most {MAX_WINDOWED_FRAME} pulses (≈ 400 MB of ROM)"
                    ),
                )
                .with_hint(format!(
                    "rom_mode = \"periodic\", or pixel.frame_pulses <= {MAX_WINDOWED_FRAME}"
                )),
            ));
        }
        if self.mode.mode == Mode::Haar {
            let haar = check_haar(d, &self.px, &self.mode, frame, self.origin)?;
            self.notes.extend(haar);
        }
        Ok(())
    }

    /// The pixel reads the ROM the probe design generates: its depth defaults to the
    /// `[probe]` design's (L = N windowed, `probe.rom_depth` periodic). A Fourier pixel
    /// addresses exactly that ROM: another `pixel.rom_depth` would read the generated ROM
    /// on the wrong bin grid (it used to be replaced silently by `rtl`).
    pub(super) fn rom_depth(&mut self) -> Result<(), DesignError> {
        let d = self.d;
        let fourier = self.mode.mode == Mode::Fourier;
        let probe_depth = if fourier {
            d.probe.depth(self.frame)
        } else {
            tofprobe_dsp::sd::ProbeConfig::default().depth(self.frame)
        };
        match self.px.rom_depth {
            None => self.px.rom_depth = Some(probe_depth),
            Some(l) if l != probe_depth && fourier => {
                return Err(self.pixel_err(PixelError::invalid(
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
        // An OSR whose band f_s/(2·OSR) lies below the ROM's first bin is the OSR's fault
        // (it used to be reported against `pixel.bins` or `pixel.rom_depth`).
        if fourier && d.pixel.frequencies_hz.is_empty() {
            let l = self.px.rom_depth.unwrap_or(probe_depth) as u64;
            if let Err(why) = crate::bin_choice::band_check(l, d.probe.osr, 1) {
                return Err(self.probe_err(
                    tofprobe_dsp::DspError::out_of_range(
                        "probe.osr",
                        tofprobe_io::text::number(d.probe.osr),
                        format!(
                            "osr < L/2 = {}: {why}; the band must hold at least the ROM's first bin f_s/L",
                            l as f64 / 2.0
                        ),
                    )
                    .with_hint(format!("osr = {}", (l as f64 / 4.0).clamp(4.0, 32.0))),
                ));
            }
        }
        Ok(())
    }

    /// `adders = "auto"`: A and C from measured timing when an oracle is given
    /// (crate::adders), else a provisional A, open; then the pixel resolves with them like
    /// any explicit value.
    pub(super) fn adders(
        &mut self,
        timing: Option<&dyn AdderTiming>,
    ) -> Result<AdderStatus, DesignError> {
        self.refuse_unused_timing_liberty()?;
        if !matches!(self.px.adders, tofprobe_pixel::config::Choice::Auto(_)) {
            return Ok(AdderStatus::Explicit);
        }
        let (status, a, c) = match timing {
            Some(t) => {
                let choice = crate::adders::choose(&self.px, &self.context, self.origin, t)?;
                self.notes.push(choice.note());
                let (a, c) = (choice.adders, choice.cycles_per_pulse);
                (AdderStatus::Chosen(choice), a, c)
            }
            None => {
                let (a, c) = crate::adders::provisional(&self.px, &self.context)
                    .map_err(|e| self.pixel_err(derived_from(e, self.d)))?;
                self.notes.push(crate::adders::open_note(a));
                (AdderStatus::Open { provisional: a }, a, c)
            }
        };
        self.px.adders = tofprobe_pixel::config::Choice::Value(a);
        self.px.cycles_per_pulse = c;
        Ok(status)
    }

    /// `timing_liberty` is read only to time the candidates of `adders = "auto"`: beside
    /// an explicit A it would be ignored silently, so it is refused, naming both keys.
    fn refuse_unused_timing_liberty(&self) -> Result<(), DesignError> {
        if let (Some(lib), tofprobe_pixel::config::Choice::Value(a)) =
            (&self.d.pixel.timing_liberty, &self.d.pixel.adders)
        {
            return Err(self.pixel_err(PixelError::invalid(
                "timing_liberty",
                format!("\"{}\"", tofprobe_io::text::clip(lib, 60)),
                format!(
                    "it is read only by pixel.adders = \"auto\" (the liberty its candidates are timed on); \
                     pixel.adders = {a} is explicit, so it would be ignored"
                ),
                "remove pixel.timing_liberty, or set pixel.adders = \"auto\"",
            )));
        }
        Ok(())
    }

    /// The pixel resolved, its Fourier bins and the ΣΔ probe design (its stability limit
    /// checked at the lowest bin, where it is lowest: towards DC), and the array.
    pub(super) fn finish(self, cache: &mut ProbeCache) -> Result<Parts, DesignError> {
        let (d, origin) = (self.d, self.origin);
        let pixel_err = |e| DesignError::pixel(origin, e);
        let pixel = self
            .px
            .resolve(&self.context)
            .map_err(|e| pixel_err(derived_from(e, d)))?;
        let (bins, probe_design) = if pixel.mode == Mode::Fourier {
            let bins = bin_indices_in(d, &self.context, pixel.bins, pixel.rom_depth as u64)
                .map_err(pixel_err)?;
            let lowest = bins.iter().copied().min().unwrap_or(1).max(1);
            let f_norm = lowest as f64 / pixel.rom_depth as f64;
            let design = cache
                .design(&d.probe, f_norm)
                .map_err(|e| DesignError::probe(origin, e))?;
            (bins, Some(design))
        } else {
            (Vec::new(), None)
        };
        let array = match &d.array {
            Some(a) => Some(crate::array::resolve_array(
                a, &d.sensor, &d.scene, &pixel, origin,
            )?),
            None => None,
        };
        Ok(Parts {
            context: self.context,
            pixel,
            bins,
            probe_design,
            mode: self.mode,
            notes: self.notes,
            array,
        })
    }
}
