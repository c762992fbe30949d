//! Beyond the paper (issue 46, point 6; the paper's own future work): a motion-model
//! imputation of the missed pulses against the pixel's 1NN hold, through the float
//! reference of Table 2 (the one front end, `tofprobe_dsp::preprocess::FrontEnd` with
//! `tofprobe_dsp::imputation`, raw held depth → Blackman FFT of the whole record).
//!
//! Scenes: Table 2's rows at ρ_s ∈ {0.03, 0.1, 0.3} (σ_s = 7.5 mm, 100 µm at 4.5 kHz),
//! with every background rate Table 2 gives at ρ_s = 0.3. Per scene and seed, one record
//! read three ways: the hold, the Kalman filter with the scene's physics
//! (`KalmanParams::from_scene`: σ_w = σ_s, σ_a = A·ω², gate 3 sd) and its fixed-gain α-β
//! form (`AlphaBeta::from_kalman` at ρ_s: power-of-two gains, what a pixel would build,
//! [`super::imputation_cost`]). Each reads Table 2's noise floor (mean |Y| over 1–10 kHz,
//! tone ±8 bins out) and amplitude (interpolated peak), the floor near the tone
//! ([`TONE_BAND`]) and the SNR there; the closed forms where they exist (the hold's eq. 12
//! extension, the α-β form's `imputation::response`, both with the background mixture).
//!
//! Power: the band floor averages ≈ 9000 bins (N = 10^7), ≈ 1 % sd per seed, so 5 seeds
//! ([`DEFAULT_SEEDS`]) resolve the floors to ≈ 0.5 % and a floor ratio of 3–10 between
//! methods beyond doubt. The SNR at the tone is limited by the tone's own amplitude
//! estimate (sd ≈ 0.8 floor): the paired gain's sd per seed was 0.3–0.8 dB at ρ_s = 0.3
//! (tone 6–8 floors up), 1.6 dB at 0.1 and 3 dB at 0.03 (tone 2 floors up), i.e. a
//! standard error of 0.15–0.35, 0.7 and 1.4 dB at 5 seeds: enough to tell a 2–3 dB gain at
//! ρ_s = 0.3, not at 0.03 (raise `--imputation-seeds` there: se ∝ 1/√seeds); the floors
//! and the closed forms carry the comparison at low ρ_s.

use rayon::prelude::*;
use serde::Serialize;
use tofprobe_dsp::Window;
use tofprobe_dsp::closed_form::{hold_noise_factor, hold_response_sq};
use tofprobe_dsp::dft::amplitude_spectrum;
use tofprobe_dsp::imputation::response::{mean_response, noise_factor};
use tofprobe_dsp::imputation::{AlphaBeta, Imputation, KalmanParams};
use tofprobe_dsp::preprocess::{FrontEnd, FrontEndOutput};
use tofprobe_dsp::stats::{NoiseBand, interpolate_peak, noise_floor};
use tofprobe_io::markdown::{Align, Table};

use crate::ExperimentError;
use crate::paper::setup::FS_HZ;
use crate::paper::stats::mean_sd;
use crate::paper::table2::{
    self, BAND, F0_HZ, ROWS, Spec, closed_form_amp_for, closed_form_noise_on_bins_for, tone_bin,
};
use crate::records::detection_record;

/// The signal rates compared.
pub const RHO_S: [f64; 3] = [0.03, 0.1, 0.3];
/// Seeds per scene by default (see the module's power note).
pub const DEFAULT_SEEDS: usize = 5;
/// The band of the floor near the tone (Hz): ±25 % of f0, the tone ±8 bins out.
pub const TONE_BAND: (f64, f64) = (0.75 * F0_HZ, 1.25 * F0_HZ);
/// First seed of this study (its own records, none of Table 2's).
const SEED_BASE: u64 = 460_000;

/// The imputation methods compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Method {
    /// The pixel's 1NN hold.
    Hold,
    /// The constant-velocity Kalman filter (covariance per pulse, gated).
    Kalman,
    /// Its fixed-gain α-β form with power-of-two gains.
    AlphaBeta,
}

impl Method {
    pub const ALL: [Method; 3] = [Method::Hold, Method::Kalman, Method::AlphaBeta];
    pub fn name(self) -> &'static str {
        match self {
            Method::Hold => "1NN hold",
            Method::Kalman => "Kalman",
            Method::AlphaBeta => "alpha-beta (pixel)",
        }
    }
}

/// One method's readings of a record (µm, dB).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    pub noise_floor_um: f64,
    pub amplitude_um: f64,
    pub noise_at_tone_um: f64,
}

impl Reading {
    pub fn snr_at_tone_db(&self) -> f64 {
        20.0 * (self.amplitude_um / self.noise_at_tone_um).log10()
    }
}

