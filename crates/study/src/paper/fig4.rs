//! Fig. 4: the noise floor at σ_I = 2 / 20 / 200 ps, N = 10^6, ρ_s = 1, no background.
//! The paper's 0.53 / 5.3 / 53 µm hold for a rectangular window; with Blackman they are
//! 0.70 / 6.98 / 69.8 µm (N_eff = 0.579 N). The TDC LSB is 0.01 mm here (a²/12 adds 1e-4
//! of σ_I² at 2 ps), so σ_s = σ_I; one record serves both windows.

use rayon::prelude::*;
use tofprobe_dsp::Window;
use tofprobe_dsp::closed_form::{noise_floor_mm, sigma_total_mm};
use tofprobe_dsp::dft::amplitude_spectrum;
use tofprobe_dsp::stats::{NoiseBand, noise_floor};
use tofprobe_scene::MM_PER_PS;

use super::setup::{FS_HZ, Setup};
use super::{Row, Tolerance};
use crate::StudyError;
use crate::records::held_record;

/// (σ_I ps, paper rectangular µm, corrected Blackman µm).
pub const POINTS: &[(f64, f64, f64)] = &[(2.0, 0.53, 0.70), (20.0, 5.3, 6.98), (200.0, 53.0, 69.8)];
/// Record length of the figure.
pub const N: u64 = 1_000_000;
const LSB_MM: f64 = 0.01;
/// White noise: any band away from DC; 1 kHz – 1 MHz (99,000 bins at 10 Hz).
const BAND: (f64, f64) = (1_000.0, 1_000_000.0);

fn one(sigma_i_ps: f64, paper: f64, blackman: f64, n: u64) -> Result<Vec<Row>, StudyError> {
    let jitter = sigma_i_ps * MM_PER_PS;
    let sigma_s = sigma_total_mm(jitter, LSB_MM);
    let setup = Setup {
        sigma_s_mm: sigma_s,
        lsb_mm: LSB_MM,
        rho_s: 1.0,
        rho_b: 0.0,
        window_mm: Setup::window_for(sigma_s, 0.0),
        tone: None,
    };
    let source = setup.source(0)?;
    let det = source.record(n);
    let held = held_record(&source, &det, setup.depth_mm())?;
    let mut rows = Vec::new();
    for (w, paper_v, design_v) in [
        (Window::Rectangular, Some(paper), None),
        (Window::Blackman, None, Some(blackman)),
    ] {
        let s = amplitude_spectrum(&held, w)?;
        let band = NoiseBand::new(BAND.0, BAND.1);
        let measured = noise_floor(&s, held.len(), FS_HZ, &band, &[])? * 1e3;
        let cf = noise_floor_mm(sigma_s, n as f64 * w.effective_length_factor()) * 1e3;
        let quick = n != N;
        rows.push(Row::judge(
            "Fig. 4",
            format!("σ_I={sigma_i_ps} ps, {}", w.name()),
            "µm",
            paper_v.filter(|_| !quick),
            design_v.filter(|_| !quick),
            measured,
            Some(cf),
            Tolerance::Relative { rel: 0.05 },
            format!("N={n}"),
        ));
    }
    Ok(rows)
}

/// The Fig. 4 rows (record length `n`; the figure's is [`N`]).
pub fn rows(n: u64) -> Result<Vec<Row>, StudyError> {
    let per: Result<Vec<Vec<Row>>, StudyError> = POINTS
        .par_iter()
        .map(|&(s, p, b)| one(s, p, b, n))
        .collect();
    Ok(per?.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    /// Short records (2^16 pulses, ≈ 6500 band bins: standard error ≈ 1%): every Fig. 4
    /// row is within 5% of eq. 12 for both windows.
    #[test]
    fn short_fig4_rows_match_eq12() {
        let rows = super::rows(1 << 16).unwrap();
        assert_eq!(rows.len(), 6);
        for r in rows {
            assert!(r.pass, "{r:?}");
        }
    }
}
