//! The bin chooser: which ROM bins k (f_k = k·f_s/L) a Fourier pixel probes — the
//! document's `frequencies_hz` rounded to the ROM's grid, else the scene's in-band tones
//! then noise bins (`tofprobe_pixel::autobins`), B in all.

use tofprobe_pixel::PixelError;
use tofprobe_pixel::autobins::{band_limit, choose_bins};

use crate::document::Document;

/// THE band rule, checked here for every caller (the resolution's OSR and ROM-depth checks
/// and the RTL's ROM policy): the ΣΔ band f_s/(2·OSR) must hold `bins` ROM bins
/// (k = 1 .. band edge, exclusive) at depth L; the refusal is one phrase they all print.
pub fn band_check(depth: u64, osr: f64, bins: usize) -> Result<(), String> {
    let limit = band_limit(depth, osr);
    if limit < bins as u64 + 1 {
        return Err(format!(
            "the ΣΔ band f_s/(2·OSR) holds {} bin(s) at L = {depth} and OSR = {osr}, fewer than B = {bins}",
            limit.saturating_sub(1)
        ));
    }
    Ok(())
}

/// The ROM bin indices of `doc` for B = `bins` bins and ROM depth L = `depth`. A band
/// f_s/(2·OSR) too narrow for B bins at L is refused naming `rom_depth`, with the
/// shallowest L that holds them.
pub fn bin_indices(doc: &Document, bins: usize, depth: u64) -> Result<Vec<u64>, PixelError> {
    bin_indices_in(doc, &doc.pixel_context(), bins, depth)
}

/// [`bin_indices`] with the document's pixel context already built (the resolution's).
pub fn bin_indices_in(
    doc: &Document,
    ctx: &tofprobe_pixel::PixelContext,
    bins: usize,
    depth: u64,
) -> Result<Vec<u64>, PixelError> {
    let fs = doc.sensor.laser_rate_hz;
    if !doc.pixel.frequencies_hz.is_empty() {
        return Ok(doc
            .pixel
            .frequencies_hz
            .iter()
            .map(|f| (f * depth as f64 / fs).round().max(1.0) as u64)
            .collect());
    }
    let osr = doc.probe.osr;
    if let Err(why) = band_check(depth, osr, bins) {
        return Err(PixelError::invalid(
            "rom_depth",
            depth,
            format!(
                "{why} (L is pixel.rom_depth, else probe.rom_depth in periodic mode, N in windowed mode)"
            ),
            min_depth(bins, osr),
        ));
    }
    Ok(choose_bins(&ctx.tones, fs, depth, osr, Some(bins))?.all())
}

/// The shallowest ROM depth whose ΣΔ band holds `bins` bins.
pub fn min_depth(bins: usize, osr: f64) -> u64 {
    let mut l = (2.0 * osr * bins as f64).floor().max(1.0) as u64;
    while band_limit(l, osr) < bins as u64 + 1 {
        l += 1;
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    /// OSR 32, B = 16: the band edge L/64 must exceed 16, so L = 1025 is the first depth
    /// (1024/64 = 16 is an integer edge, itself out of band); one below holds 15 bins.
    #[test]
    fn min_depth_is_the_first_that_holds_the_bins() {
        assert_eq!(min_depth(16, 32.0), 1025);
        assert_eq!(band_limit(1025, 32.0), 17);
        assert_eq!(band_limit(1024, 32.0), 16);
    }
}
