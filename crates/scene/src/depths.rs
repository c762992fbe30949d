//! How the batched Monte Carlo evaluates a block's depths δ(t): a sine motion as
//! sin(θ_j + kΔ) = s_j cos kΔ + c_j sin kΔ over sub-blocks of [`SUB`] pulses from a table of
//! (cos kΔ, sin kΔ) (no serial recurrence per pulse); other motions by the scene's own
//! evaluation (crates/scene/src/batch.rs is the kernel that reads them).

use std::f64::consts::TAU;

use crate::MotionConfig;
use crate::scene::Scene;

/// Pulses per sine sub-block (one table of cos kΔ, sin kΔ).
pub(crate) const SUB: usize = 64;

/// A sine motion's per-sub-block tables.
#[derive(Debug, Clone)]
pub(crate) struct SineTable {
    amplitude_mm: f64,
    frequency_hz: f64,
    phase_deg: f64,
    cos_k: [f64; SUB],
    sin_k: [f64; SUB],
    /// (sin, cos) of SUB·Δ: the step from one sub-block's anchor to the next.
    step: (f64, f64),
}

/// How the batched kernel evaluates δ(t): the sine tables when every motion is a sine.
#[derive(Debug, Clone)]
pub(crate) struct Depths {
    sines: Option<Vec<SineTable>>,
}

impl Depths {
    pub(crate) fn new(scene: &Scene, period_s: f64) -> Depths {
        let sines = scene
            .motions()
            .iter()
            .map(|m| match *m {
                MotionConfig::Sine {
                    amplitude_mm,
                    frequency_hz,
                    phase_deg,
                } => {
                    let d = TAU * frequency_hz * period_s;
                    let mut cos_k = [0.0; SUB];
                    let mut sin_k = [0.0; SUB];
                    for k in 0..SUB {
                        (sin_k[k], cos_k[k]) = (d * k as f64).sin_cos();
                    }
                    Some(SineTable {
                        amplitude_mm,
                        frequency_hz,
                        phase_deg,
                        cos_k,
                        sin_k,
                        step: (d * SUB as f64).sin_cos(),
                    })
                }
                _ => None,
            })
            .collect();
        Depths { sines }
    }

    /// δ (mm) of pulses `first_pulse ..` into `out`.
    #[inline(always)]
    pub(crate) fn fill(&self, scene: &Scene, first_pulse: u64, period_s: f64, out: &mut [f64]) {
        let Some(sines) = &self.sines else {
            scene.fill_depths_mm(first_pulse, period_s, out);
            return;
        };
        let base = scene.static_depth_mm();
        if sines.is_empty() {
            out.fill(base);
        }
        for (n, t) in sines.iter().enumerate() {
            // The anchor's phase reduced modulo one period first (as the reference does).
            let cycles =
                (t.frequency_hz * period_s * first_pulse as f64).fract() + t.phase_deg / 360.0;
            let (mut s, mut c) = (TAU * cycles).sin_cos();
            let (ds, dc) = t.step;
            for sub in out.chunks_mut(SUB) {
                let (a_s, a_c) = (t.amplitude_mm * s, t.amplitude_mm * c);
                // The first motion's term is added to the static depth as it is written
                // (the same sum as filling first: one pass over the block, not two).
                if n == 0 {
                    for ((d, &ck), &sk) in sub.iter_mut().zip(&t.cos_k).zip(&t.sin_k) {
                        *d = base + (a_s * ck + a_c * sk);
                    }
                } else {
                    for ((d, &ck), &sk) in sub.iter_mut().zip(&t.cos_k).zip(&t.sin_k) {
                        *d += a_s * ck + a_c * sk;
                    }
                }
                let s1 = s * dc + c * ds;
                c = c * dc - s * ds;
                s = s1;
            }
        }
    }
}
