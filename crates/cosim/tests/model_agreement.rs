//! The pixel crate's cycle-accurate model and the generator's reference model (from which
//! the golden vectors come) agree on every cycle: pins and register writes, both modes, the
//! default and random small configurations, on random stimuli.

use proptest::prelude::*;
use tofprobe_cosim::pixel_bridge::compare_models;
use tofprobe_rtlgen::params::{Mode, PixelParams};
use tofprobe_rtlgen::stimulus::{random_stimulus, sign_probe_rom};

fn check(p: &PixelParams, frames: u64, seed: u64) {
    let stim = random_stimulus(p, frames * p.frame_pulses, seed);
    let rom = sign_probe_rom(p);
    let d = compare_models(p, &stim, &rom, frames).expect("both models accept the configuration");
    assert!(
        d.is_none(),
        "{p:?}: first difference (cycle, what, pixel crate, reference) {d:?}"
    );
}

#[test]
fn default_both_modes_agree() {
    for mode in [Mode::Fourier, Mode::Haar] {
        let p = PixelParams {
            mode,
            frame_pulses: 256,
            rom_depth: 256,
            ..PixelParams::default()
        };
        check(&p, 3, 11);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, rng_seed: proptest::test_runner::RngSeed::Fixed(6), ..ProptestConfig::default() })]
    #[test]
    fn random_configurations_agree(
        haar in any::<bool>(), bins in 1usize..6, u in 0u32..4, a in 1usize..5, extra_c in 0usize..3,
        t in 1u32..9, s in 0u32..8, f in 0u32..5, extra_w in 0u32..20, log_n in 4u32..7, l in 1usize..40,
        zoom_frac in 0.0f64..1.0, seed in 0u64..1000,
    ) {
        let mode = if haar { Mode::Haar } else { Mode::Fourier };
        let mut p = PixelParams {
            mode, bins, haar_scales: u, adders: 1, cycles_per_pulse: 1, tdc_bits: t,
            zoom: ((1u64 << t) as f64 * zoom_frac) as u32, shift: s, frac_bits: f, width: 0,
            frame_pulses: 1 << log_n, rom_depth: l, ..PixelParams::default()
        };
        p.adders = a.min(p.ops_per_pulse());
        p.cycles_per_pulse = p.slots() + extra_c;
        p.width = (p.operand_bits() + extra_w).min(63);
        p.validate().expect("generated configuration is valid");
        check(&p, 2, seed);
    }
}
