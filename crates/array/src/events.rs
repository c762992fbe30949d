//! Haar arrays: each pixel's transition time with its uncertainty, and the velocity of an
//! edge across the sensor. A pixel's registers, as its scalogram
//! (`Scalogram::from_registers`), go through the pixel's own least-squares step/ramp fit,
//! `tofprobe_dsp::haar::fit_transition` (one implementation for the pixel and the array):
//! the fitted centre of the transition and its Cramér–Rao sd under the closed-form noise
//! of the scene's static depth. A pixel whose fitted |height| is below 8 σ of a segment
//! mean has no transition (its time is −1 in the map). The edge's velocity comes from the
//! weighted least-squares plane t = t0 + g·(x, y) over the pixels with a transition at
//! least 3 sd inside the frame's first and last segments (nearer, the fit sees less than a
//! segment of level on one side and its time is censored), weights 1/sd²: speed 1/|g|,
//! direction atan2(g_y, g_x).

use rayon::prelude::*;
use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_dsp::haar::FAMILY_RATE;
use tofprobe_dsp::haar::analysis::Scalogram;
use tofprobe_dsp::haar::{HaarNoise, Thresholds, fit_transition};

use crate::model::ArrayFrame;

/// The event-time map and the edge fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventMap {
    /// [R, C] transition time (ms from the frame start); −1 where there is none.
    pub time_ms: Vec<f64>,
    /// [R, C] the fit's sd of each time (ms); −1 where there is none.
    pub time_sd_ms: Vec<f64>,
    /// Pixels with a transition.
    pub pixels: usize,
    /// The fitted edge: speed (mm/s on the scene plane) and direction (degrees from +x
    /// towards +y); `None` with fewer than 3 transitions or no motion resolved.
    pub velocity_mm_per_s: Option<f64>,
    pub direction_deg: Option<f64>,
}

/// The map and fit of a Haar frame.
pub fn event_map(design: &ResolvedDesign, frame: &ArrayFrame) -> EventMap {
    let u = design.pixel.haar_scales;
    let n = design.pixel.frame_pulses;
    let s = design.sensor();
    let segments = 1usize << (u + 1);
    // σ of a segment mean in codes (the depth noise over its pulses), from eq. 12's σ_s.
    let sigma_codes =
        tofprobe_dsp::closed_form::sigma_total_mm(s.jitter_mm(), s.tdc_lsb_mm()) / s.tdc_lsb_mm();
    let min_step = 8.0 * sigma_codes / (n as f64 / segments as f64).sqrt();
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    // The per-coefficient sd of the noise model (the resolution validated U and N).
    let sd_mm = HaarNoise::for_static_scene(s, design.document.scene.depth_mm)
        .and_then(|noise| Thresholds::new(&noise, n as usize, u, FAMILY_RATE))
        .map(|t| t.sd_mm)
        .unwrap_or_default();
    // A time within 3 sd of a segment from the frame's start or end is censored: the fit
    // has less than a segment of level on that side, and its times there bias the plane.
    let frame_s = n as f64 / s.laser_rate_hz;
    let segment_s = frame_s / segments as f64;
    let inside = |t: f64, sd: f64| t - 3.0 * sd > segment_s && t + 3.0 * sd < frame_s - segment_s;
    // The fits are independent: in parallel on the caller's pool, collected in pixel order
    // and accumulated serially, so the map and the plane are the same on any thread count.
    let fits: Vec<Option<(f64, f64)>> = (0..frame.rows * frame.cols)
        .into_par_iter()
        .map(|p| {
            let (r, c) = (p / frame.cols, p % frame.cols);
            // The frame holds 2^(U+1) − 1 words per pixel.
            let scalogram =
                Scalogram::from_registers(frame.pixel(r, c), n, u, s.tdc_lsb_mm(), s.laser_rate_hz)
                    .ok()?;
            fit_transition(&scalogram, &sd_mm)
                .filter(|f| f.height_mm.abs() >= min_step && f.time_sd_s.is_finite())
                .map(|f| (f.time_s, f.time_sd_s))
        })
        .collect();
    let mut time_ms = vec![-1.0; frame.rows * frame.cols];
    let mut time_sd_ms = vec![-1.0; frame.rows * frame.cols];
    let mut points = Vec::new();
    let mut events = 0;
    for (p, fit) in fits.into_iter().enumerate() {
        let Some((time_s, time_sd_s)) = fit else {
            continue;
        };
        let (r, c) = (p / frame.cols, p % frame.cols);
        time_ms[p] = time_s * 1e3;
        time_sd_ms[p] = time_sd_s * 1e3;
        let w = 1.0 / time_sd_s.powi(2).max(f64::MIN_POSITIVE);
        events += 1;
        if inside(time_s, time_sd_s) {
            points.push(((c as f64 + 0.5) * mm, (r as f64 + 0.5) * mm, time_s, w));
        }
    }
    let (velocity, direction) = match fit_plane(&points) {
        Some((gx, gy)) if gx.hypot(gy) > 0.0 => {
            (Some(1.0 / gx.hypot(gy)), Some(gy.atan2(gx).to_degrees()))
        }
        _ => (None, None),
    };
    EventMap {
        time_ms,
        time_sd_ms,
        pixels: events,
        velocity_mm_per_s: velocity.filter(|v| v.is_finite()),
        direction_deg: direction.filter(|d| d.is_finite()),
    }
}

