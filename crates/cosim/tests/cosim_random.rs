//! Eight random configurations (B, U, W, A, C, S, F, Z, mode, N, ROM depth and the stimulus
//! seed drawn by proptest from a fixed seed) pass in Verilator, bit for bit, over 2 frames.
//! Kept small: the Verilator build dominates, so R ≤ 15 and short frames.

mod common;
use common::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::{Mode, PixelParams};

fn config() -> impl Strategy<Value = (PixelParams, u64)> {
    (
        any::<bool>(),
        (1usize..5, 0u32..3, 1usize..5, 0usize..3),
        (1u32..10, 0.0f64..1.0, 0u32..9, 0u32..6, 0u32..12),
        (4u32..7, 1usize..48, 0u64..10_000),
    )
        .prop_map(|(haar, (b, u, a, ec), (t, zf, s, f, ew), (ln, l, seed))| {
            let mut p = PixelParams {
                mode: if haar { Mode::Haar } else { Mode::Fourier },
                bins: b,
                haar_scales: u,
                adders: 1,
                cycles_per_pulse: 1,
                tdc_bits: t,
                zoom: ((1u64 << t) as f64 * zf) as u32,
                shift: s,
                frac_bits: f,
                width: 8,
                frame_pulses: 1 << ln,
                rom_depth: l,
            };
            p.adders = a.min(p.ops_per_pulse());
            p.cycles_per_pulse = p.slots() + ec;
            p.width = (p.operand_bits() + ew).min(63);
            (p, seed)
        })
}

#[test]
fn eight_random_configurations_pass_in_verilator() {
    if !tools_or_skip(
        &["verilator"],
        "eight_random_configurations_pass_in_verilator",
    ) {
        return;
    }
    let mut runner = TestRunner::new(Config {
        cases: 8,
        rng_seed: RngSeed::Fixed(0x0070_70be),
        failure_persistence: None,
        ..Config::default()
    });
    let case = std::cell::Cell::new(0);
    runner
        .run(&config(), |(p, seed)| {
            p.validate().expect("drawn configuration is valid");
            case.set(case.get() + 1);
            let mut o = CosimOptions::new(work_dir(&format!("random-{}", case.get())));
            o.frames = 2;
            o.seed = seed;
            o.vcd_on_mismatch = false;
            let r = cosim(&p, &o).expect("co-simulation runs");
            prop_assert!(r.pass, "{:?} seed {}: {:?}", p, seed, r.first);
            prop_assert_eq!(r.outcome.frames, 2);
            Ok(())
        })
        .expect("every random configuration passes");
    assert_eq!(case.get(), 8);
}
