//! The whole TOML configuration document, from a file or the embedded default
//! (`scenes/default.toml`, the paper's Fig. 8 case). This module only parses: what the
//! document means (validation, defaults, the pixel, the bins) is [`crate::resolve()`]'s job,
//! done once.
//!
//! Every table rejects unknown keys (`deny_unknown_fields`), so a typo is an error with a
//! line and column, not a silently ignored setting. Sections added by later capabilities
//! (e.g. `[probe]`, `[pixel]`) are `#[serde(default)]` fields of [`Document`].

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tofprobe_pixel::PixelContext;
use tofprobe_scene::{AcquisitionConfig, PhotonSource, Scene, SceneConfig, SensorConfig};

use crate::error::DesignError;
use crate::{DEFAULT_ORIGIN, DEFAULT_TOML};

pub mod keys;
pub mod schema;

/// Jitter σ on each side of the scene's depth range that `width = "auto"` sizes for (the
/// pixel crate's one sizing rule, also used by `tofprobe size`).
pub use tofprobe_pixel::sizing::SIZING_SIGMAS;

/// The configuration document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Document {
    /// `[sensor]`: laser, jitter, TDC, window, photon rates.
    pub sensor: SensorConfig,
    /// `[scene]`: static depth and motions.
    pub scene: SceneConfig,
    /// `[acquisition]`: number of pulses (or duration) and seed.
    pub acquisition: AcquisitionConfig,
    /// `[pixel]`: the bit-true pixel (bins, adders, cycles, prefilter, widths).
    #[serde(default)]
    pub pixel: tofprobe_pixel::PixelConfig,
    /// `[probe]`: the ΣΔ probe design (order, OSR, H_inf, window, amplitude, ROM mode).
    #[serde(default)]
    pub probe: tofprobe_dsp::sd::ProbeConfig,
    /// `[array]`: R × C pixels on the scene plane (absent: the single pixel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<crate::array::ArrayConfig>,
}

impl Document {
    /// Parses TOML text; `origin` names the source in error messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Document, DesignError> {
        toml::from_str(text).map_err(|e| {
            let parser = schema::clip_message(e.to_string().trim_end());
            // The key the walk names, with where the parser stopped and (unless the walk
            // already quotes it) what it said.
            let message = match schema::wrong_type(text) {
                Some(m) => {
                    let said = schema::clip_message(e.message().trim());
                    let at = e.span().map(|r| {
                        let before = &text[..r.start.min(text.len())];
                        let line = before.matches('\n').count() + 1;
                        let column =
                            before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
                        format!("line {line}, column {column}")
                    });
                    match (at, m.contains(&said)) {
                        (Some(at), true) => format!("{m} (at {at})"),
                        (Some(at), false) => format!("{m} (at {at}: {said})"),
                        (None, true) => m,
                        (None, false) => format!("{m} ({said})"),
                    }
                }
                None => parser,
            };
            DesignError::Toml {
                origin: origin.to_string(),
                message,
            }
        })
    }

    /// Reads and parses `path`, or the embedded default when `path` is `None`; returns the
    /// document and its origin (the path as given, or [`DEFAULT_ORIGIN`]).
    pub fn read(path: Option<&Path>) -> Result<(Document, String), DesignError> {
        let (text, origin) = match path {
            None => (DEFAULT_TOML.to_string(), DEFAULT_ORIGIN.to_string()),
            Some(p) => (read_text(p)?, p.display().to_string()),
        };
        Ok((Document::from_toml_str(&text, &origin)?, origin))
    }

    /// What the sensor, acquisition, probe design and scene tell the pixel: window codes,
    /// laser rate, N, the scene's tones, the OSR and the codes its detections can take
    /// (±[`SIZING_SIGMAS`] σ of jitter around its depth range; the whole window with
    /// background photons).
    pub fn pixel_context(&self) -> PixelContext {
        let s = &self.sensor;
        let ctx = PixelContext::from_sensor(s, self.pulses());
        let Ok(scene) = Scene::new(&self.scene) else {
            return ctx;
        };
        let (lo, hi) = scene.depth_range_mm();
        let codes = tofprobe_pixel::sizing::scene_code_range(
            lo,
            hi,
            s.jitter_mm(),
            SIZING_SIGMAS,
            s.window_start_mm(),
            s.tdc_lsb_mm(),
            s.tdc_codes(),
            s.background_rate > 0.0,
        );
        ctx.with_scene(scene.tones(), self.probe.osr, codes)
    }

    /// The number of pulses N of the acquisition.
    pub fn pulses(&self) -> u64 {
        self.acquisition.pulses(self.sensor.laser_rate_hz)
    }

    /// Builds the photon source of this document.
    pub fn photon_source(&self) -> Result<PhotonSource, tofprobe_scene::SceneError> {
        let scene = Scene::new(&self.scene)?;
        PhotonSource::new(&self.sensor, &scene, self.acquisition.seed)
    }
}

