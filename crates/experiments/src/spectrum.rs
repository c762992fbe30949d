//! The bit-true spectrum of a resolved design (`tofprobe simulate`, the trade-off): its
//! probe ROM generated, one frame of the photon source through the transaction model
//! and, on request, the spectrum plotted to an SVG (written atomically).

use std::path::Path;

use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_io::chart::prelude::*;
use tofprobe_pixel::spectrum::{BitTrueSpectrum, bit_true_spectrum};
use tofprobe_pixel::{PixelError, PixelParams};
use tofprobe_scene::PhotonSource;

use crate::error::ExperimentError;

/// Everything needed to run the bit-true pixel on a design.
#[derive(Debug, Clone)]
pub struct BitTrueSetup {
    /// The resolved pixel.
    pub params: PixelParams,
    /// The generated probe ROM (bins in ROM order).
    pub rom: ProbeRom,
}

/// The design's pixel and its probe ROM (Fourier mode only).
pub fn setup(design: &ResolvedDesign) -> Result<BitTrueSetup, ExperimentError> {
    let Some(rom) = design.probe_rom()? else {
        return Err(DesignError::pixel(
            &design.origin,
            PixelError::mismatch("bit-true spectrum mode", design.pixel.mode, "fourier"),
        )
        .into());
    };
    Ok(BitTrueSetup {
        params: design.pixel.clone(),
        rom,
    })
}

/// Runs one frame of the design's photon source through the bit-true model.
pub fn run_spectrum(
    setup: &BitTrueSetup,
    source: &PhotonSource,
    lsb_mm: f64,
    origin: &str,
) -> Result<BitTrueSpectrum, ExperimentError> {
    bit_true_spectrum(&setup.params, &setup.rom, source, lsb_mm)
        .map_err(|e| DesignError::pixel(origin, e).into())
}

/// Plots amplitude (µm, log) against frequency (Hz) as stems, with the noise estimate as
/// a horizontal line, and writes the SVG atomically.
pub fn write_svg(
    path: &Path,
    title: &str,
    spectrum: &BitTrueSpectrum,
) -> Result<(), ExperimentError> {
    let err = |e: &dyn std::fmt::Display| ExperimentError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let pts: Vec<(f64, f64)> = spectrum
        .bins
        .iter()
        .map(|b| (b.frequency_hz, b.amplitude_um.max(1e-6)))
        .collect();
    if pts.is_empty() {
        return Err(err(&"no bins to plot"));
    }
    let x1 = pts.iter().fold(0.0f64, |m, p| m.max(p.0)) * 1.05;
    let y0 = pts.iter().fold(f64::INFINITY, |m, p| m.min(p.1)) * 0.5;
    let y1 = pts.iter().fold(0.0f64, |m, p| m.max(p.1)) * 2.0;
    let svg = svg((900, 520), |root| {
        let frame = Frame::new(title, 20)
            .margin(12)
            .axes("frequency (Hz)", "amplitude (µm)");
        let mut chart = frame.build(root, 0.0..x1, (y0..y1).log_scale())?;
        frame.draw_mesh(&mut chart)?;
        chart.draw_series(
            pts.iter()
                .map(|&(x, y)| PathElement::new(vec![(x, y0), (x, y)], BLUE.stroke_width(2))),
        )?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, BLUE.filled())))?
            .label("bit-true bins")
            .legend(|(x, y)| Circle::new((x, y), 4, BLUE.filled()));
        let noise = spectrum.median_amplitude_um.max(1e-6);
        chart
            .draw_series(LineSeries::new(vec![(0.0, noise), (x1, noise)], RED))?
            .label("noise estimate (median over bins)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        legend(&mut chart, SeriesLabelPosition::MiddleRight, 1.0, None)
    })
    .map_err(|e| err(&e))?;
    tofprobe_io::write_svg_atomic(path, svg.as_bytes()).map_err(|e| ExperimentError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Writes `bytes` to `path` atomically ([`tofprobe_io::write_atomic`]): the study's one
/// file writer.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExperimentError> {
    tofprobe_io::write_atomic(path, bytes).map_err(|e| ExperimentError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
