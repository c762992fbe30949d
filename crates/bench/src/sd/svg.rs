//! The SVG of `bench sd --svg`: the output spectrum of a 50 kHz probe (the paper's
//! Fig. 2: the noise shaping).

use std::path::Path;

use tofprobe_dsp::sd::Modulator;
use tofprobe_dsp::sd::quality::ToneSpectrum;

use super::{FS_HZ, err};
use crate::BenchError;
use tofprobe_io::chart::prelude::*;

/// The output spectrum of a 50 kHz, amplitude-0.5 probe (2^16 samples, Hann), dB vs
/// log frequency, with the band edge f_s/(2·OSR) marked.
pub(crate) fn write(m: &Modulator, path: &Path) -> Result<(), BenchError> {
    let n = 1usize << 16;
    let tone = (50_000.0 / FS_HZ * n as f64).round() as usize;
    let sp = ToneSpectrum::measure(m, 0.5, tone, n).map_err(err)?;
    let pts: Vec<(f64, f64)> = sp
        .power
        .iter()
        .enumerate()
        .skip(1)
        .map(|(k, p)| (k as f64 * FS_HZ / n as f64, 10.0 * p.max(1e-20).log10()))
        .collect();
    let band = FS_HZ / (2.0 * m.osr);
    let text = svg((900, 500), |root| {
        let frame = Frame::new(
            "Output spectrum of a 50 kHz probe (order 3, OSR 32, H_inf 1.5)",
            18,
        )
        .label_areas(40, 50)
        .axes("frequency (Hz)", "power per bin (dB re full-scale sine)");
        let mut chart = frame.build(root, (150.0f64..5e6).log_scale(), -160.0f64..0.0)?;
        frame.draw_mesh(&mut chart)?;
        chart.draw_series(LineSeries::new(pts.iter().copied(), &BLUE))?;
        chart
            .draw_series(LineSeries::new(vec![(band, -160.0), (band, 0.0)], &RED))?
            .label("f_s / (2 OSR) = 156 kHz");
        Ok(())
    })
    .map_err(err)?;
    tofprobe_io::write_svg_atomic(path, text.as_bytes()).map_err(|e| BenchError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