/// Weighted least squares t = t0 + gx·x + gy·y over points (x, y, t, weight): (gx, gy)
/// in s/mm, or `None` when the positions do not span a plane's worth of directions (fewer
/// than 3, or collinear, fitted along their line instead).
pub fn fit_plane(p: &[(f64, f64, f64, f64)]) -> Option<(f64, f64)> {
    if p.len() < 3 {
        return None;
    }
    let k: f64 = p.iter().map(|q| q.3).sum();
    let (mx, my, mt) = p.iter().fold((0.0, 0.0, 0.0), |a, q| {
        (
            a.0 + q.3 * q.0 / k,
            a.1 + q.3 * q.1 / k,
            a.2 + q.3 * q.2 / k,
        )
    });
    let (mut sxx, mut syy, mut sxy, mut sxt, mut syt) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(x, y, t, w) in p {
        let (dx, dy, dt) = (x - mx, y - my, t - mt);
        sxx += w * dx * dx;
        syy += w * dy * dy;
        sxy += w * dx * dy;
        sxt += w * dx * dt;
        syt += w * dy * dt;
    }
    let det = sxx * syy - sxy * sxy;
    if det.abs() > 1e-12 * (sxx * syy).max(f64::MIN_POSITIVE) {
        Some(((sxt * syy - syt * sxy) / det, (syt * sxx - sxt * sxy) / det))
    } else if sxx > 0.0 {
        Some((sxt / sxx, 0.0))
    } else if syy > 0.0 {
        Some((0.0, syt / syy))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noiseless step of 10 codes at pulse 300 of 1024 (U = 3: 16 cells of 64): the
    /// least-squares fit of the registers puts it at 300 pulses (to the golden section's
    /// 1e-6 pulse) with height −10 mm.
    #[test]
    fn the_fit_is_exact_on_a_step() {
        let x: Vec<i64> = (0..1024).map(|n| if n < 300 { 40 } else { 30 }).collect();
        let words = tofprobe_dsp::haar::haar_sums(&x, 3).unwrap();
        let s = Scalogram::from_registers(&words, 1024, 3, 1.0, 1.0).unwrap();
        let f = fit_transition(&s, &[0.01; 15]).unwrap();
        assert!((f.time_s - 300.0).abs() < 1e-6, "{f:?}");
        assert!(
            (f.height_mm + 10.0).abs() < 1e-9 && f.duration_s == 0.0,
            "{f:?}"
        );
    }

    /// Weighting by 1/sd²: points on a 10 × 10 grid whose times carry noise of sd 1 µs
    /// (even columns) or 20 µs (odd), 400 draws. The weighted slope's error has the sd
    /// of weighted least squares, σ_g² = 1/Σ w (x − x̄_w)²; the unweighted fit's is
    /// larger (≈ 14 µs/√(Σ(x − x̄)²) here, 7× larger): its error sd must exceed twice the
    /// weighted prediction, and the weighted one lies within 20 % of it (400 draws: the
    /// sample sd is within ±3.5 % at 1 sd).
    #[test]
    fn the_weighted_plane_fit_has_its_predicted_spread() {
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut normal = || {
            let mut u = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        let grid: Vec<(f64, f64, f64)> = (0..100)
            .map(|i| {
                let (x, y) = ((i % 10) as f64, (i / 10) as f64);
                (x, y, if i % 2 == 0 { 1e-6 } else { 20e-6 })
            })
            .collect();
        let w: f64 = grid.iter().map(|g| g.2.powi(-2)).sum();
        let xw: f64 = grid.iter().map(|g| g.0 * g.2.powi(-2)).sum::<f64>() / w;
        let predicted = 1.0
            / grid
                .iter()
                .map(|g| (g.0 - xw).powi(2) / g.2.powi(2))
                .sum::<f64>()
                .sqrt();
        let (mut ew, mut eu) = (0.0, 0.0);
        let draws = 400;
        for _ in 0..draws {
            let pts: Vec<_> = grid
                .iter()
                .map(|&(x, y, sd)| (x, y, 1e-3 + x / 500.0 + sd * normal(), sd.powi(-2)))
                .collect();
            ew += (fit_plane(&pts).unwrap().0 - 1.0 / 500.0).powi(2);
            let flat: Vec<_> = pts.iter().map(|p| (p.0, p.1, p.2, 1.0)).collect();
            eu += (fit_plane(&flat).unwrap().0 - 1.0 / 500.0).powi(2);
        }
        let (sw, su) = ((ew / draws as f64).sqrt(), (eu / draws as f64).sqrt());
        assert!((sw / predicted - 1.0).abs() < 0.2, "{sw} vs {predicted}");
        assert!(su > 2.0 * predicted, "unweighted {su} vs {predicted}");
    }

    #[test]
    fn the_plane_fit_recovers_a_slowness() {
        // t = 0.1 + (x·cos 30° + y·sin 30°)/500 mm/s.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let p: Vec<_> = (0..20)
            .map(|i| {
                let (x, y) = ((i % 5) as f64, (i / 5) as f64);
                (x, y, 0.1 + (x * c + y * s) / 500.0, 1.0)
            })
            .collect();
        let (gx, gy) = fit_plane(&p).unwrap();
        assert!((1.0 / gx.hypot(gy) - 500.0).abs() < 1e-9);
        assert!((gy.atan2(gx).to_degrees() - 30.0).abs() < 1e-9);
    }
}
