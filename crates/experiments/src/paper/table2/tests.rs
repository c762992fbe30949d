//! Table 2's unit tests (crates/experiments/src/paper/table2.rs).

use super::*;
use crate::paper::Tolerance;
use crate::paper::stats::K;

/// A measurement of noise `noise` µm and "A meas." `amp` µm, nothing else.
pub(crate) fn measurement(noise: f64, amp: Option<f64>) -> Measurement {
    Measurement {
        noise_um: noise,
        amp_um: amp,
        phasors: Vec::new(),
        bit_true: None,
        top_bins: Vec::new(),
    }
}

/// The plotted spectrum is the level of the spectrum: on a flat Rayleigh floor (mean
/// sqrt(π/2) = 1.2533 mm, drawn from a fixed LCG) the median group mean above 10 kHz
/// is within 4 % of it (81 groups of 20–100 bins, each mean within ≈ 8 % sd: the
/// median's standard error ≈ 1.1 %, so 4 % is > 3.5σ), while the group maxima — what spectra.svg used to draw — sit ≥ 1.5×
/// above it (the maximum of M ≥ 20 Rayleigh bins exceeds the mean by ≈ sqrt(2 ln M)).
#[test]
fn decimated_spectrum_is_the_group_mean() {
    let n = 1_000_000usize;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let spectrum: Vec<f64> = (0..n / 2)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let u = ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
            (-2.0 * u.ln()).sqrt() * 1e-3
        })
        .collect();
    let (mean, max) = decimate(&spectrum, n);
    assert_eq!(mean.len(), max.len());
    let median = |v: &[(f64, f64)]| {
        let mut y: Vec<f64> = v.iter().filter(|p| p.0 >= 10_000.0).map(|p| p.1).collect();
        y.sort_by(f64::total_cmp);
        y[y.len() / 2]
    };
    let level = (std::f64::consts::PI / 2.0).sqrt();
    assert!(
        (median(&mean) / level - 1.0).abs() < 0.04,
        "{}",
        median(&mean)
    );
    assert!(median(&max) > 1.5 * level, "{}", median(&max));
}

/// A short record (2^18 pulses, 38 Hz bins) of the σ_s = 7.5 mm, ρ_s = 0.3 row: the
/// band holds ≈ 220 bins, ≈ 110 independent ones under Blackman, so the mean Rayleigh
/// magnitude has a standard error ≈ 0.52/sqrt(110) ≈ 5%; 15% is 3σ. The probe columns run
/// on their own seeds (none shared with the DFT column or each other), every record read
/// by the DFT on the probe bins too, and their rows carry the paper's ΣΔ values.
#[test]
fn short_row_matches_closed_form() {
    let spec = ROWS[9];
    let n = 1u64 << 18;
    let probe = crate::paper::sigma_delta::tests::setup_for_tests(n);
    let r = run_row_with(&spec, n, Some(&probe), COLUMNS).unwrap();
    let m = &r.dft0;
    assert!(
        (m.noise_um / r.closed_form_um - 1.0).abs() < 0.15,
        "{} vs {}",
        m.noise_um,
        r.closed_form_um
    );
    assert_eq!(r.amps_um.len(), SEEDS.len());
    assert_eq!(r.noises_um.len(), SEEDS.len());
    // The row's own seeds (row 9 of ROWS: 10000..10005 for the DFT, 10100.. for the ΣΔ,
    // 10200.. for the bit-true pixel).
    assert_eq!(r.seeds, (10_000..10_005).collect::<Vec<u64>>());
    let sd = r.probe(SD).expect("ΣΔ ran");
    let bt = r.probe(BIT_TRUE).expect("bit-true ran");
    assert_eq!(sd.seeds, (10_100..10_105).collect::<Vec<u64>>());
    assert_eq!(bt.seeds, (10_200..10_205).collect::<Vec<u64>>());
    assert_eq!(sd.records.len(), SEEDS.len());
    assert!(bt.check.as_ref().is_some_and(|c| c.worst_ratio <= 1.0));
    let rows = crate::paper::sigma_delta::rows(&r, true);
    for fam in [
        "Table 2 ΣΔ noise",
        "Table 2 ΣΔ amplitude",
        "Table 2 ΣΔ SNR",
        "Table 2 bit-true noise",
        "Table 2 bit-true amplitude",
        "Table 2 bit-true SNR",
    ] {
        let row = rows.iter().find(|x| x.family == fam).expect(fam);
        let st = if fam.contains("ΣΔ") { sd } else { bt };
        assert_eq!(row.seeds, st.seeds, "{row:?}");
        assert!(row.pass && row.seed_sd.is_some_and(|s| s > 0.0), "{row:?}");
        assert!(
            row.paper.is_some() && row.same_record_dft.is_some(),
            "{row:?}"
        );
        assert!(row.closed_form.is_some(), "{row:?}");
    }
    let dft_only = run_row_with(&spec, n, Some(&probe), &COLUMNS[..1]).unwrap();
    assert!(dft_only.probes.is_empty());
}

