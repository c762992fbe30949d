//! The generated pixel as an [`RtlProvider`]: `tofprobe-rtlgen` renders the pixel module
//! for any (B, W) from a base `[pixel]` configuration. Only the pixel file is written and
//! synthesised: the chip-level probe ROM and the top are left out.

use crate::analysis::{RtlProvider, RtlVariant};
use crate::error::{EdaError, Result};
use crate::fsutil::write_atomic;
use std::path::Path;
use tofprobe_pixel::PixelParams;
use tofprobe_rtlgen::{RenderOptions, render};

/// Renders the generated pixel for (B, W), all other parameters from `base`.
#[derive(Debug, Clone)]
pub struct GeneratedPixel {
    /// The configured pixel.
    pub base: PixelParams,
}

impl GeneratedPixel {
    /// The parameters of the (B, W) variant. C is raised to the schedule's minimum
    /// ⌈2B / A⌉ when the sweep asks for more bins than the configured C can serve (the
    /// contract rejects K > C), so a B sweep stays synthesisable.
    pub fn variant_params(&self, bins: u64, width: u32) -> Result<PixelParams> {
        let mut p = self.base.clone();
        p.bins = usize::try_from(bins).map_err(|_| EdaError::OutOfRange {
            field: "bins",
            value: bins.to_string(),
            allowed: "fits usize".into(),
        })?;
        p.width = width;
        p.cycles_per_pulse = p.cycles_per_pulse.max(p.slots());
        p.validate().map_err(|e| EdaError::OutOfRange {
            field: "pixel variant (B, W)",
            value: format!("B={bins} W={width}"),
            allowed: e.to_string(),
        })?;
        Ok(p)
    }

    /// Name of the pixel module.
    pub fn top(&self) -> String {
        tofprobe_rtlgen::module_names(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX).0
    }
}

impl RtlProvider for GeneratedPixel {
    fn rtl(&self, bins: u64, width: u32, dir: &Path) -> Result<RtlVariant> {
        let mut p = self.variant_params(bins, width)?;
        // The pixel module depends on neither the ROM's contents nor its depth L (rom_word
        // is a port); rendering with L = 1 avoids building the chip-level ROM's N-entry
        // table (10^7 lines at the default) just to throw it away. Only the header comment
        // of the pixel file differs from `tofprobe rtl`'s.
        p.rom_depth = 1;
        let rom = vec![0u64; p.rom_depth * p.registers().div_ceil(64)];
        let files =
            render(&p, &rom, &RenderOptions::default()).map_err(|e| EdaError::OutOfRange {
                field: "pixel variant (B, W)",
                value: format!("B={bins} W={width}"),
                allowed: e.to_string(),
            })?;
        let top = tofprobe_rtlgen::module_names(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX).0;
        let pixel = files
            .iter()
            .find(|f| f.template == "pixel.v")
            .ok_or_else(|| EdaError::Parse {
                tool: "tofprobe-rtlgen",
                what: "the rendered pixel.v",
                tail: String::new(),
            })?;
        let path = dir.join(&pixel.name);
        write_atomic(&path, pixel.contents.as_bytes())?;
        Ok(RtlVariant {
            sources: vec![path],
            top,
            params: vec![],
        })
    }

    fn with_adders(
        &self,
        adders: u64,
        cycles_per_pulse: u64,
    ) -> Result<Option<Box<dyn RtlProvider>>> {
        let mut base = self.base.clone();
        let (Ok(a), Ok(c)) = (usize::try_from(adders), usize::try_from(cycles_per_pulse)) else {
            return Ok(None);
        };
        base.adders = a;
        base.cycles_per_pulse = c;
        Ok(base
            .validate()
            .ok()
            .map(|()| Box::new(GeneratedPixel { base }) as Box<dyn RtlProvider>))
    }
}
