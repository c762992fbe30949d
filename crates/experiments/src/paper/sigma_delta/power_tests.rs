//! The probe rows' power (issue 46): at N = 10^7 every ΣΔ and bit-true row of Table 2 has
//! seeds of its own, enough that a 5 % noise bias and a ±10 µm amplitude bias fail each
//! tested row — shown on rows built from seed values with exactly the predicted sd about
//! the closed form (symmetric quantiles rescaled to sample sd 1, what the test reads).
//! Unbiased they pass; a bias the probe's records share with their DFT (physics: the DFT
//! reference cannot see it) fails the closed form; a bias of the probe alone fails both.

use super::super::stats;
use super::super::table2::{
    AMP_BIAS_UM, BIT_TRUE, FULL_N, Measurement, NOISE_BIAS, ProbeRecord, ProbeRun, ROWS, RowResult,
    SD, SeedSet, Spec, closed_form_amp_um, closed_form_noise_on_bins_um, seeds_for_set,
};
use super::{probe_bins, rows};
use crate::paper::Row;

/// `count` values of sample mean 0 and sample sd 1 (logits of (i + ½)/count, rescaled).
fn unit_spread(count: usize) -> Vec<f64> {
    let z: Vec<f64> = (0..count)
        .map(|i| {
            let p = (i as f64 + 0.5) / count as f64;
            (p / (1.0 - p)).ln()
        })
        .collect();
    let (m, s) = stats::mean_sd(&z);
    z.iter().map(|v| (v - m) / s).collect()
}

/// A measurement whose noise bins all read `noise_um` and whose tone bin reads `amp_um`.
fn measured(noise_um: f64, amp_um: Option<f64>, bins: usize) -> Measurement {
    let mut phasors = vec![[amp_um.unwrap_or(0.0) * 1e-3, 0.0]];
    phasors.extend(std::iter::repeat_n([noise_um * 1e-3, 0.0], bins));
    Measurement {
        noise_um,
        amp_um,
        phasors,
        bit_true: None,
        top_bins: Vec::new(),
    }
}

/// The biases of one built run: (noise factor, amplitude shift µm) of the records (the
/// probe and its DFT alike) and of the probe alone.
#[derive(Clone, Copy)]
struct Bias {
    shared: (f64, f64),
    probe: (f64, f64),
}

const NONE: Bias = Bias {
    shared: (1.0, 0.0),
    probe: (1.0, 0.0),
};

/// The probe rows of `spec`'s column `column` built from seed values about the closed form
/// with the predicted sd, biased by `bias`.
fn built_rows(spec: &Spec, column: &'static str, bias: Bias) -> Vec<Row> {
    let n = FULL_N;
    let set = if column == SD {
        SeedSet::FloatSd
    } else {
        SeedSet::BitTrue
    };
    let seeds = seeds_for_set(spec, n, set).unwrap();
    let bins = probe_bins(n);
    let m = bins.len() - 1;
    let floor = closed_form_noise_on_bins_um(spec, n as usize, &bins[1..]).unwrap();
    let tone_floor = closed_form_noise_on_bins_um(spec, n as usize, &bins[..1]).unwrap();
    let a_eff = closed_form_amp_um(spec).unwrap();
    let rel = ((4.0 / std::f64::consts::PI - 1.0) / m as f64).sqrt();
    let z = unit_spread(seeds.len());
    let records = seeds
        .iter()
        .enumerate()
        .map(|(i, &seed)| {
            // The noise and the amplitude drawn in opposite orders (uncorrelated SNRs).
            let noise = floor * (1.0 + rel * z[z.len() - 1 - i]) * bias.shared.0;
            let amp = a_eff.map(|a| {
                stats::rician_mean(a, tone_floor)
                    + tone_floor * (2.0 / std::f64::consts::PI).sqrt() * z[i]
                    + bias.shared.1
            });
            ProbeRecord {
                seed,
                probe: measured(noise * bias.probe.0, amp.map(|a| a + bias.probe.1), m),
                dft: measured(noise, amp, m),
            }
        })
        .collect();
    let r = RowResult {
        spec: *spec,
        pulses: n,
        dft0: measured(floor, None, m),
        seeds: Vec::new(),
        noises_um: Vec::new(),
        band_bins: 9000,
        amps_um: Vec::new(),
        closed_form_um: floor,
        amp_closed_um: a_eff,
        spectrum: Vec::new(),
        spectrum_max: Vec::new(),
        probes: vec![ProbeRun {
            column,
            seeds,
            records,
            raw: None,
            check: None,
        }],
    };
    rows(&r, false)
}

