//! The fidelity levels through the library (no binary, no process per case): on a short
//! windowed frame with a 1 mm tone on a ROM bin, `tradeoff::measure_levels` measures each
//! level of the registry once, and only what it needs. Checked against independent
//! numbers: the tone read by every float level is the true 1 mm within the frame's noise,
//! the bit-true level equals the pixel crate's spectrum of the same stream, a subset of the
//! ladder reads the same numbers as the whole ladder (each level is a function of the
//! record, not of which others ran), and a Haar level is refused on a Fourier design.

use tofprobe_design::ProbeCache;

use crate::common::short_tone_frame;
use tofprobe_experiments::level::Level;
use tofprobe_experiments::spectrum::setup;
use tofprobe_experiments::tradeoff::{measure_levels, measure_setup};

const N: u64 = 1 << 15;

#[test]
fn every_fourier_level_reads_the_tone_and_a_subset_reads_the_same() {
    let d = short_tone_frame(N);
    let su = setup(&d).unwrap();
    let all = measure_setup(&d, &su, false).unwrap();
    let names: Vec<&str> = all.levels.iter().map(|l| l.level.as_str()).collect();
    let want: Vec<&str> = Level::fourier_ladder(false)
        .iter()
        .map(|l| l.name())
        .collect();
    assert_eq!(names, want, "the registry's ladder, in its order");
    let truth = all.true_amplitude_um.expect("a tone on a bin");
    assert!((truth - 1000.0).abs() < 1e-9, "{truth}");
    // σ_I = 7.5 mm at N = 2^15 with Blackman's N_eff ≈ 0.58 N: the floor is
    // sqrt(π σ²/N_eff) ≈ 97 µm; the tone is read within 5 floors (≈ 0.5 mm) by every
    // level that reads it (the closed form models it: within 1 %).
    for l in &all.levels {
        let a = l
            .amplitude_um
            .unwrap_or_else(|| panic!("{}: no tone", l.level));
        let tol = if l.level == Level::ClosedForm.name() {
            10.0
        } else {
            500.0
        };
        assert!((a - truth).abs() < tol, "{}: {a} vs {truth}", l.level);
        assert!(l.noise_um.is_finite() && l.noise_um > 0.0, "{}", l.level);
    }
    // Bit-exact levels share the transaction model's reading.
    let bt = all.level(Level::BitTrue).unwrap();
    let cy = all.level(Level::Cycle).unwrap();
    assert_eq!(bt.amplitude_um, cy.amplitude_um);
    assert!(cy.extrapolated && !bt.extrapolated);
    // The bit-true level is the pixel crate's spectrum of the same stream.
    let source = d.photon_source().unwrap();
    let s = tofprobe_pixel::spectrum::bit_true_spectrum(
        &su.params,
        &su.rom,
        &source,
        d.sensor().tdc_lsb_mm(),
    )
    .unwrap();
    let tone = s
        .bins
        .iter()
        .map(|b| b.amplitude_um)
        .fold(f64::MIN, f64::max);
    assert_eq!(bt.amplitude_um, Some(tone));
    // A subset, in another order: the same numbers (times aside).
    let sub = measure_levels(&d, &su, &[Level::BitTrue, Level::FloatSd]).unwrap();
    assert_eq!(sub.levels.len(), 2);
    for l in &sub.levels {
        let full = all.levels.iter().find(|f| f.level == l.level).unwrap();
        assert_eq!(l.amplitude_um, full.amplitude_um, "{}", l.level);
        assert_eq!(l.noise_um, full.noise_um, "{}", l.level);
        assert_eq!(l.amplitude_err_vs_dft_um, full.amplitude_err_vs_dft_um);
    }
    assert_eq!(sub.levels[0].level, Level::BitTrue.name());
}

#[test]
fn a_haar_level_is_refused_on_a_fourier_design() {
    let d = short_tone_frame(N);
    let su = setup(&d).unwrap();
    let e = measure_levels(&d, &su, &[Level::FloatHaar])
        .unwrap_err()
        .to_string();
    assert!(e.contains("float Haar") && e.contains("Fourier"), "{e}");
}

/// The options' accuracy through the library: an option's tone error per seed is
/// |bit-true − float full DFT| of that option's design and seed, recomputed here naively
/// through the level API; the order of the seeds is kept whatever the thread count, and an
/// option that changes the arithmetic (G = 0) changes the error.
#[test]
fn option_accuracy_is_the_bit_true_error_against_the_dft_per_seed() {
    use tofprobe_experiments::options::accuracy::measure;
    use tofprobe_experiments::options::catalogue::ArchOption;
    use tofprobe_experiments::tradeoff::overrides::with_overrides;
    let d = short_tone_frame(N);
    let options = vec![
        ArchOption {
            name: "baseline".into(),
            overrides: vec![],
        },
        ArchOption {
            name: "G=0".into(),
            overrides: vec![("pixel.register_frac_bits".into(), "0".into())],
        },
    ];
    let seeds = [3u64, 4, 5];
    let got = measure(&d.document, &d.origin, &options, &seeds);
    let mut means = Vec::new();
    for (o, acc) in options.iter().zip(&got) {
        let acc = acc.as_ref().expect("measured");
        assert_eq!(acc.tone_error_um.per_seed.len(), seeds.len());
        for (&seed, &err) in seeds.iter().zip(&acc.tone_error_um.per_seed) {
            let seed_s = seed.to_string();
            let mut ov: Vec<(&str, &str)> = o
                .overrides
                .iter()
                .map(|(k, v)| (k.as_str(), v.as_str()))
                .collect();
            ov.push(("acquisition.seed", &seed_s));
            let od = with_overrides(&d.document, "naive", &ov, &mut ProbeCache::default()).unwrap();
            let su = setup(&od).unwrap();
            let r = measure_levels(&od, &su, &[Level::FullDft, Level::BitTrue]).unwrap();
            let dft = r.level(Level::FullDft).unwrap().amplitude_um.unwrap();
            let bt = r.level(Level::BitTrue).unwrap().amplitude_um.unwrap();
            assert_eq!(err, (bt - dft).abs(), "{} seed {seed}", o.name);
        }
        means.push(acc.tone_error_um.mean);
    }
    assert_ne!(
        means[0], means[1],
        "G = 0 must change the arithmetic: {means:?}"
    );
}
