//! Table 2's verdict rows of the DFT column — noise, "A meas.", SNR — each judged against
//! its closed form (the paper's value where there is none) with the paper's printed value
//! beside it, flagged as an erratum when the seeds put it off; the probe columns' rows
//! (`super::super::sigma_delta::rows`); and the eq. 12 row.

use tofprobe_dsp::closed_form::noise_floor_mm;

use super::super::sigma_delta;
use super::super::stats::{self, K, SeedStats};
use super::super::{Row, Tolerance};
use super::{AMP_MIN_SNR, BAND, F0_HZ, NOISE_REL, PEAK_BAND, ROWS, RowResult, WINDOW};

/// The note on the paper's value of a row: "ERRATUM" where its z against the seeds' mean
/// exceeds K, with the difference in % of the mean; in a `--quick` run (records too short
/// to compare with the paper's 10^7 pulses) that it is shown, not compared.
pub fn paper_note(paper: Option<f64>, st: &SeedStats, quick: bool) -> String {
    match (paper, st.z_paper) {
        (Some(p), _) if quick => {
            format!("paper {p} shown (N = 10^7), not compared with this short record; ")
        }
        (Some(p), Some(z)) if z.abs() > K => format!(
            "ERRATUM: paper {p} is {:+.1}% from the mean (z = {z:+.1}); ",
            (p / st.mean - 1.0) * 100.0
        ),
        _ => String::new(),
    }
}

/// The paper's value for seed statistics: compared (z-score) only on full records.
fn compared(paper: f64, quick: bool) -> Option<f64> {
    (!quick).then_some(paper)
}

/// The noise row of a row result: the DFT floor's mean over the seeds against the closed
/// form, tolerance K·se with the sd of one seed the larger of the measured one and
/// floor·sqrt((4/π − 1)·Σ|γ|²/M) (`stats`), M the band bins.
pub fn noise_row(r: &RowResult, quick: bool) -> Row {
    let paper = r.spec.printed.noise_um.dft;
    let sd_pred = r.closed_form_um * stats::floor_rel_sd(r.band_bins, WINDOW);
    let st = stats::seed_stats(
        &r.noises_um,
        sd_pred,
        compared(paper, quick),
        Some(r.closed_form_um),
    );
    Row::judge(
        "Table 2 noise",
        r.spec.label(),
        "µm",
        Some(paper),
        None,
        st.mean,
        Some(r.closed_form_um),
        Tolerance::Seeds { k: K, se: st.se },
        format!(
            "{}DFT, {} bins; predicted sd of one seed {sd_pred:.3}; window {} mm, σ_I {:.3} mm",
            paper_note(Some(paper), &st, quick),
            r.band_bins,
            r.spec.setup().window_mm,
            r.spec.setup().jitter_mm().unwrap_or(f64::NAN)
        ),
    )
    .with_seeds(&r.seeds, &st, Some(BAND))
}

/// The "A meas." row of the DFT column. With a tone: the mean over the seeds against the
/// closed form, tolerance K·se. The closed form is the expected reading of a tone
/// g·|H(ρ_v, ω0)|·A in noise of the row's floor: the Rician mean E|A_eff + n|
/// (`stats::rician_mean`). A tone's amplitude error is the noise's projection on the
/// tone's phase, variance E|n|²/2 = (2/π)·floor², so one seed's sd is at least
/// floor·sqrt(2/π) ≈ 0.80·floor. Below A_eff = [`AMP_MIN_SNR`]·floor the ±2-bin peak
/// search reads the largest of five noise bins rather than the tone (a bias the Rician
/// mean does not model), so such rows are shown with their z-scores and not tested.
/// Without a tone "A meas." is the spectrum's largest value over [`PEAK_BAND`]
/// ([`largest_value_row`]).
pub fn amplitude_row(r: &RowResult, quick: bool) -> Option<Row> {
    if r.amps_um.len() < 2 {
        return None;
    }
    let paper = r.spec.printed.amp_um.dft;
    let floor = r.closed_form_um;
    if r.spec.amp_um.is_none() {
        return Some(largest_value_row(
            "Table 2 amplitude",
            r,
            &r.amps_um,
            &r.seeds,
            paper,
            floor,
            quick,
            "DFT: the largest bin",
        ));
    }
    let sd_pred = floor * (2.0 / std::f64::consts::PI).sqrt();
    let expected = r.amp_closed_um.map(|a| stats::rician_mean(a, floor));
    let st = stats::seed_stats(&r.amps_um, sd_pred, compared(paper, quick), expected);
    let snr = r.amp_closed_um.unwrap_or(0.0) / floor;
    let (tol, why) = if snr >= AMP_MIN_SNR {
        (Tolerance::Seeds { k: K, se: st.se }, String::new())
    } else {
        (
            Tolerance::Untested,
            format!(
                "NOT TESTED: A_eff/floor = {snr:.2} < {AMP_MIN_SNR} (peak search reads noise); "
            ),
        )
    };
    Some(
        Row::judge(
            "Table 2 amplitude",
            r.spec.label(),
            "µm",
            Some(paper),
            None,
            st.mean,
            expected,
            tol,
            format!(
                "{why}{}closed form E|A_eff + n| with A_eff = g·|H|·A = {:.2}; DFT interpolated peak at {F0_HZ} Hz; per seed {:?}; predicted sd {sd_pred:.2}",
                paper_note(Some(paper), &st, quick),
                r.amp_closed_um.unwrap_or(f64::NAN),
                r.amps_um.iter().map(|a| (a * 100.0).round() / 100.0).collect::<Vec<_>>()
            ),
        )
        .with_seeds(&r.seeds, &st, None),
    )
}