fn verdict(rows: &[Row], what: &str) -> Option<bool> {
    rows.iter()
        .find(|r| r.family.ends_with(what))
        .filter(|r| !matches!(r.tolerance, crate::paper::Tolerance::Untested))
        .map(|r| r.pass)
}

#[test]
fn a_five_percent_noise_bias_and_a_ten_micron_amplitude_bias_fail_every_probe_row() {
    let (mut noise_rows, mut amp_rows) = (0, 0);
    let mut seeds_seen = std::collections::BTreeSet::new();
    for spec in ROWS.iter() {
        for column in [SD, BIT_TRUE] {
            let fresh = built_rows(spec, column, NONE);
            let seeds = &fresh[0].seeds;
            for s in seeds {
                assert!(seeds_seen.insert(*s), "seed {s} used twice");
            }
            for what in [" noise", " amplitude", " SNR"] {
                if let Some(pass) = verdict(&fresh, what) {
                    assert!(pass, "{} {column}{what}: unbiased must pass", spec.label());
                }
            }
            let label = format!("{} {column}", spec.label());
            assert_eq!(verdict(&fresh, " noise"), Some(true), "{label}");
            noise_rows += 1;
            for f in [1.0 + NOISE_BIAS, 1.0 - NOISE_BIAS] {
                for bias in [
                    Bias {
                        shared: (f, 0.0),
                        ..NONE
                    },
                    Bias {
                        probe: (f, 0.0),
                        ..NONE
                    },
                ] {
                    let b = built_rows(spec, column, bias);
                    assert_eq!(verdict(&b, " noise"), Some(false), "{label}: noise × {f}");
                }
            }
            if verdict(&fresh, " amplitude").is_none() || spec.amp_um.is_none() {
                continue;
            }
            amp_rows += 1;
            for shift in [AMP_BIAS_UM, -AMP_BIAS_UM] {
                let shared = built_rows(
                    spec,
                    column,
                    Bias {
                        shared: (1.0, shift),
                        ..NONE
                    },
                );
                let amp = shared.iter().find(|r| r.family.ends_with("amplitude"));
                // The DFT of the same records carries the bias too: only the closed form
                // can catch it.
                let amp = amp.unwrap();
                assert!(!amp.pass, "{label}: amplitude {shift:+} µm shared passes");
                assert!(
                    (amp.measured - amp.same_record_dft.unwrap()).abs()
                        <= amp.same_record_tolerance.unwrap(),
                    "{label}: the same-record reference shares the bias"
                );
                let alone = built_rows(
                    spec,
                    column,
                    Bias {
                        probe: (1.0, shift),
                        ..NONE
                    },
                );
                assert_eq!(verdict(&alone, " amplitude"), Some(false), "{label}");
            }
        }
    }
    // 18 rows × 2 columns; 10 tone rows stand ≥ 3 floors above their noise.
    assert_eq!(noise_rows, 36);
    assert!(amp_rows >= 20, "{amp_rows}");
}

/// Row 16 of the issue (ρ_s 0.3, ρ_b 0.075): a ΣΔ amplitude of 65.95 µm against the
/// closed form ≈ 83 µm passed when the ΣΔ rows were judged only against the DFT of their
/// own records; judged on physics it fails, the same records' DFT agreeing or not.
#[test]
fn the_issues_row_16_fails_on_physics() {
    let spec = ROWS
        .iter()
        .find(|s| s.rho_s == 0.3 && s.rho_b == 0.075)
        .unwrap();
    let a = stats::rician_mean(closed_form_amp_um(spec).unwrap().unwrap(), 16.0);
    assert!((a - 83.3).abs() < 2.0, "closed form {a}");
    let rows = built_rows(
        spec,
        SD,
        Bias {
            shared: (1.0, 65.95 - a),
            ..NONE
        },
    );
    let amp = rows
        .iter()
        .find(|r| r.family == "Table 2 ΣΔ amplitude")
        .unwrap();
    assert!(!amp.pass, "{amp:?}");
    assert_eq!(amp.paper, Some(88.47));
    assert!(amp.z_closed_form.unwrap() > 3.0, "{amp:?}");
}
