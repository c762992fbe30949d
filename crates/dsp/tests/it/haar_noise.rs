//! The Haar noise model against simulation at a larger scale than the unit tests (which
//! run 300–2000 frames): 2000 frames of 2^14 pulses for three sensors, and 20,000 frames
//! of 2^12 pulses for the false-event rate. Run with
//! `cargo test --release -p tofprobe-dsp --test it haar_noise:: -- --ignored --nocapture`
//! (≈ 10 s); the same function (`static_noise_check`) serves `tofprobe reproduce`.

use tofprobe_dsp::haar::montecarlo::sensor_with_rates as sensor;
use tofprobe_dsp::haar::montecarlo::static_noise_check;

/// Tolerances as in the unit tests: 4 standard errors of an sd estimate (1/sqrt(2m)) plus
/// 1 % for the model's approximations; false-event frames within 5 Poisson sd.
#[test]
#[ignore = "heavy Monte Carlo (≈ 10 s): run with --ignored"]
fn noise_model_at_scale() {
    for (rs, rb) in [(1.0, 0.0), (0.3, 0.0), (0.03, 0.0), (0.3, 0.1), (1.0, 0.3)] {
        let c = static_noise_check(&sensor(rs, rb), 30.0, 14, 6, 2000, 0.01, 3).unwrap();
        println!("ρs {rs} ρb {rb}: N = 2^14, U = 6, {} frames", c.frames);
        for s in &c.scales {
            let rel = s.measured_sd_mm / s.predicted_sd_mm - 1.0;
            println!(
                "  u {}: predicted {:.5} mm, measured {:.5} mm ({:+.2} %, {} coefficients)",
                s.u,
                s.predicted_sd_mm,
                s.measured_sd_mm,
                100.0 * rel,
                s.samples
            );
            assert!(rel.abs() < 4.0 / (2.0 * s.samples as f64).sqrt() + 0.01);
        }
        println!(
            "  frames with a false event: {} (expected {:.1})",
            c.frames_with_events, c.expected_frames_with_events
        );
    }
    let c = static_noise_check(&sensor(1.0, 0.0), 30.0, 12, 6, 20_000, 0.01, 5).unwrap();
    println!(
        "false events, α = 1 %: {} of {} frames (expected {:.1}); exceedances {} (expected {:.1})",
        c.frames_with_events,
        c.frames,
        c.expected_frames_with_events,
        c.exceedances,
        c.expected_exceedances
    );
    let sd = c.expected_frames_with_events.sqrt();
    assert!((c.frames_with_events as f64 - c.expected_frames_with_events).abs() < 5.0 * sd);
}
