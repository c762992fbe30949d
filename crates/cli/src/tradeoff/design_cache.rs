//! The bit-true setup of many knob settings with the ΣΔ probe design shared: the design's
//! stability sweep is the expensive part of a setup (seconds in a debug build) and depends
//! only on `[probe]` and the lowest normalised bin, which most knob settings (W, F, S, B)
//! leave alone. Resolves like [`crate::commands::spectrum_svg::setup`] (its `resolve`).

use tofprobe_dsp::sd::{ProbeDesign, ProbeRom};

use crate::commands::spectrum_svg::{BitTrueSetup, resolve};
use crate::config::Config;
use crate::error::CliError;

/// Designs already made, keyed by the `[probe]` section and the lowest bin's f/f_s.
#[derive(Default)]
pub struct DesignCache {
    designs: Vec<(String, u64, ProbeDesign)>,
}

impl DesignCache {
    /// Resolves the pixel of `config` and generates its ROM, reusing a cached design.
    pub fn setup(&mut self, config: &Config, origin: &str) -> Result<BitTrueSetup, CliError> {
        let probe_err = |source| CliError::Probe {
            origin: origin.to_string(),
            source,
        };
        let (params, bins, f_norm) = resolve(config, origin)?;
        let key = format!("{:?}", config.probe);
        let pos = self
            .designs
            .iter()
            .position(|(k, f, _)| *k == key && *f == f_norm.to_bits());
        let design = match pos {
            Some(i) => &self.designs[i].2,
            None => {
                let d = ProbeDesign::new(&config.probe, f_norm).map_err(probe_err)?;
                self.designs.push((key, f_norm.to_bits(), d));
                &self.designs[self.designs.len() - 1].2
            }
        };
        let rom = ProbeRom::generate(
            design,
            config.sensor.laser_rate_hz,
            params.frame_pulses,
            &bins,
        )
        .map_err(probe_err)?;
        Ok(BitTrueSetup { params, rom })
    }

    /// Number of distinct designs made so far.
    #[cfg(test)]
    pub fn designs(&self) -> usize {
        self.designs.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::spectrum_svg::setup;
    use crate::config::{DEFAULT_ORIGIN, DEFAULT_TOML};

    #[test]
    fn cached_setup_equals_the_plain_one_and_reuses_the_design() {
        let mut c = Config::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN).expect("default");
        c.acquisition.pulses = Some(4096);
        c.acquisition.duration_s = None;
        let mut cache = DesignCache::default();
        let a = cache.setup(&c, "t").expect("setup");
        let plain = setup(&c, "t").expect("setup");
        assert_eq!(a.params, plain.params);
        assert_eq!(a.rom, plain.rom);
        // F does not touch [probe] or the bins: same design, same ROM.
        c.pixel.frac_bits = 4;
        let b = cache.setup(&c, "t").expect("setup");
        assert_eq!(cache.designs(), 1);
        assert_eq!(b.rom, a.rom);
    }
}
