//! The whole TOML configuration document, loaded from a file or from the embedded default
//! (`scenes/default.toml`, the paper's Fig. 8 case), and validated as a whole.
//!
//! Every table rejects unknown keys (`deny_unknown_fields`), so a typo is an error with a
//! line and column, not a silently ignored setting. Sections added by later capabilities
//! (e.g. `[probe]`, `[pixel]`) are `#[serde(default)]` fields of [`Config`].

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tofprobe_pixel::{PixelContext, PixelParams};
use tofprobe_scene::{AcquisitionConfig, PhotonSource, Scene, SceneConfig, SensorConfig};

use crate::error::CliError;

/// The embedded default configuration text (paper Fig. 8: 0.1 mm at 4.5 kHz on 30 mm,
/// σ_I = 50 ps, ρ_s = 1, ρ_b = 0, 1 s at 10 MHz).
pub const DEFAULT_TOML: &str = include_str!("../../../scenes/default.toml");

/// Name used in messages for the embedded default.
pub const DEFAULT_ORIGIN: &str = "<embedded default>";

/// Jitter σ on each side of the scene's depth range that `width = "auto"` sizes for (the
/// pixel crate's one sizing rule, also used by `tofprobe size`).
pub use tofprobe_pixel::sizing::SIZING_SIGMAS;

/// The configuration document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
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
}

/// A loaded, validated configuration together with where it came from.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The parsed document.
    pub config: Config,
    /// The file path, or [`DEFAULT_ORIGIN`].
    pub origin: String,
}

impl Config {
    /// Parses TOML text; `origin` names the source in error messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Config, CliError> {
        toml::from_str(text).map_err(|e| CliError::Toml {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        })
    }

    /// Loads `path`, or the embedded default when `path` is `None`, and validates it.
    pub fn load(path: Option<&Path>) -> Result<Loaded, CliError> {
        let (text, origin) = match path {
            None => (DEFAULT_TOML.to_string(), DEFAULT_ORIGIN.to_string()),
            Some(p) => (read_text(p)?, p.display().to_string()),
        };
        let config = Config::from_toml_str(&text, &origin)?;
        config.validate(&origin)?;
        Ok(Loaded { config, origin })
    }

    /// Validates every section and their consistency (the window must contain the scene,
    /// `[probe]` must be a valid design, `[pixel]` must resolve against the sensor, the
    /// acquisition and the scene); `origin` names the file in the error.
    pub fn validate(&self, origin: &str) -> Result<(), CliError> {
        let scene_err = |source| CliError::Scene {
            origin: origin.to_string(),
            source,
        };
        self.sensor.validate().map_err(scene_err)?;
        let scene = Scene::new(&self.scene).map_err(scene_err)?;
        self.acquisition
            .validate(self.sensor.laser_rate_hz)
            .map_err(scene_err)?;
        PhotonSource::new(&self.sensor, &scene, self.acquisition.seed).map_err(scene_err)?;
        self.probe.validate().map_err(|source| CliError::Probe {
            origin: origin.to_string(),
            source,
        })?;
        let frame = self.pixel.frame_pulses.unwrap_or(self.pulses());
        self.probe
            .check_frame(frame)
            .map_err(|source| CliError::Probe {
                origin: origin.to_string(),
                source,
            })?;
        self.pixel_params().map_err(|source| CliError::Pixel {
            origin: origin.to_string(),
            source,
        })?;
        Ok(())
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

    /// The resolved `[pixel]`: its ROM depth defaults to the `[probe]` design's (L = N in
    /// windowed mode, `probe.rom_depth` in periodic mode), so the pixel reads the ROM the
    /// probe design generates.
    pub fn pixel_params(&self) -> Result<PixelParams, tofprobe_pixel::PixelError> {
        let ctx = self.pixel_context();
        let mut px = self.pixel.clone();
        if px.rom_depth.is_none() {
            let n = px.frame_pulses.unwrap_or(ctx.pulses);
            px.rom_depth = Some(self.probe.depth(n));
        }
        px.resolve(&ctx)
    }

    /// The number of pulses N of the acquisition.
    pub fn pulses(&self) -> u64 {
        self.acquisition.pulses(self.sensor.laser_rate_hz)
    }

    /// Builds the photon source of this configuration.
    pub fn photon_source(&self) -> Result<PhotonSource, tofprobe_scene::SceneError> {
        let scene = Scene::new(&self.scene)?;
        PhotonSource::new(&self.sensor, &scene, self.acquisition.seed)
    }
}

impl Loaded {
    /// Wraps a scene error with this configuration's origin.
    pub fn error(&self, source: tofprobe_scene::SceneError) -> CliError {
        CliError::Scene {
            origin: self.origin.clone(),
            source,
        }
    }
}

/// Reads a file as UTF-8 text with a specific error for each way it can fail.
pub fn read_text(path: &Path) -> Result<String, CliError> {
    if path.is_dir() {
        return Err(CliError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let bytes = std::fs::read(path).map_err(|source| CliError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    String::from_utf8(bytes).map_err(|e| CliError::NotUtf8 {
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
        let loaded = Config::load(None).expect("default loads");
        let c = &loaded.config;
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
            let err = Config::from_toml_str(&text, "t.toml").expect_err("unknown key");
            let msg = err.to_string();
            assert!(msg.contains("colour"), "{msg}");
            assert!(msg.contains(&format!("line {line}")), "{msg}");
        }
        let extra_section = format!("{DEFAULT_TOML}\n[extra]\nx = 1\n");
        assert!(Config::from_toml_str(&extra_section, "t.toml").is_err());
    }
}
