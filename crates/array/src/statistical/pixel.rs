//! What the statistical levels read of one pixel: the motion it sees (its SPADs' static
//! depths and sines, averaged over a superpixel's G² SPADs like the front end averages
//! their codes) and the statistics of its detected codes from the closed forms of
//! `tofprobe_dsp::closed_form` (the first-arrival mixture: valid rate ρ_v with pile-up,
//! mean, variance plus a²/12, the gain ∂μ/∂t_s by which the mean follows the signal) or,
//! for a superpixel, `tofprobe_dsp::superpixel` (ρ' = 1 − (1 − p)^{G²} and the mean
//! square error of the rounded average).

use rustfft::num_complex::Complex64;
use tofprobe_design::{DesignError, ResolvedDesign};
use tofprobe_dsp::closed_form::{MixtureParams, detected, mixture_gain};
use tofprobe_dsp::superpixel::superpixel_noise;
use tofprobe_scene::{MotionConfig, Scene};

use crate::error::ArrayError;

/// The rates and static depth a pixel's code statistics depend on (f64 bits, so equal
/// pixels share one computation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NoiseKey {
    signal_rate: u64,
    background_rate: u64,
    depth_mm: u64,
}

/// One pixel's scene: the key of its code statistics and its sines, each as (frequency
/// Hz, a·e^{jφ} mm for a·sin(2πft + φ)).
#[derive(Debug, Clone)]
pub struct PixelScene {
    pub key: NoiseKey,
    pub sines: Vec<(f64, Complex64)>,
}

/// The statistics of a pixel's detected code (TDC codes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CodeStats {
    /// ρ_v: a pulse's probability of a detection (the hold's rate).
    pub valid_rate: f64,
    /// E\[code\] of a detection.
    pub mean_code: f64,
    /// Var\[code\] of a detection (codes², the TDC's 1/12 included).
    pub variance: f64,
    /// ∂E\[depth\]/∂t_s: the part of a small motion the mean follows (1 without background).
    pub gain: f64,
}

/// The scene of pixel (r, c) of `design` (an `[array]` design), from the parsed `scene`.
pub fn pixel_scene(
    design: &ResolvedDesign,
    scene: &Scene,
    r: usize,
    c: usize,
) -> Result<PixelScene, ArrayError> {
    let a = design
        .array
        .as_ref()
        .ok_or_else(|| ArrayError::Shape(format!("`{}` has no [array]", design.origin)))?;
    let spads: Vec<(usize, usize)> = a.spads_of(r, c).collect();
    let k = spads.len() as f64;
    let (mut rs, mut rb, mut depth) = (0.0, 0.0, 0.0);
    let mut sines: Vec<(f64, Complex64)> = Vec::new();
    for &(sr, sc) in &spads {
        let i = sr * a.spad_cols() + sc;
        rs += a.signal_rate[i] / k;
        rb += a.background_rate[i] / k;
        let (x, y) = a.spad_centre_mm(sr, sc);
        let at = scene.at_point(x, y);
        depth += at.static_depth_mm() / k;
        for m in at.motions() {
            let MotionConfig::Sine {
                amplitude_mm,
                frequency_hz,
                phase_deg,
            } = m
            else {
                return Err(ArrayError::Shape(format!(
                    "array.level = \"{}\" models sines and plate modes only: scene motion {} \
                     at pixel ({r}, {c})",
                    a.level,
                    m.kind()
                )));
            };
            let z = Complex64::from_polar(amplitude_mm / k, phase_deg.to_radians());
            match sines.iter_mut().find(|(f, _)| f == frequency_hz) {
                Some((_, s)) => *s += z,
                None => sines.push((*frequency_hz, z)),
            }
        }
    }
    Ok(PixelScene {
        key: NoiseKey {
            signal_rate: rs.to_bits(),
            background_rate: rb.to_bits(),
            depth_mm: depth.to_bits(),
        },
        sines,
    })
}

/// The code statistics of a pixel of `key` in `design`.
pub fn code_stats(design: &ResolvedDesign, key: NoiseKey) -> Result<CodeStats, ArrayError> {
    let s = design.sensor();
    let lsb = s.tdc_lsb_mm();
    let (rs, rb) = (
        f64::from_bits(key.signal_rate),
        f64::from_bits(key.background_rate),
    );
    let depth = f64::from_bits(key.depth_mm) - s.window_start_mm();
    let g = design.array.as_ref().map_or(1, |a| a.superpixel);
    let err = |e| ArrayError::from(DesignError::probe(&design.origin, e));
    if g > 1 {
        if rs <= 0.0 {
            return Ok(CodeStats {
                valid_rate: 0.0,
                mean_code: 0.0,
                variance: 0.0,
                gain: 1.0,
            });
        }
        let sp = superpixel_noise((g * g) as u32, rs.min(1.0), s.jitter_mm() / lsb).map_err(err)?;
        return Ok(CodeStats {
            valid_rate: sp.detection_rate,
            mean_code: depth / lsb - 0.5,
            variance: sp.mse_lsb2,
            gain: 1.0,
        });
    }
    let mixture = MixtureParams {
        signal_rate: rs,
        background_rate: rb,
        signal_depth_mm: depth,
        jitter_mm: s.jitter_mm(),
        window_mm: s.window_end_mm() - s.window_start_mm(),
    };
    let fa = detected(&mixture).map_err(err)?;
    let gain = if rb > 0.0 && rs > 0.0 {
        mixture_gain(&mixture).map_err(err)?
    } else {
        1.0
    };
    Ok(CodeStats {
        valid_rate: fa.valid_rate.min(1.0),
        // A code is floor(t/a): its mean sits half a code below t/a (Sheppard).
        mean_code: fa.mean_mm / lsb - 0.5,
        variance: (fa.variance_mm2 + lsb * lsb / 12.0) / (lsb * lsb),
        gain,
    })
}
