//! One run of the paper reproduction (`tofprobe reproduce`): the shared ΣΔ probe ROM
//! generated once and passed to every Table 2 row, then every family's rows, and the
//! figures drawn from the same data, written as one output set (whole or absent).

use std::path::Path;
use std::time::Instant;

use super::chart::Chart;
use super::sigma_delta::ProbeSetup;
use super::{Row, band_spectra, bandwidth, fig4, figures, plots, table2, transients};
use crate::ExperimentError;

/// The rows, plots and timings of one run.
#[derive(Debug, Clone)]
pub struct Reproduction {
    /// Every row, in table order.
    pub rows: Vec<Row>,
    /// The plot files written (paths).
    pub plots: Vec<String>,
    /// The paper's figures among them: (figure, path), e.g. ("Fig. 4", "DIR/fig4_….svg").
    pub figures: Vec<(String, String)>,
    /// Pulses of the Table 2 records.
    pub table2_pulses: u64,
    /// Generating the shared ΣΔ probe ROM (design sweep included), s.
    pub rom_seconds: f64,
    /// All Table 2 rows (every column, every seed), s.
    pub table2_seconds: f64,
    /// Fig. 7/8's full-band ΣΔ probing and DFT, s.
    pub band_seconds: f64,
}

/// The figure a file draws ("Fig. 2" for `fig2_…`), none for Table 2's own plots.
pub fn figure_of(file: &str) -> Option<String> {
    let rest = file.strip_prefix("fig")?;
    let num: String = rest.chars().take_while(char::is_ascii_digit).collect();
    (!num.is_empty()).then(|| format!("Fig. {num}"))
}

/// Runs the reproduction (`quick`: short records) and writes the plots into `out`: every
/// SVG is rendered, staged and moved into place together (`tofprobe_io::OutputSet`, begun
/// before the simulation), so a failed run leaves the old set, never part of a new one.
pub fn reproduce(quick: bool, out: &Path) -> Result<Reproduction, ExperimentError> {
    let (n_t2, n_f4, n_bw) = if quick {
        (1 << 20, 1 << 17, 1 << 21)
    } else {
        (10_000_000, fig4::N, bandwidth::N)
    };
    // The set is begun first: an unusable --out fails before minutes of simulation, and a
    // failure anywhere below drops it (its stage, and the directory if it made it, removed).
    let mut set = tofprobe_io::OutputSet::begin(out).map_err(|e| io(out, e))?;
    let t_rom = Instant::now();
    // Generated once here; every row's ΣΔ columns read it.
    let probe = ProbeSetup::new(n_t2)?;
    let rom_seconds = t_rom.elapsed().as_secs_f64();
    let t_rows = Instant::now();
    let results = table2::run_all(&probe)?;
    let table2_seconds = t_rows.elapsed().as_secs_f64();
    let t_band = Instant::now();
    let step = if quick {
        band_spectra::QUICK_STEP_HZ
    } else {
        band_spectra::STEP_HZ
    };
    let band = band_spectra::measure(&probe, step)?;
    let band7 = band_spectra::measure_scene(&band_spectra::fig7_scene(), &probe, step)?;
    let band_seconds = t_band.elapsed().as_secs_f64();
    let design = probe.design.clone();
    drop(probe);
    let mut rows: Vec<Row> = results
        .iter()
        .flat_map(|r| table2::rows_of(r, quick))
        .collect();
    rows.extend(table2::eq12_row(&results, n_t2, quick));
    let f4 = fig4::points(n_f4)?;
    rows.extend(fig4::rows_of(&f4, n_f4));
    let corners = bandwidth::corners(n_bw)?;
    rows.extend(bandwidth::rows_of(&corners, n_bw));
    let figs = transients::figures()?;
    rows.extend(transients::rows(&figs));

    let mut charts: Vec<Chart> = vec![
        figures::fig2(&design.modulator, design.config.amplitude)?,
        figures::fig4_chart(&f4, n_f4),
        plots::fig5(&results, quick),
        figures::fig6(&corners, quick),
    ];
    charts.push(band_spectra::fig7(&band7, n_t2, quick)?);
    charts.push(band_spectra::fig8(&band, n_t2, quick)?);
    charts.push(plots::fig9(&results, quick));
    charts.extend(plots::charts(&results, quick));
    let mut files: Vec<(String, String)> = Vec::new();
    for c in &charts {
        files.push((c.file.clone(), c.render()?));
    }
    files.extend(transients::svgs(&figs)?);
    for (name, text) in &files {
        set.add(name, text.as_bytes()).map_err(|e| io(out, e))?;
    }
    set.commit(None).map_err(|e| io(out, e))?;
    let path = |name: &str| out.join(name).display().to_string();
    Ok(Reproduction {
        rows,
        plots: files.iter().map(|(n, _)| path(n)).collect(),
        figures: files
            .iter()
            .filter_map(|(n, _)| figure_of(n).map(|f| (f, path(n))))
            .collect(),
        table2_pulses: n_t2,
        rom_seconds,
        table2_seconds,
        band_seconds,
    })
}

fn io(dir: &Path, e: std::io::Error) -> ExperimentError {
    ExperimentError::Output {
        path: dir.to_path_buf(),
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn figure_names() {
        assert_eq!(
            super::figure_of("fig12_scalogram.svg").as_deref(),
            Some("Fig. 12")
        );
        assert_eq!(
            super::figure_of("fig2_probe_spectrum.svg").as_deref(),
            Some("Fig. 2")
        );
        assert_eq!(super::figure_of("spectra.svg"), None);
    }
}
