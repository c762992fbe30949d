//! Haar arrays: each pixel's transition time, and the velocity of an edge across the
//! sensor. A pixel's registers, as its scalogram (`Scalogram::from_registers`), give the
//! mean depth (relative to the frame's) of each of the 2^(U+1) finest half-wavelets through
//! the one inverse transform, `Scalogram::cell_means_mm`. For one transition from level a (first segment) to b (last
//! segment) at time τ, segment j's mean is a·f_j + b·(1 − f_j), f_j its fraction before
//! τ, so τ = Σ_j (m_j − b)/(a − b) · (its duration): exact for a noiseless step wherever it
//! falls, the "area" estimator. A pixel whose |a − b| is below 8 σ of a segment mean has no
//! transition (its time is −1 in the map). The edge's velocity comes from the
//! least-squares plane t = t0 + g·(x, y) over the pixels with a transition: speed 1/|g|,
//! direction atan2(g_y, g_x).

use serde::Serialize;
use tofprobe_design::ResolvedDesign;
use tofprobe_dsp::haar::analysis::Scalogram;

use crate::model::ArrayFrame;

/// The event-time map and the edge fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventMap {
    /// [R, C] transition time (ms from the frame start); −1 where there is none.
    pub time_ms: Vec<f64>,
    /// Pixels with a transition.
    pub pixels: usize,
    /// The fitted edge: speed (mm/s on the scene plane) and direction (degrees from +x
    /// towards +y); `None` with fewer than 3 transitions or no motion resolved.
    pub velocity_mm_per_s: Option<f64>,
    pub direction_deg: Option<f64>,
}

/// The transition time (s) of one pixel's cell means `m`, or `None` below `min_step`.
pub fn transition_time_s(m: &[f64], segment_s: f64, min_step: f64) -> Option<f64> {
    let (a, b) = (*m.first()?, *m.last()?);
    if (a - b).abs() < min_step {
        return None;
    }
    let t: f64 = m.iter().map(|&x| (x - b) / (a - b) * segment_s).sum();
    Some(t.clamp(0.0, segment_s * m.len() as f64))
}

/// The map and fit of a Haar frame.
pub fn event_map(design: &ResolvedDesign, frame: &ArrayFrame) -> EventMap {
    let u = design.pixel.haar_scales;
    let n = design.pixel.frame_pulses;
    let s = design.sensor();
    let segments = 1usize << (u + 1);
    let segment_s = n as f64 / segments as f64 / s.laser_rate_hz;
    // σ of a segment mean in codes (the depth noise over its pulses), from eq. 12's σ_s.
    let sigma_codes =
        tofprobe_dsp::closed_form::sigma_total_mm(s.jitter_mm(), s.tdc_lsb_mm()) / s.tdc_lsb_mm();
    let min_step = 8.0 * sigma_codes / (n as f64 / segments as f64).sqrt();
    let mm = design.array.as_ref().map_or(1.0, |a| a.mm_per_pixel);
    let mut time_ms = vec![-1.0; frame.rows * frame.cols];
    let mut points = Vec::new();
    for (p, t) in time_ms.iter_mut().enumerate() {
        let (r, c) = (p / frame.cols, p % frame.cols);
        // The resolution validated U and N, and the frame holds 2^(U+1) − 1 words per pixel.
        let Ok(scalogram) =
            Scalogram::from_registers(frame.pixel(r, c), n, u, s.tdc_lsb_mm(), s.laser_rate_hz)
        else {
            continue;
        };
        let m = scalogram.cell_means_mm();
        if let Some(ts) = transition_time_s(&m, segment_s, min_step) {
            *t = ts * 1e3;
            points.push(((c as f64 + 0.5) * mm, (r as f64 + 0.5) * mm, ts));
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
        pixels: points.len(),
        velocity_mm_per_s: velocity.filter(|v| v.is_finite()),
        direction_deg: direction.filter(|d| d.is_finite()),
    }
}

/// Least squares t = t0 + gx·x + gy·y: (gx, gy) in s/mm, or `None` when the positions do
/// not span a plane's worth of directions (fewer than 3, or collinear, fitted along their
/// line instead).
fn fit_plane(p: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
    if p.len() < 3 {
        return None;
    }
    let k = p.len() as f64;
    let (mx, my, mt) = p.iter().fold((0.0, 0.0, 0.0), |a, q| {
        (a.0 + q.0 / k, a.1 + q.1 / k, a.2 + q.2 / k)
    });
    let (mut sxx, mut syy, mut sxy, mut sxt, mut syt) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(x, y, t) in p {
        let (dx, dy, dt) = (x - mx, y - my, t - mt);
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
        sxt += dx * dt;
        syt += dy * dt;
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

    /// A noiseless step of 10 codes at pulse 300 of 1024 (U = 3: 16 segments of 64): the
    /// detail sums of the record, as a scalogram of 1 mm codes and inverted, put the step at
    /// 300 pulses exactly.
    #[test]
    fn the_area_estimator_is_exact_on_a_step() {
        let x: Vec<i64> = (0..1024).map(|n| if n < 300 { 40 } else { 30 }).collect();
        let words = tofprobe_dsp::haar::haar_sums(&x, 3).unwrap();
        let m = Scalogram::from_registers(&words, 1024, 3, 1.0, 1.0)
            .unwrap()
            .cell_means_mm();
        assert_eq!(m.len(), 16);
        // Segment 0 is 10 mm above segment 15 (relative levels).
        assert!((m[0] - m[15] - 10.0).abs() < 1e-12);
        let t = transition_time_s(&m, 64.0, 1.0).unwrap();
        assert!((t - 300.0).abs() < 1e-9, "{t}");
        assert!(
            transition_time_s(&m, 64.0, 11.0).is_none(),
            "below the threshold"
        );
    }

    #[test]
    fn the_plane_fit_recovers_a_slowness() {
        // t = 0.1 + (x·cos 30° + y·sin 30°)/500 mm/s.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let p: Vec<_> = (0..20)
            .map(|i| {
                let (x, y) = ((i % 5) as f64, (i / 5) as f64);
                (x, y, 0.1 + (x * c + y * s) / 500.0)
            })
            .collect();
        let (gx, gy) = fit_plane(&p).unwrap();
        assert!((1.0 / gx.hypot(gy) - 500.0).abs() < 1e-9);
        assert!((gy.atan2(gx).to_degrees() - 30.0).abs() < 1e-9);
    }
}
