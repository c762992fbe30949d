//! The array model against closed forms: a plate mode's measured complex map matches the
//! true mode shape (modal assurance criterion ≥ 0.99, and a wrong mode is told apart), the
//! phase flips by 180° across the nodal line, a static array's noise floor is the
//! single-pixel closed form (eq. 12) on average over the pixels, and a rotor's blade-pass
//! frequency appears where its blades cross and not elsewhere.

use std::f64::consts::PI;

use tofprobe_array::maps::{fourier_maps, mac};
use tofprobe_array::model::run_array;

use crate::common::{design, plate};

/// 8 × 8 pixels of 10 mm: the 80 mm plate of `common::plate` exactly.
const PLATE_ARRAY: &str = "rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 10.0";

fn maps(d: &tofprobe_design::ResolvedDesign) -> tofprobe_array::maps::VibrationMaps {
    let rom = d.probe_rom().unwrap().unwrap();
    let frame = run_array(d, Some(&rom.image)).unwrap();
    fourier_maps(d, &rom, &frame).unwrap()
}

/// sin(mπx/L)·sin(nπy/L) at the 8 × 8 pixel centres of the 80 mm plate.
fn shape(m: f64, n: f64) -> Vec<(f64, f64)> {
    (0..64)
        .map(|i| {
            let (x, y) = ((i % 8) as f64 * 10.0 + 5.0, (i / 8) as f64 * 10.0 + 5.0);
            ((m * PI * x / 80.0).sin() * (n * PI * y / 80.0).sin(), 0.0)
        })
        .collect()
}

#[test]
fn a_plate_mode_is_recovered_with_its_nodal_line() {
    // 200,000 pulses: the floor per bin is ≈ 30 µm (eq. 12) against a 1 mm mode.
    let d = design(&plate(2, 1), 200_000, PLATE_ARRAY);
    let m = maps(&d);
    let b = m.dominant_bin;
    assert_eq!(m.frequencies_hz[b], 1500.0, "the tone's bin dominates");
    let measured = m.deflection(b);
    let true_mac = mac(&measured, &shape(2.0, 1.0));
    // MAC ≈ 1 − noise energy / shape energy: 64 pixels × E|n|² = 64 · (4/π)(30 µm)² ≈ 7.3e4
    // µm² against Σ|1 mm · shape|² = 16 · 10^6 µm²: ≈ 0.995 expected, 0.99 with margin.
    assert!(
        true_mac >= 0.99,
        "MAC with the true (2, 1) shape {true_mac}"
    );
    // A deliberately wrong reference fails: the (1, 2) mode is orthogonal to (2, 1).
    let wrong = mac(&measured, &shape(1.0, 2.0));
    assert!(wrong < 0.1, "MAC with the (1, 2) shape {wrong}");
    // Across the nodal line x = 40 mm (between columns 3 and 4) the phase flips by 180°.
    for r in 0..8 {
        let (pl, pr) = (m.phase(b)[r * 8 + 1], m.phase(b)[r * 8 + 6]);
        let diff = (pl - pr).rem_euclid(360.0);
        // The weakest pixels compared (row 0: |shape| = 0.92 · 0.195 of 1 mm = 180 µm) have
        // a phase noise of ≈ 30/180 rad ≈ 10° each, 14° on the difference: 45° is 3σ. The
        // mean over the 8 rows is held to 10° below.
        assert!((diff - 180.0).abs() < 45.0, "row {r}: {pl}° vs {pr}°");
    }
    let mean: f64 = (0..8)
        .map(|r| (m.phase(b)[r * 8 + 1] - m.phase(b)[r * 8 + 6]).rem_euclid(360.0))
        .sum::<f64>()
        / 8.0;
    assert!((mean - 180.0).abs() < 10.0, "mean flip {mean}°");
}