/// "A meas." of a row without a tone (any column): the largest value over [`PEAK_BAND`],
/// judged against the closed form for the largest of M Rayleigh bins in the column's
/// floor `floor` (`closed_form::largest_bin_um`), K·se with one seed's sd at least the
/// closed form's. The paper's values, 2.93–3.99 floors (3.29 on average), are what the
/// largest of ≈ 2,000 bins gives (3.23 floors), not of the ≈ 19,000 bins of 1 Hz from 1
/// to 20 kHz (3.65): its spectra were read on a coarser grid than their 1 Hz bins.
#[allow(clippy::too_many_arguments)]
pub fn largest_value_row(
    family: &'static str,
    r: &RowResult,
    values: &[f64],
    seeds: &[u64],
    paper: f64,
    floor: f64,
    quick: bool,
    how: &str,
) -> Row {
    let m = super::peak_band_bins(r.pulses as usize);
    let (expected, sd_pred) = super::largest_bin_um(floor, m);
    let st = stats::seed_stats(values, sd_pred, compared(paper, quick), Some(expected));
    let (coarse, _) = super::largest_bin_um(floor, 2000);
    Row::judge(
        family,
        r.spec.label(),
        "µm",
        Some(paper),
        None,
        st.mean,
        Some(expected),
        Tolerance::Seeds { k: K, se: st.se },
        format!(
            "{}no tone: \"A meas.\" = the spectrum's largest value over {}–{} Hz, interpolated \
             (the paper's definition); {how}; closed form: the largest of {m} Rayleigh bins in \
             the floor {floor:.3} ({:.2} floors, sd {sd_pred:.3}); the largest of 2,000 would \
             be {coarse:.2} ({:.2} floors): the paper's values fit a coarser grid than 1 Hz",
            paper_note(Some(paper), &st, quick),
            PEAK_BAND.0,
            PEAK_BAND.1,
            expected / floor,
            coarse / floor,
        ),
    )
    .with_seeds(seeds, &st, Some(PEAK_BAND))
}

/// 20·log10(2/√π): a Rayleigh |Y|'s rms over its mean, in dB.
pub fn rms_over_mean_db() -> f64 {
    20.0 * (2.0 / std::f64::consts::PI.sqrt()).log10()
}

