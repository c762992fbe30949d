//! The verdict rows of Table 2's probe columns — the float ΣΔ and the bit-true pixel — on
//! their own seeds: noise, "A meas." and SNR, each beside the paper's ΣΔ value and judged
//! twice: against the closed form (physics: a biased probe fails there even if the DFT of
//! its records shared the bias) and against the same records read by the DFT on the same
//! bins (`same_record_dft`: the probe's own error, free of sampling noise). Plus the ΣΔ
//! read without the prefilter and, in the bit-true noise row, the register check.
//!
//! The probe's closed form: the depth noise of eq. 12 (mixture, hold, Blackman N_eff) on
//! the probe's own bins (`table2::closed_form_noise_on_bins_um`), with the probe's own
//! error added in power: |Y_probe|² = |Y_dft|² + |e|², e the ΣΔ quantisation noise mixed
//! with the prefiltered depth, independent of the depth noise at the bin. Its share
//! ε² = Σ|Y_probe − Y_dft|²/Σ|Y_dft|² is read on the same records (the only measured part:
//! ε ≈ 0.1–0.2, so sqrt(1 + ε²) moves the floor by 0.5–2 %; a gain error of the probe
//! leaves ε² nearly unchanged — 5 % moves it by 0.0025 — and fails the closed form).

use super::super::stats::{self, K};
use super::super::table2::{
    self, AMP_MIN_SNR, F0_HZ, Measurement, ProbeRun, RowResult, SD, closed_form_noise_on_bins_um,
};
use super::super::{Row, Tolerance};
use super::{FRAC_BITS, NOISE_SPAN_HZ, SHIFT, bt_diff_um, error_um, noise_um, probe_bins};

/// A probe's noise within this of the same records' DFT noise on the same bins (issue 4).
pub const NOISE_REL: f64 = 0.03;
/// A probe's tone amplitude within this of the same records' DFT at the same bin.
pub const AMP_REL: f64 = 0.01;
/// "Several times the floor": the unprefiltered ΣΔ error must be at least this many
/// noise floors. DESIGN.md reports ≈ 6×, the dsp unit test 4.9× on white noise; 3× keeps
/// a margin below both while staying an order of magnitude above the prefiltered error
/// (≈ 0.2×), so the row fails if the prefilter stopped mattering.
pub const RAW_FACTOR_MIN: f64 = 3.0;
/// The design value of that factor (DESIGN.md).
pub const RAW_FACTOR_DESIGN: f64 = 6.0;

/// What a probe column's closed forms need: its floor on its noise bins and at the tone
/// bin (µm, ε included), ε² and the relative sd of one record's floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeClosedForm {
    pub floor_um: f64,
    pub tone_floor_um: f64,
    pub eps2: f64,
    pub floor_rel_sd: f64,
}

/// The closed forms of a probe column of row `r` (module doc).
pub fn probe_closed_form(r: &RowResult, run: &ProbeRun) -> ProbeClosedForm {
    let n = r.pulses;
    let bins = probe_bins(n);
    let cf = |b: &[u64]| closed_form_noise_on_bins_um(&r.spec, n as usize, b).unwrap_or(f64::NAN);
    let (mut err, mut dft) = (0.0, 0.0);
    for rec in &run.records {
        for (p, d) in rec.probe.phasors.iter().zip(&rec.dft.phasors).skip(1) {
            err += (p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2);
            dft += d[0] * d[0] + d[1] * d[1];
        }
    }
    let eps2 = if dft > 0.0 { err / dft } else { f64::NAN };
    let grow = (1.0 + eps2).sqrt();
    let m = bins.len().saturating_sub(1).max(1) as f64;
    ProbeClosedForm {
        floor_um: cf(&bins[1..]) * grow,
        tone_floor_um: cf(&bins[..1]) * grow,
        eps2,
        floor_rel_sd: ((4.0 / std::f64::consts::PI - 1.0) / m).sqrt(),
    }
}

/// The family names of a probe column.
fn family(column: &str, what: &str) -> &'static str {
    match (column == SD, what) {
        (true, "noise") => "Table 2 ΣΔ noise",
        (true, "amplitude") => "Table 2 ΣΔ amplitude",
        (true, _) => "Table 2 ΣΔ SNR",
        (false, "noise") => "Table 2 bit-true noise",
        (false, "amplitude") => "Table 2 bit-true amplitude",
        (false, _) => "Table 2 bit-true SNR",
    }
}

fn noise_of(m: &Measurement) -> Option<f64> {
    Some(m.noise_um)
}

fn amp_of(m: &Measurement) -> Option<f64> {
    m.amp_um
}

/// Mean ΣΔ error on the noise bins over the run's records (µm).
fn mean_error_um(run: &ProbeRun) -> f64 {
    let e: Vec<f64> = run
        .records
        .iter()
        .map(|r| error_um(&r.probe.phasors, &r.dft.phasors))
        .collect();
    stats::mean_sd(&e).0
}