/// Reads a file as UTF-8 text with a specific error for each way it can fail: a directory,
/// not a regular file (`/dev/zero`, a FIFO) or larger than
/// [`tofprobe_io::bounded::MAX_CONFIG_BYTES`] (refused before reading it), not UTF-8.
pub fn read_text(path: &Path) -> Result<String, DesignError> {
    if path.is_dir() {
        return Err(DesignError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let bytes = tofprobe_io::read_bounded(path, tofprobe_io::bounded::MAX_CONFIG_BYTES).map_err(
        |source| DesignError::Read {
            path: path.to_path_buf(),
            source,
        },
    )?;
    String::from_utf8(bytes).map_err(|e| DesignError::NotUtf8 {
        path: PathBuf::from(path),
        offset: e.utf8_error().valid_up_to(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded default is the paper's Fig. 8 case, and it validates.
    #[test]
    fn embedded_default_is_fig8() {
        let loaded = crate::load(None).expect("default loads");
        let c = &loaded.document;
        assert_eq!(c.pulses(), 10_000_000); // 1 s at 10 MHz
        assert_eq!(c.sensor.jitter_mm(), 7.5); // 50 ps · 0.15 mm/ps
        assert_eq!(c.sensor.tdc_codes(), 80); // 400 ps / 5 ps
        assert_eq!(c.sensor.tdc_bits(), 7);
        assert_eq!((c.sensor.signal_rate, c.sensor.background_rate), (1.0, 0.0));
        assert_eq!(c.scene.depth_mm, 30.0);
        let scene = Scene::new(&c.scene).expect("scene");
        assert_eq!(scene.tones(), vec![(4500.0, 0.1)]);
        assert_eq!(c.acquisition.seed, 1);
    }

    /// Unknown keys are rejected in every table, with the line of the key (for a motion,
    /// the line of its `[[scene.motion]]` header: serde buffers internally tagged tables,
    /// so the key's own span is lost; the message still names the key and the expected
    /// ones).
    #[test]
    fn unknown_keys_are_rejected_everywhere() {
        for (anchor, extra) in [
            ("[sensor]\n", "colour = 1\n"),
            ("[scene]\n", "colour = 1\n"),
            ("[[scene.motion]]\n", "colour = 1\n"),
            ("[acquisition]\n", "colour = 1\n"),
        ] {
            let text = DEFAULT_TOML.replacen(anchor, &format!("{anchor}{extra}"), 1);
            let key = text
                .lines()
                .position(|l| l == "colour = 1")
                .expect("inserted")
                + 1;
            let line = if anchor.starts_with("[[") {
                key - 1
            } else {
                key
            };
            let err = Document::from_toml_str(&text, "t.toml").expect_err("unknown key");
            let msg = err.to_string();
            assert!(msg.contains("colour"), "{msg}");
            assert!(msg.contains(&format!("line {line}")), "{msg}");
        }
        let extra_section = format!("{DEFAULT_TOML}\n[extra]\nx = 1\n");
        assert!(Document::from_toml_str(&extra_section, "t.toml").is_err());
    }
}