/// Mean and sd over seeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    pub mean: f64,
    pub sd: f64,
}

impl Spread {
    fn of(v: &[f64]) -> Self {
        let (mean, sd) = mean_sd(v);
        Spread { mean, sd }
    }
}

/// One method on one scene, over the seeds.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MethodResult {
    pub method: String,
    /// Table 2's noise floor (1–10 kHz), µm.
    pub noise_floor_um: Spread,
    /// "A meas." at 4.5 kHz, µm.
    pub amplitude_um: Spread,
    /// The floor over [`TONE_BAND`], µm.
    pub noise_at_tone_um: Spread,
    pub snr_at_tone_db: Spread,
    /// SNR at the tone minus the hold's on the same records, dB.
    pub snr_gain_over_hold_db: Spread,
    /// Closed forms (hold and α-β; none for the time-varying Kalman), µm.
    pub closed_form_noise_floor_um: Option<f64>,
    pub closed_form_amplitude_um: Option<f64>,
    /// The closed-form floor over [`TONE_BAND`] (µm) and the SNR gain over the hold it
    /// predicts with the closed-form amplitude (dB; both read as the measurement is, so the
    /// floor's slope across the band is in both).
    pub closed_form_noise_at_tone_um: Option<f64>,
    pub closed_form_snr_gain_over_hold_db: Option<f64>,
}

/// A method's closed forms (µm): band floor, amplitude, floor over [`TONE_BAND`].
#[derive(Debug, Clone, Copy, Default)]
struct ClosedForms {
    floor: Option<f64>,
    amp: Option<f64>,
    near: Option<f64>,
}

impl ClosedForms {
    fn snr_db(&self) -> Option<f64> {
        Some(20.0 * (self.amp? / self.near?).log10())
    }
}

/// One scene (a Table 2 row).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SceneImputation {
    pub sigma_s_mm: f64,
    pub rho_s: f64,
    pub rho_b: f64,
    pub amplitude_true_um: f64,
    /// The Kalman filter's σ_a (mm/pulse²) and σ_w (mm), and the α-β gains.
    pub process_noise_mm_per_pulse2: f64,
    pub measurement_noise_mm: f64,
    pub alpha: f64,
    pub beta_per_pulse: f64,
    pub methods: Vec<MethodResult>,
}

/// The whole study.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ImputationReport {
    pub pulses: u64,
    pub seeds: usize,
    pub scenes: Vec<SceneImputation>,
    /// The pixel's cost of each form ([`super::imputation_cost`]).
    pub pixel_cost: Vec<super::imputation_cost::ImputationCost>,
}

/// The scenes: Table 2's tone rows at [`RHO_S`].
pub fn scenes() -> Vec<Spec> {
    ROWS.iter()
        .filter(|r| r.amp_um.is_some() && RHO_S.contains(&r.rho_s))
        .copied()
        .collect()
}

/// The Kalman filter and α-β form of a scene (physics defaults).
pub fn filters(spec: &Spec) -> Result<(KalmanParams, AlphaBeta), ExperimentError> {
    let a_mm = spec.amp_um.unwrap_or(0.0) * 1e-3;
    let w0 = 2.0 * std::f64::consts::PI * F0_HZ / FS_HZ;
    let k = KalmanParams::from_scene(spec.sigma_s_mm, a_mm, w0);
    Ok((k, AlphaBeta::from_kalman(&k, spec.rho_s)?))
}

/// The imputation of `method` for `spec`.
pub fn imputation(spec: &Spec, method: Method) -> Result<Imputation, ExperimentError> {
    let (k, g) = filters(spec)?;
    Ok(match method {
        Method::Hold => Imputation::Hold,
        Method::Kalman => Imputation::Kalman(k),
        Method::AlphaBeta => Imputation::AlphaBeta(g),
    })
}

/// Reads one imputed record (mm) as Table 2 does, plus the floor near the tone.
pub fn read(record: &[f64]) -> Result<Reading, ExperimentError> {
    let n = record.len();
    let spectrum = amplitude_spectrum(record, Window::Blackman)?;
    let m = table2::measure_spectrum(&spectrum, n, true)?;
    let k0 = tone_bin(n) as f64;
    let near = noise_floor(
        &spectrum,
        n,
        FS_HZ,
        &NoiseBand::new(TONE_BAND.0, TONE_BAND.1),
        &[k0],
    )?;
    let amp = interpolate_peak(&spectrum, k0 as usize, 2)?.amplitude;
    Ok(Reading {
        noise_floor_um: m.noise_um,
        amplitude_um: amp * 1e3,
        noise_at_tone_um: near * 1e3,
    })
}

