//! The SVG of `tofprobe bench fullband --svg`: the ΣΔ-probed and DFT amplitude spectra of
//! the same record, µm (log) against Hz, one line each.

use std::path::Path;

use tofprobe_dsp::sd::fullband_spectrum::BandSpectrum;

use crate::BenchError;
use tofprobe_io::chart::prelude::*;

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::internal("fullband --svg", e)
}

/// Writes the plot atomically.
pub(crate) fn write(path: &Path, s: &BandSpectrum, origin: &str) -> Result<(), BenchError> {
    let um = |v: Vec<f64>| -> Vec<(f64, f64)> {
        s.frequencies_hz
            .iter()
            .zip(v)
            .map(|(&f, a)| (f, (a * 1000.0).max(1e-3)))
            .collect()
    };
    let (sd, dft) = (
        um(s.sd.iter().map(|y| y.norm()).collect()),
        um(s.dft.iter().map(|y| y.norm()).collect()),
    );
    let f_max = s.frequencies_hz.last().copied().unwrap_or(1.0).max(1.0);
    let y_max = sd.iter().chain(&dft).map(|p| p.1).fold(1.0, f64::max) * 2.0;
    let text = svg((1000, 520), |root| {
        let frame = Frame::new(
            format!(
                "Full-band spectrum, {} bins: sigma-delta probing vs DFT ({origin})",
                s.bins.len()
            ),
            18,
        )
        .axes("frequency (Hz)", "amplitude (um)");
        let mut chart = frame.build(root, 0.0..f_max, (0.1f64..y_max).log_scale())?;
        frame.draw_mesh(&mut chart)?;
        chart
            .draw_series(LineSeries::new(dft, &BLUE))?
            .label("DFT")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        chart
            .draw_series(LineSeries::new(sd, &RED))?
            .label("sigma-delta probing")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        legend(&mut chart, SeriesLabelPosition::MiddleRight, 1.0, None)
    })
    .map_err(err)?;
    tofprobe_io::write_svg_atomic(path, text.as_bytes()).map_err(|e| BenchError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
