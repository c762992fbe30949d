//! The bit-true spectrum of a configuration for `tofprobe simulate`: resolves `[pixel]`
//! and `[probe]`, picks the ROM bins (explicit `frequencies_hz`, else from the scene's
//! tones plus noise bins), generates the probe ROM, runs the transaction model over one
//! frame and, on request, plots the spectrum to an SVG (written atomically).

use std::path::Path;

use plotters::prelude::*;
use tofprobe_dsp::sd::{ProbeDesign, ProbeRom};
use tofprobe_pixel::autobins::choose_bins;
use tofprobe_pixel::spectrum::{BitTrueSpectrum, bit_true_spectrum};
use tofprobe_pixel::{Mode, PixelError, PixelParams};
use tofprobe_scene::PhotonSource;

use crate::config::Config;
use crate::error::CliError;

/// Everything needed to run the bit-true pixel on a configuration.
#[derive(Debug, Clone)]
pub struct BitTrueSetup {
    /// The resolved pixel.
    pub params: PixelParams,
    /// The generated probe ROM (bins in ROM order).
    pub rom: ProbeRom,
}

/// The ROM bin indices of a configuration for B bins and depth L: `frequencies_hz`
/// rounded to k·f_s/L, else the scene's in-band tones then noise bins, B in all.
pub fn bin_indices(config: &Config, bins: usize, depth: u64) -> Result<Vec<u64>, PixelError> {
    let fs = config.sensor.laser_rate_hz;
    if !config.pixel.frequencies_hz.is_empty() {
        return Ok(config
            .pixel
            .frequencies_hz
            .iter()
            .map(|f| (f * depth as f64 / fs).round().max(1.0) as u64)
            .collect());
    }
    let ctx = config.pixel_context();
    Ok(choose_bins(&ctx.tones, fs, depth, config.probe.osr, Some(bins))?.all())
}

/// What a bit-true setup needs before the ROM: the resolved pixel (Fourier mode only), its
/// bin indices and the lowest bin's f/f_s, where the probe amplitude's stability limit is
/// checked (it is lowest towards DC).
pub fn resolve(config: &Config, origin: &str) -> Result<(PixelParams, Vec<u64>, f64), CliError> {
    let pixel_err = |source| CliError::Pixel {
        origin: origin.to_string(),
        source,
    };
    let params = config.pixel_params().map_err(pixel_err)?;
    if params.mode != Mode::Fourier {
        return Err(pixel_err(PixelError::mismatch(
            "bit-true spectrum mode",
            params.mode,
            "fourier",
        )));
    }
    let bins = bin_indices(config, params.bins, params.rom_depth as u64).map_err(pixel_err)?;
    let lowest = bins.iter().copied().min().unwrap_or(1).max(1);
    let f_norm = lowest as f64 / params.rom_depth as f64;
    Ok((params, bins, f_norm))
}

/// Resolves the pixel and generates its ROM (Fourier mode only).
pub fn setup(config: &Config, origin: &str) -> Result<BitTrueSetup, CliError> {
    let probe_err = |source| CliError::Probe {
        origin: origin.to_string(),
        source,
    };
    let (params, bins, f_norm) = resolve(config, origin)?;
    let fs = config.sensor.laser_rate_hz;
    let design = ProbeDesign::new(&config.probe, f_norm).map_err(probe_err)?;
    let rom = ProbeRom::generate(&design, fs, params.frame_pulses, &bins).map_err(probe_err)?;
    Ok(BitTrueSetup { params, rom })
}

/// Runs one frame of the configuration's photon source through the bit-true model.
pub fn run_spectrum(
    setup: &BitTrueSetup,
    source: &PhotonSource,
    lsb_mm: f64,
    origin: &str,
) -> Result<BitTrueSpectrum, CliError> {
    bit_true_spectrum(&setup.params, &setup.rom, source, lsb_mm).map_err(|source| CliError::Pixel {
        origin: origin.to_string(),
        source,
    })
}

/// Plots amplitude (µm, log) against frequency (Hz) as stems, with the noise estimate as
/// a horizontal line, and writes the SVG atomically.
pub fn write_svg(path: &Path, title: &str, spectrum: &BitTrueSpectrum) -> Result<(), CliError> {
    let err = |e: &dyn std::fmt::Display| CliError::Output {
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
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..x1, (y0..y1).log_scale())
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .y_desc("amplitude (µm)")
            .draw()
            .map_err(|e| err(&e))?;
        chart
            .draw_series(
                pts.iter()
                    .map(|&(x, y)| PathElement::new(vec![(x, y0), (x, y)], BLUE.stroke_width(2))),
            )
            .map_err(|e| err(&e))?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, BLUE.filled())))
            .map_err(|e| err(&e))?
            .label("bit-true bins")
            .legend(|(x, y)| Circle::new((x, y), 4, BLUE.filled()));
        let noise = spectrum.median_amplitude_um.max(1e-6);
        chart
            .draw_series(LineSeries::new(vec![(0.0, noise), (x1, noise)], RED))
            .map_err(|e| err(&e))?
            .label("noise estimate (median over bins)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .configure_series_labels()
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    write_atomic(path, svg.as_bytes())
}

/// Writes `bytes` to `path` atomically ([`tofprobe_io::write_atomic`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    tofprobe_io::write_atomic(path, bytes).map_err(|e| CliError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