/// The SNR row of any column (tone rows): per seed 20·log10(A meas./noise) of that seed's
/// own amplitude and floor (the paper's caption), mean ± sd, judged against the closed
/// form `snr_closed` (`closed_form::snr_closed_db`) with K·se, the sd of one seed at least
/// the delta method's 8.69·sqrt((2/π)·floor²/A² + rel²). The printed SNRs are all
/// 1.03–1.10 dB below the caption's formula on the paper's own printed A meas. and noise:
/// 20·log10(2/√π) = 1.05 dB, the noise's rms in place of its mean. That erratum is said on
/// every SNR row, with the caption's value of the printed numbers as the corrected one.
#[allow(clippy::too_many_arguments)]
pub fn snr_row(
    family: &'static str,
    r: &RowResult,
    per_seed: &[(f64, f64)],
    seeds: &[u64],
    floor: f64,
    floor_rel_sd: f64,
    paper: (f64, f64, f64),
    quick: bool,
) -> Option<Row> {
    let a_eff = r.amp_closed_um?;
    if per_seed.len() < 2 {
        return None;
    }
    let (printed, a_printed, n_printed) = paper;
    let snrs: Vec<f64> = per_seed
        .iter()
        .map(|&(a, n)| 20.0 * (a / n).log10())
        .collect();
    let m = stats::rician_mean(a_eff, floor);
    let db = 20.0 / std::f64::consts::LN_10;
    let sd_pred =
        db * ((2.0 / std::f64::consts::PI) * floor * floor / (m * m) + floor_rel_sd.powi(2)).sqrt();
    let closed = super::snr_closed_db(a_eff, floor, floor_rel_sd);
    let st = stats::seed_stats(&snrs, sd_pred, compared(printed, quick), Some(closed));
    let caption = 20.0 * (a_printed / n_printed).log10();
    let tol = if a_eff / floor >= AMP_MIN_SNR {
        Tolerance::Seeds { k: K, se: st.se }
    } else {
        Tolerance::Untested
    };
    let row = Row::judge(
        family,
        r.spec.label(),
        "dB",
        Some(printed),
        Some(caption),
        st.mean,
        Some(closed),
        tol,
        format!(
            "{}{}ERRATUM (definition): the printed SNR is {:.2} dB below its caption's \
             20·log10(A meas./Noise) of the printed values, {caption:.2} dB (shown as corrected): \
             20·log10(2/√π) = {:.2} dB, the noise's rms (2/√π)·mean|Y| in place of the mean; \
             measured: the caption's formula per seed; closed form 20·log10(E|A_eff + n|/floor) \
             + delta-method terms, A_eff = {a_eff:.2}, floor {floor:.3}; predicted sd {sd_pred:.3}",
            if matches!(tol, Tolerance::Untested) {
                format!(
                    "NOT TESTED: A_eff/floor = {:.2} < {AMP_MIN_SNR}; ",
                    a_eff / floor
                )
            } else {
                String::new()
            },
            paper_note(Some(printed), &st, quick),
            caption - printed,
            rms_over_mean_db()
        ),
    )
    .with_seeds(seeds, &st, None);
    Some(row)
}

/// The DFT column's SNR row.
fn dft_snr_row(r: &RowResult, quick: bool) -> Option<Row> {
    let printed = r.spec.printed.snr_db?;
    let per_seed: Vec<(f64, f64)> = r
        .amps_um
        .iter()
        .copied()
        .zip(r.noises_um.iter().copied())
        .collect();
    snr_row(
        "Table 2 SNR",
        r,
        &per_seed,
        &r.seeds,
        r.closed_form_um,
        stats::floor_rel_sd(r.band_bins, WINDOW),
        (
            printed.dft,
            r.spec.printed.amp_um.dft,
            r.spec.printed.noise_um.dft,
        ),
        quick,
    )
}

/// The table rows of one row result: the DFT column's noise, "A meas." and SNR, then the
/// probe columns' rows.
pub fn rows_of(r: &RowResult, quick: bool) -> Vec<Row> {
    let mut out = vec![noise_row(r, quick)];
    out.extend(amplitude_row(r, quick));
    out.extend(dft_snr_row(r, quick));
    out.extend(sigma_delta::rows(r, quick));
    out
}

/// The eq. 12 row: the paper's 2.21 µm prediction beside its 2.25 µm simulation, at
/// σ_s = 3 mm, N = 10^7, Blackman (the first row of [`ROWS`]).
pub fn eq12_row(results: &[RowResult], n: u64, quick: bool) -> Option<Row> {
    let r = results.iter().find(|r| r.spec == ROWS[0])?;
    let n_eff = n as f64 * WINDOW.effective_length_factor();
    let predicted = noise_floor_mm(r.spec.sigma_s_mm, n_eff) * 1e3;
    Some(Row::judge(
        "eq. 12",
        "σ_s=3 mm, Blackman: simulation vs prediction".into(),
        "µm",
        (!quick).then_some(r.spec.printed.noise_um.dft),
        None,
        stats::mean_sd(&r.noises_um).0,
        Some(predicted),
        Tolerance::Relative { rel: NOISE_REL },
        format!(
            "paper predicts 2.21; sqrt(π σ²/N_eff) with N_eff = {:.4}·N = {predicted:.3}",
            WINDOW.effective_length_factor()
        ),
    ))
}