/// The probe noise row: mean over the column's seeds against the closed form (K·se, one
/// seed's sd at least floor·sqrt((4/π − 1)/M)) and the same records' DFT (± [`NOISE_REL`]).
pub fn noise_row(r: &RowResult, run: &ProbeRun, cf: &ProbeClosedForm, quick: bool) -> Row {
    let paper = r.spec.printed.noise_um.sd;
    let values = run.probe_values(noise_of);
    let reference = stats::mean_sd(&run.dft_values(noise_of)).0;
    let st = stats::seed_stats(
        &values,
        cf.floor_um * cf.floor_rel_sd,
        (!quick).then_some(paper),
        Some(cf.floor_um),
    );
    let bins = run.records.first().map_or(0, |x| x.probe.phasors.len()) - 1;
    Row::judge(
        family(run.column, "noise"),
        r.spec.label(),
        "µm",
        Some(paper),
        None,
        st.mean,
        Some(cf.floor_um),
        Tolerance::Seeds { k: K, se: st.se },
        format!(
            "{}{} on {bins} bins ({}–{} Hz); closed form: eq. 12 on these bins ⊕ the probe's \
             error, ε² = {:.4} of the DFT's power on the same records (ΣΔ error {:.3}× the \
             floor); same-record DFT ± {:.0}%",
            table2::paper_note(Some(paper), &st, quick),
            run.column,
            NOISE_SPAN_HZ.0,
            NOISE_SPAN_HZ.1,
            cf.eps2,
            mean_error_um(run) / reference,
            NOISE_REL * 100.0
        ),
    )
    .with_seeds(&run.seeds, &st, Some(NOISE_SPAN_HZ))
    .with_same_record(reference, NOISE_REL * reference)
}

/// The tolerance of a probe's amplitude against the same records' DFT: 1 %, or where the
/// probe error makes 1 % unreachable, 3ē (ē the mean error on the noise bins). The ΣΔ error
/// at the read bin is the same mixing noise as at the noise bins; its projection on the
/// peak moves |Y| by ≈ |e|·cos θ (std ≈ ē/1.13 for a Rayleigh |e| of mean ē), so below
/// A/floor ≈ 3·0.2/0.01 = 60 the tolerance is 3ē (≈ 3.4σ); over S seeds the mean's error
/// is smaller, so this stays conservative.
fn amp_same_record_tolerance(mean_err: f64, a_dft: f64) -> (f64, String) {
    let rel_err = 3.0 * mean_err / a_dft;
    if rel_err > AMP_REL {
        (
            3.0 * mean_err,
            format!(
                "same-record ± 3ē = {:.3} µm (1% needs A/floor ≳ 60)",
                3.0 * mean_err
            ),
        )
    } else {
        (AMP_REL * a_dft, "same-record ± 1%".into())
    }
}

/// The probe "A meas." row: with a tone, the mean over the seeds against E|A_eff + n| in
/// the probe's floor at the tone bin (K·se, sd ≥ floor·sqrt(2/π); untested below
/// [`AMP_MIN_SNR`] floors), and against the same records' DFT at the tone bin; without a
/// tone, the largest value (ΣΔ only) against the paper and the same records' DFT.
pub fn amplitude_row(
    r: &RowResult,
    run: &ProbeRun,
    cf: &ProbeClosedForm,
    quick: bool,
) -> Option<Row> {
    let values = run.probe_values(amp_of);
    if values.len() < 2 {
        return None;
    }
    let paper = r.spec.printed.amp_um.sd;
    let a_dft = stats::mean_sd(&run.dft_values(amp_of)).0;
    let (tol_same, why_same) = amp_same_record_tolerance(mean_error_um(run), a_dft);
    let Some(a_eff) = r.amp_closed_um else {
        let row = table2::largest_value_row(
            family(run.column, "amplitude"),
            r,
            &values,
            &run.seeds,
            paper,
            cf.floor_um,
            quick,
            "ΣΔ: the record's 16 largest DFT bins and their neighbours probed, the largest interpolated",
        );
        return Some(with_note(row, &why_same).with_same_record(a_dft, tol_same));
    };
    let floor = cf.tone_floor_um;
    let sd_pred = floor * (2.0 / std::f64::consts::PI).sqrt();
    let expected = stats::rician_mean(a_eff, floor);
    let st = stats::seed_stats(&values, sd_pred, (!quick).then_some(paper), Some(expected));
    let (tol, untested) = if a_eff / floor >= AMP_MIN_SNR {
        (Tolerance::Seeds { k: K, se: st.se }, String::new())
    } else {
        (
            Tolerance::Untested,
            format!(
                "NOT TESTED against the closed form: A_eff/floor = {:.2} < {AMP_MIN_SNR}; ",
                a_eff / floor
            ),
        )
    };
    let row = Row::judge(
        family(run.column, "amplitude"),
        r.spec.label(),
        "µm",
        Some(paper),
        None,
        st.mean,
        Some(expected),
        tol,
        format!(
            "{untested}{}{} at the tone bin ({F0_HZ:.0} Hz); closed form E|A_eff + n|, A_eff = \
             {a_eff:.2}, probe floor there {floor:.3}; predicted sd {sd_pred:.2}; {why_same}",
            table2::paper_note(Some(paper), &st, quick),
            run.column,
        ),
    )
    .with_seeds(&run.seeds, &st, None);
    Some(row.with_same_record(a_dft, tol_same))
}