/// The detections of a scene's record in mm (from the window start; `None`: missed).
pub fn depths(spec: &Spec, seed: u64, n: u64) -> Result<Vec<Option<f64>>, ExperimentError> {
    let source = spec.setup().source(seed)?;
    let codes = detection_record(&source, n);
    Ok(codes
        .iter()
        .map(|c| c.map(|c| source.code_to_depth_mm(c)))
        .collect())
}

/// `detections` through the one front end with `imputation` (raw held output).
pub fn impute(detections: &[Option<f64>], imp: Imputation) -> Result<Vec<f64>, ExperimentError> {
    let mut fe = FrontEnd::with_imputation(0.0, FrontEndOutput::Held, imp)?;
    Ok(detections.iter().map(|&d| fe.step(d)).collect())
}

/// One scene over `seeds` seeds of `n` pulses (seeds in parallel on the current pool).
pub fn measure_scene(
    spec: &Spec,
    n: u64,
    seeds: usize,
) -> Result<SceneImputation, ExperimentError> {
    let row = ROWS.iter().position(|r| r == spec).unwrap_or(0) as u64;
    let per_seed: Vec<Vec<Reading>> = (0..seeds as u64)
        .into_par_iter()
        .map(|s| {
            let det = depths(spec, SEED_BASE + 1000 * row + s, n)?;
            Method::ALL
                .iter()
                .map(|&m| read(&impute(&det, imputation(spec, m)?)?))
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<_, ExperimentError>>()?;
    let (k, g) = filters(spec)?;
    let cfs = Method::ALL
        .iter()
        .map(|&m| closed_forms(spec, n as usize, m, &g))
        .collect::<Result<Vec<_>, _>>()?;
    let mut methods = Vec::new();
    for (i, &m) in Method::ALL.iter().enumerate() {
        let col = |f: fn(&Reading) -> f64| {
            Spread::of(&per_seed.iter().map(|r| f(&r[i])).collect::<Vec<_>>())
        };
        let gain: Vec<f64> = per_seed
            .iter()
            .map(|r| r[i].snr_at_tone_db() - r[0].snr_at_tone_db())
            .collect();
        let cf = cfs[i];
        methods.push(MethodResult {
            method: m.name().into(),
            noise_floor_um: col(|r| r.noise_floor_um),
            amplitude_um: col(|r| r.amplitude_um),
            noise_at_tone_um: col(|r| r.noise_at_tone_um),
            snr_at_tone_db: col(Reading::snr_at_tone_db),
            snr_gain_over_hold_db: Spread::of(&gain),
            closed_form_noise_floor_um: cf.floor,
            closed_form_amplitude_um: cf.amp,
            closed_form_noise_at_tone_um: cf.near,
            closed_form_snr_gain_over_hold_db: cf.snr_db().zip(cfs[0].snr_db()).map(|(a, h)| a - h),
        });
    }
    Ok(SceneImputation {
        sigma_s_mm: spec.sigma_s_mm,
        rho_s: spec.rho_s,
        rho_b: spec.rho_b,
        amplitude_true_um: spec.amp_um.unwrap_or(0.0),
        process_noise_mm_per_pulse2: k.process_noise,
        measurement_noise_mm: k.measurement_noise,
        alpha: g.alpha,
        beta_per_pulse: g.beta,
        methods,
    })
}

/// The closed-form band floor and amplitude of `method` (µm): the hold's and the α-β
/// form's (its gate ignored: at 3 sd it drops < 0.3 % of the signal and, with background,
/// part of the mixture the closed form keeps — the measured floor sits below it there).
fn closed_forms(
    spec: &Spec,
    n: usize,
    method: Method,
    g: &AlphaBeta,
) -> Result<ClosedForms, ExperimentError> {
    let bins = |band: (f64, f64)| -> Result<Vec<u64>, ExperimentError> {
        Ok(NoiseBand::new(band.0, band.1)
            .bins(n / 2 + 1, n, FS_HZ, &[tone_bin(n) as f64])?
            .into_iter()
            .map(|k| k as u64)
            .collect())
    };
    let (band, near) = (bins(BAND)?, bins(TONE_BAND)?);
    let (a, b) = (g.alpha, g.beta);
    let hold = |r: f64, w: f64| Ok(hold_noise_factor(r, w));
    let ab = |r: f64, w: f64| noise_factor(a, b, r, w);
    let factor: &dyn Fn(f64, f64) -> Result<f64, tofprobe_dsp::DspError> = match method {
        Method::Hold => &hold,
        Method::AlphaBeta => &ab,
        Method::Kalman => return Ok(ClosedForms::default()),
    };
    let amp = match method {
        Method::Hold => closed_form_amp_for(spec, &|r, w| Ok(hold_response_sq(r, w)))?,
        _ => closed_form_amp_for(spec, &|r, w| Ok(mean_response(a, b, r, w)?.norm_sqr()))?,
    };
    Ok(ClosedForms {
        floor: Some(closed_form_noise_on_bins_for(spec, n, &band, factor)?),
        amp,
        near: Some(closed_form_noise_on_bins_for(spec, n, &near, factor)?),
    })
}

/// Every scene of [`scenes`] at `n` pulses and `seeds` seeds, with the pixel cost on
/// `cells` (the sky130 liberty's, [`super::imputation_cost::CellAreas`]).
pub fn measure(
    n: u64,
    seeds: usize,
    cells: Option<&super::imputation_cost::CellAreas>,
) -> Result<ImputationReport, ExperimentError> {
    if seeds < 2 {
        return Err(ExperimentError::option(
            "imputation seeds",
            seeds,
            "≥ 2 (a spread needs two)",
        ));
    }
    let scenes = scenes()
        .iter()
        .map(|s| measure_scene(s, n, seeds))
        .collect::<Result<Vec<_>, _>>()?;
    let pixel_cost = match cells {
        Some(c) => {
            let gains: Vec<_> = scenes
                .iter()
                .map(|sc| super::imputation_cost::Gains {
                    rho_s: sc.rho_s,
                    alpha: sc.alpha,
                    beta_per_pulse: sc.beta_per_pulse,
                })
                .collect();
            super::imputation_cost::costs(&gains, c)
        }
        None => Vec::new(),
    };
    Ok(ImputationReport {
        pulses: n,
        seeds,
        scenes,
        pixel_cost,
    })
}

/// The Markdown tables.
pub fn markdown(r: &ImputationReport) -> String {
    let right = |h: &'static str| (h, Align::Right);
    let left = |h: &'static str| (h, Align::Left);
    let mut t = Table::new([
        right("σ_s mm"),
        right("ρ_s"),
        right("ρ_b"),
        left("method"),
        left("noise floor µm (closed form)"),
        left("amplitude µm (closed form)"),
        left("floor at tone µm (closed form)"),
        left("SNR at tone dB"),
        left("vs hold dB (closed form)"),
    ]);
    let cf = |x: Option<f64>| x.map(|v| format!(" ({v:.2})")).unwrap_or_default();
    let ms = |x: &Spread| format!("{:.2} ± {:.2}", x.mean, x.sd);
    for sc in &r.scenes {
        for m in &sc.methods {
            t.row([
                sc.sigma_s_mm.to_string(),
                sc.rho_s.to_string(),
                sc.rho_b.to_string(),
                m.method.to_string(),
                ms(&m.noise_floor_um) + &cf(m.closed_form_noise_floor_um),
                ms(&m.amplitude_um) + &cf(m.closed_form_amplitude_um),
                ms(&m.noise_at_tone_um) + &cf(m.closed_form_noise_at_tone_um),
                ms(&m.snr_at_tone_db),
                format!(
                    "{:+.2} ± {:.2}{}",
                    m.snr_gain_over_hold_db.mean,
                    m.snr_gain_over_hold_db.sd,
                    m.closed_form_snr_gain_over_hold_db
                        .map(|v| format!(" ({v:+.2})"))
                        .unwrap_or_default(),
                ),
            ]);
        }
    }
    let mut s = format!(
        "### Imputation: Kalman and α-β against the 1NN hold (Table 2's scenes, N = {}, {} seeds, mean ± sd)\n\n{t}",
        r.pulses, r.seeds
    );
    s.push_str(
        "\nKalman: σ_w = σ_s, σ_a = A·ω² (the tone's peak acceleration), gate 3 sd; α-β: Kalata's gains at T = 1/ρ_s rounded to powers of two. Without background no imputation gains more than 10·log10(2 − ρ) dB (bound below) over the hold at equal response (tofprobe_dsp::imputation::response); with background the gate also drops outliers the hold keeps, so the gain can exceed it, and the α-β closed form (no gate) sits above the gated floor.\n\n",
    );
    let mut gains = Table::new([
        right("ρ_s"),
        right("σ_w mm"),
        right("σ_a mm/pulse²"),
        right("α"),
        right("β 1/pulse"),
        right("bound dB"),
    ]);
    let mut seen = Vec::new();
    for sc in r.scenes.iter().filter(|sc| {
        let new = !seen.contains(&sc.rho_s);
        seen.push(sc.rho_s);
        new
    }) {
        gains.row([
            sc.rho_s.to_string(),
            sc.measurement_noise_mm.to_string(),
            format!("{:.3e}", sc.process_noise_mm_per_pulse2),
            format!("2^{}", sc.alpha.log2()),
            format!("2^{}", sc.beta_per_pulse.log2()),
            format!(
                "{:.2}",
                tofprobe_dsp::imputation::response::snr_bound_db(sc.rho_s)
            ),
        ]);
    }
    s.push_str(&gains.render());
    s.push_str(&super::imputation_cost::markdown(&r.pixel_cost));
    s
}