#[test]
fn a_static_array_has_the_single_pixel_noise_floor() {
    let d = design(
        "",
        200_000,
        "rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 1.0",
    );
    let m = maps(&d);
    let s = &d.document.sensor;
    let sigma = tofprobe_dsp::closed_form::sigma_total_mm(s.jitter_mm(), s.tdc_lsb_mm());
    // Rectangular periodic ROM: N_eff = N.
    let floor_um = tofprobe_dsp::closed_form::noise_floor_mm(sigma, 200_000.0) * 1000.0;
    for b in 0..m.bins() {
        let mean = m.mean_amplitude(b);
        // |Y| is Rayleigh (CV 0.52): the mean of 64 pixels has a 6.5 % standard error; 4σ
        // is 26 %, and the ΣΔ probe's own in-band error is below 1 % of the floor.
        assert!(
            (mean / floor_um - 1.0).abs() < 0.26,
            "bin {b} at {} Hz: mean {mean} µm, closed form {floor_um} µm",
            m.frequencies_hz[b]
        );
    }
}

#[test]
fn a_rotor_shows_its_blade_pass_where_its_blades_cross() {
    // 3 blades at 10,000 rpm: blade pass 500 Hz, a ROM bin (k = 1). Centre of the 8 × 8
    // array of 5 mm pixels (20, 20) mm, tip radius 12 mm: the corners are outside.
    let rotor = "[[scene.motion]]\nkind = \"rotor\"\nblades = 3\nrpm = 10000.0\n\
                 centre_x_mm = 20.0\ncentre_y_mm = 20.0\nradius_mm = 12.0\n\
                 hub_radius_mm = 2.0\nblade_mm = -2.0\n";
    let d = design(
        rotor,
        200_000,
        "rows = 8\ncols = 8\npitch_um = 30.0\nmm_per_pixel = 5.0",
    );
    let m = maps(&d);
    let b = m
        .frequencies_hz
        .iter()
        .position(|&f| f == 500.0)
        .expect("the blade-pass frequency is a bin");
    let a = m.amplitude(b);
    // A ±1 mm square wave (blade fraction ½) has a fundamental of 4/π mm = 1273 µm; noise
    // ≈ 30 µm. Pixels crossed by the blades read > 600 µm; pixels outside < 150 µm (5σ).
    let (mut crossed, mut outside) = (0, 0);
    for (i, &amp) in a.iter().enumerate() {
        let (x, y) = ((i % 8) as f64 * 5.0 + 2.5, (i / 8) as f64 * 5.0 + 2.5);
        let r = (x - 20.0f64).hypot(y - 20.0);
        if (3.0..11.0).contains(&r) {
            assert!(amp > 600.0, "pixel {i} at r = {r} mm reads {amp} µm");
            crossed += 1;
        } else if r > 13.0 {
            assert!(amp < 150.0, "pixel {i} at r = {r} mm reads {amp} µm");
            outside += 1;
        }
    }
    assert!(
        crossed >= 12 && outside >= 4,
        "{crossed} crossed, {outside} outside"
    );
}

/// A −4 mm step sweeping 12 × 12 pixels of 1 mm along +x at 6 m/s (each column 167 µs
/// after the last, the first 250 µs into a 3.3 ms Haar frame of 2^15 pulses): every pixel
/// has a transition, and the plane fit of their times gives the speed within 5 % and the
/// direction within 3°. A wrong speed in the scene moves the fit (the check can fail).
#[test]
fn a_sweeping_edge_has_its_velocity() {
    let edge = |v: f64| {
        format!(
            "[[scene.motion]]\nkind = \"edge\"\nheight_mm = -4.0\nvelocity_mm_per_s = {v}\n\
             start_mm = -1.0\n"
        )
    };
    let array = "rows = 12\ncols = 12\npitch_um = 30.0\nmm_per_pixel = 1.0";
    let measure = |v: f64| {
        let d = crate::common::haar_design(&edge(v), 1 << 15, array);
        let frame = run_array(&d, None).unwrap();
        tofprobe_array::events::event_map(&d, &frame)
    };
    let e = measure(6000.0);
    assert_eq!(e.pixels, 144, "every pixel steps inside the frame");
    let v = e.velocity_mm_per_s.unwrap();
    // Per-pixel timing noise: 32 segment means of 1024 pulses, σ 7.5 mm / 32 ≈ 0.23 mm
    // each against a 4 mm step: ≈ 30 µs per pixel; over 144 pixels spanning 1.8 ms the
    // slope's error is ≈ 0.5 %: 5 % is the tolerance.
    assert!((v / 6000.0 - 1.0).abs() < 0.05, "{v} mm/s");
    assert!(
        e.direction_deg.unwrap().abs() < 3.0,
        "{:?}",
        e.direction_deg
    );
    let slower = measure(4000.0).velocity_mm_per_s.unwrap();
    assert!((slower / 4000.0 - 1.0).abs() < 0.05 && (slower / 6000.0 - 1.0).abs() > 0.2);
}

