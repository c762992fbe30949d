//! The SVG of `tofprobe bench fullband --svg`: the ΣΔ-probed and DFT amplitude spectra of
//! the same record, µm (log) against Hz, one line each.

use std::path::Path;

use plotters::prelude::*;
use tofprobe_dsp::sd::fullband_spectrum::BandSpectrum;

use crate::BenchError;

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
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1000, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Full-band spectrum, {} bins: sigma-delta probing vs DFT ({origin})",
                    s.bins.len()
                ),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..f_max, (0.1f64..y_max).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .y_desc("amplitude (um)")
            .draw()
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(dft, &BLUE))
            .map_err(err)?
            .label("DFT")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        chart
            .draw_series(LineSeries::new(sd, &RED))
            .map_err(err)?
            .label("sigma-delta probing")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .configure_series_labels()
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    tofprobe_io::write_svg_atomic(path, text.as_bytes()).map_err(|e| BenchError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