fn with_note(mut row: Row, note: &str) -> Row {
    row.note = format!("{}; {note}", row.note);
    row
}

/// The probe SNR row (tone rows): the caption's 20·log10(A meas./noise) per seed against
/// its closed form (`table2::snr_row`) and against the same records' DFT SNR on the same
/// bins (± the amplitude's and the noise's same-record tolerances, in dB).
pub fn snr_row(r: &RowResult, run: &ProbeRun, cf: &ProbeClosedForm, quick: bool) -> Option<Row> {
    let printed = r.spec.printed.snr_db?;
    let pairs = |m: fn(&table2::ProbeRecord) -> &Measurement| -> Vec<(f64, f64)> {
        run.records
            .iter()
            .filter_map(|x| Some((m(x).amp_um?, m(x).noise_um)))
            .collect()
    };
    let probe = pairs(|x| &x.probe);
    let dft = pairs(|x| &x.dft);
    let row = table2::snr_row(
        family(run.column, "snr"),
        r,
        &probe,
        &run.seeds,
        cf.floor_um,
        cf.floor_rel_sd,
        (
            printed.sd,
            r.spec.printed.amp_um.sd,
            r.spec.printed.noise_um.sd,
        ),
        quick,
    )?;
    let dft_snr: Vec<f64> = dft.iter().map(|&(a, n)| 20.0 * (a / n).log10()).collect();
    let reference = stats::mean_sd(&dft_snr).0;
    let a_dft = stats::mean_sd(&dft.iter().map(|x| x.0).collect::<Vec<_>>()).0;
    let (tol_amp, _) = amp_same_record_tolerance(mean_error_um(run), a_dft);
    let db = 20.0 / std::f64::consts::LN_10;
    let tol = db * (tol_amp / a_dft + NOISE_REL);
    Some(with_note(row, &format!("same-record ± {tol:.3} dB")).with_same_record(reference, tol))
}

/// The ΣΔ read without the prefilter (first ΣΔ record, ρ_s = 1 rows): its error against
/// the same record's DFT is several floors.
fn raw_row(r: &RowResult, run: &ProbeRun) -> Option<Row> {
    let raw = run.raw.as_ref()?;
    let first = run.records.first()?;
    let dft_noise = noise_um(&first.dft.phasors);
    let factor = error_um(&raw.phasors, &first.dft.phasors) / dft_noise;
    Some(
        Row::judge(
            "Table 2 ΣΔ without prefilter",
            r.spec.label(),
            "× floor",
            None,
            Some(RAW_FACTOR_DESIGN),
            factor,
            None,
            Tolerance::AtLeast {
                min: RAW_FACTOR_MIN,
            },
            format!(
                "seed {}; mean |Y_ΣΔ − Y_DFT| / DFT floor over {} bins; with the prefilter {:.3}×; \
                 noise read without it {:.3} µm vs {dft_noise:.3}",
                first.seed,
                first.dft.phasors.len() - 1,
                error_um(&first.probe.phasors, &first.dft.phasors) / dft_noise,
                raw.noise_um
            ),
        )
        .with_seeds(
            &run.seeds[..1],
            &stats::seed_stats(&[factor], 0.0, None, None),
            None,
        ),
    )
}

/// Adds the register check to the bit-true noise row: it passes only if every register of
/// the first record is within the derived bound of the float ΣΔ on the same codes.
fn with_check(mut row: Row, run: &ProbeRun) -> Row {
    let Some(check) = &run.check else {
        return row;
    };
    row.note = format!(
        "{}; register check (seed {}): W = {}, T = {}, F = {FRAC_BITS}, S = {SHIFT}; per register \
         |bit − float| ≤ 2^(S−F−1)(N−1−m+|Σs|): worst {:.3} codes of {:.0} ({:.2e}); max \
         |Y_bit − Y_float(same codes)| {:.3} µm",
        row.note,
        run.seeds[0],
        check.width,
        check.tdc_bits,
        check.worst_codes,
        check.bound_codes,
        check.worst_ratio,
        bt_diff_um(check)
    );
    row.pass &= check.worst_ratio <= 1.0;
    row
}

/// Every probe row of one Table 2 row.
pub fn rows(r: &RowResult, quick: bool) -> Vec<Row> {
    let mut out = Vec::new();
    for run in &r.probes {
        if run.records.is_empty() {
            continue;
        }
        let cf = probe_closed_form(r, run);
        out.push(with_check(noise_row(r, run, &cf, quick), run));
        out.extend(amplitude_row(r, run, &cf, quick));
        out.extend(snr_row(r, run, &cf, quick));
        out.extend(raw_row(r, run));
    }
    out
}