/// Issue 46 point 4: per-pixel edge times from the least-squares fit scatter as the fit
/// predicts. Edges the examples do not use: a step at 7 m/s towards 37°, and a 2 mm-wide
/// front (a ramp of 0.57 ms) at 3.5 m/s towards −120°, over 12 × 12 pixels of 1 mm (2^15
/// pulses, U = 4). Each pixel's error against the scene's arrival (the front's centre at
/// the pixel's centre) over its stated sd has an rms within [1/1.5, 1.5] (144 pixels: the
/// rms of unit normals is within ±6 % at 1 sd); the weighted velocity is within 3 % and
/// 2°. The old estimator (levels from the first and last cell only, the area rule) on the
/// same registers fails the bar against the same sd by far.
#[test]
fn edge_times_scatter_as_the_fit_predicts() {
    let array = "rows = 12\ncols = 12\npitch_um = 30.0\nmm_per_pixel = 1.0";
    for (v, dir, width, start) in [(7000.0, 37.0, 0.0, -1.0), (3500.0, -120.0, 2.0, -14.0)] {
        let m = format!(
            "[[scene.motion]]\nkind = \"edge\"\nheight_mm = -4.0\nvelocity_mm_per_s = {v}\n\
             direction_deg = {dir}\nstart_mm = {start}\nwidth_mm = {width}\n"
        );
        let d = crate::common::haar_design(&m, 1 << 15, array);
        let frame = run_array(&d, None).unwrap();
        let e = tofprobe_array::events::event_map(&d, &frame);
        let (sn, cs) = f64::to_radians(dir).sin_cos();
        let (mut z2, mut old2, mut k) = (0.0, 0.0, 0.0);
        for p in 0..144 {
            let (x, y) = ((p % 12) as f64 + 0.5, (p / 12) as f64 + 0.5);
            let truth_ms = ((x * cs + y * sn - start) / v + 0.5 * width / v) * 1e3;
            let (t, sd) = (e.time_ms[p], e.time_sd_ms[p]);
            if t < 0.0 {
                continue;
            }
            // Only fronts inside the frame with a cell of level each side.
            if !(0.3..3.0).contains(&truth_ms) {
                continue;
            }
            z2 += ((t - truth_ms) / sd).powi(2);
            old2 += ((area_time_ms(&d, &frame, p) - truth_ms) / sd).powi(2);
            k += 1.0;
        }
        let (rms, old) = ((z2 / k).sqrt(), (old2 / k).sqrt());
        assert!(k >= 60.0, "{k} pixels");
        assert!(
            (1.0 / 1.5..1.5).contains(&rms),
            "{v} mm/s {dir}°: rms z {rms} over {k}"
        );
        assert!(old > 3.0, "the area rule scatters {old} sd");
        let speed = e.velocity_mm_per_s.unwrap();
        assert!((speed / v - 1.0).abs() < 0.03, "{speed} mm/s");
        let de = (e.direction_deg.unwrap() - dir + 540.0).rem_euclid(360.0) - 180.0;
        assert!(de.abs() < 2.0, "{:?}", e.direction_deg);
    }
}

/// The estimator before issue 46: levels a, b from the first and last cell, τ = Σ (m_j −
/// b)/(a − b) × the cell's duration (ms).
fn area_time_ms(
    d: &tofprobe_design::ResolvedDesign,
    frame: &tofprobe_array::model::ArrayFrame,
    p: usize,
) -> f64 {
    let s = d.sensor();
    let (n, u) = (d.pixel.frame_pulses, d.pixel.haar_scales);
    let sc = tofprobe_dsp::haar::Scalogram::from_registers(
        frame.pixel(p / frame.cols, p % frame.cols),
        n,
        u,
        s.tdc_lsb_mm(),
        s.laser_rate_hz,
    )
    .unwrap();
    let m = sc.cell_means_mm();
    let (a, b) = (m[0], m[m.len() - 1]);
    let cell_ms = sc.duration_s() / m.len() as f64 * 1e3;
    m.iter().map(|&x| (x - b) / (a - b) * cell_ms).sum()
}