/// Statistical power: at N = 10^7 every tested amplitude row has seeds enough that a
/// 10 µm bias fails its test, and no two rows share a seed. Shown on seed amplitudes
/// built to have exactly the predicted sd about the closed form (normal quantiles,
/// rescaled): unbiased they pass, shifted by ±10 µm they fail — while with the old
/// five shared seeds the same shift passes at least one row (the defect).
#[test]
fn a_ten_micron_amplitude_bias_fails_every_tested_row() {
    let n = FULL_N;
    let mut all: Vec<u64> = Vec::new();
    let mut tested = 0;
    for spec in ROWS.iter() {
        let seeds = seeds_for(spec, n).unwrap();
        eprintln!("{}: {} seeds from {}", spec.label(), seeds.len(), seeds[0]);
        all.extend(&seeds);
        let Some(amp) = closed_form_amp_um(spec).unwrap() else {
            continue;
        };
        let floor = closed_form_noise_um(spec, n as usize).unwrap();
        let expected = stats::rician_mean(amp, floor);
        let sd = floor * (2.0 / std::f64::consts::PI).sqrt();
        let draws = |count: usize, shift: f64| -> Vec<f64> {
            // A symmetric spread (logits of (i + ½)/count) rescaled to sample sd 1:
            // mean 0 and sd 1 exactly, which is all the row's test reads.
            let z: Vec<f64> = (0..count)
                .map(|i| {
                    let p = (i as f64 + 0.5) / count as f64;
                    (p / (1.0 - p)).ln()
                })
                .collect();
            let (_, zs) = stats::mean_sd(&z);
            z.iter().map(|v| expected + shift + sd * v / zs).collect()
        };
        let row_with = |amps: Vec<f64>| {
            let r = RowResult {
                spec: *spec,
                pulses: n,
                dft0: measurement(floor, None),
                seeds: (0..amps.len() as u64).collect(),
                noises_um: vec![floor; amps.len()],
                band_bins: 100,
                amps_um: amps,
                closed_form_um: floor,
                amp_closed_um: Some(amp),
                spectrum: Vec::new(),
                spectrum_max: Vec::new(),
                probes: Vec::new(),
            };
            amplitude_row(&r, false).unwrap()
        };
        let row = row_with(draws(seeds.len(), 0.0));
        if matches!(row.tolerance, Tolerance::Untested) {
            continue;
        }
        tested += 1;
        assert!(row.pass, "{}: unbiased must pass: {row:?}", spec.label());
        for shift in [AMP_BIAS_UM, -AMP_BIAS_UM] {
            let biased = row_with(draws(seeds.len(), shift));
            assert!(!biased.pass, "{} with {shift} µm passes", spec.label());
        }
    }
    assert!(tested >= 10, "{tested}");
    let unique: std::collections::BTreeSet<u64> = all.iter().copied().collect();
    assert_eq!(unique.len(), all.len(), "rows share seeds");
    // The old five seeds: some tested row lets a 10 µm bias through.
    let weak = ROWS.iter().any(|spec| {
        let (Some(amp), Ok(floor)) = (
            closed_form_amp_um(spec).unwrap(),
            closed_form_noise_um(spec, n as usize),
        ) else {
            return false;
        };
        let sd = floor * (2.0 / std::f64::consts::PI).sqrt();
        amp / floor >= AMP_MIN_SNR && AMP_BIAS_UM < K * sd / (SEEDS.len() as f64).sqrt()
    });
    assert!(
        weak,
        "five seeds were already enough: the seed counts buy nothing"
    );
}

/// Deliberately wrong pipelines fail the noise row (2^16 pulses, DFT column only, the
/// five seeds; ≈ 59 band bins give a predicted 10% sd per seed, se 4.7%, so K·se ≈ 14%):
/// the correct pipeline passes; no window-gain correction (2/N instead of 2/(N·G),
/// i.e. × 0.42) and half the jitter (σ_s 7.5 → 3.76 mm, floor × 0.5) fail.
#[test]
fn broken_pipelines_fail_the_noise_row() {
    let n = 1u64 << 16;
    let spec = ROWS[1];
    let good = run_row_with(&spec, n, None, &COLUMNS[..1]).unwrap();
    let row = noise_row(&good, true);
    assert!(row.pass, "{row:?}");
    assert_eq!(row.seeds.len(), SEEDS.len());
    assert!(row.z_closed_form.is_some() && row.band_hz == Some(BAND));

    let mut no_window = good.clone();
    for v in &mut no_window.noises_um {
        *v *= WINDOW.coherent_gain();
    }
    assert!(
        !noise_row(&no_window, true).pass,
        "no window correction must fail"
    );

    let j = spec.setup().jitter_mm().unwrap() / 2.0;
    let half = Spec {
        sigma_s_mm: (j * j + LSB_MM * LSB_MM / 12.0).sqrt(),
        ..spec
    };
    let mut half_jitter = run_row_with(&half, n, None, &COLUMNS[..1]).unwrap();
    // Judged as the row it claims to be: the closed form of the true jitter.
    half_jitter.spec = spec;
    half_jitter.closed_form_um = good.closed_form_um;
    let row = noise_row(&half_jitter, true);
    assert!(!row.pass, "half the jitter must fail: {row:?}");
    assert!(row.z_closed_form.unwrap() > 3.0);
}
