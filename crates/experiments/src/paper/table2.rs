//! Table 2 (1 s, f_s = 10 MHz, Blackman): the DFT noise floor and the measured amplitude
//! of every row, against the paper and the closed form (eq. 12 extended for the hold and
//! the background mixture, `tofprobe_dsp::closed_form`).
//!
//! Per row and per seed of the row's own seeds ([`seeds_for`]): a full record → 1NN hold (raw held depth, no
//! prefilter) → full Blackman FFT → noise floor (mean |Y| over 1–10 kHz, DC and ±8 bins
//! around the tone excluded) and the interpolated peak; the rows show mean ± sd over the
//! seeds and are judged by `super::stats` (tolerance from the spread and the number of
//! band bins). Seed 0 also runs every other column. Every column is a [`Column`]: a function from a row's record to
//! (noise, amplitude) plus, for the probe columns, phasors at the shared probe bins. The
//! float ΣΔ (with and without prefilter) and bit-true columns and their rows are in
//! `super::sigma_delta`; the DFT column also reads its spectrum at those probe bins so the
//! ΣΔ columns are compared with the DFT of the same record on the same bins.

use rayon::prelude::*;
use tofprobe_dsp::Window;
use tofprobe_dsp::dft::{amplitude_scale, amplitude_spectrum, windowed_dft_half};
use tofprobe_dsp::stats::{NoiseBand, interpolate_peak, noise_floor};
use tofprobe_scene::PhotonSource;

use super::chart::Curve;
use super::setup::{FS_HZ, LSB_MM, Setup};
use super::sigma_delta::{self, Phasor, ProbeSetup};
use super::stats::{self, K};
use crate::ExperimentError;

mod closed_form;
mod rows;
pub use closed_form::{band_bins, closed_form_amp_um, closed_form_noise_um};
pub use rows::{AMP_MIN_SNR, amplitude_row, eq12_row, noise_row, rows_of};

/// The analysis window of Table 2.
pub const WINDOW: Window = Window::Blackman;
/// The noise band (Hz).
pub const BAND: (f64, f64) = (1_000.0, 10_000.0);
/// The tone frequency of the amplitude rows.
pub const F0_HZ: f64 = 4_500.0;
/// The seeds of a row not in [`ROWS`] (tests' own specs), and the count every row has at
/// least: noise floor and amplitude are means over a row's seeds ([`seeds_for`]).
pub const SEEDS: &[u64] = stats::SEEDS;
/// The amplitude bias a full-length tested amplitude row must catch (µm): its seed count
/// makes K·se ≤ this ([`seeds_for`]).
pub const AMP_BIAS_UM: f64 = 10.0;
/// The most seeds a row gets (a full record costs ≈ 1 s of CPU per seed).
pub const MAX_SEEDS: usize = 64;
/// Record length from which rows get their powered seed counts (shorter `--quick`
/// records keep [`SEEDS`]'s count: their floors are too high for a 10 µm test anyway).
pub const FULL_N: u64 = 10_000_000;
/// The float ΣΔ column runs on this many of a row's seeds (its rows compare ΣΔ with the
/// DFT of the same records, a paired difference that needs no more).
pub const SD_SEEDS: usize = 5;

/// A row's own seeds: rows share none (row i of [`ROWS`] draws from 1000·(i + 1) on, so
/// their statistics are independent), and a tested amplitude row of a full record has
/// enough that a [`AMP_BIAS_UM`] bias fails its K·se test: S = ⌈(K·sd/bias)²⌉ with sd the
/// predicted sd of one seed's amplitude, floor·sqrt(2/π) (`amplitude_row`), between
/// [`SEEDS`]'s count and [`MAX_SEEDS`]. A spec outside [`ROWS`] gets [`SEEDS`].
pub fn seeds_for(spec: &Spec, n: u64) -> Result<Vec<u64>, ExperimentError> {
    let Some(i) = ROWS.iter().position(|r| r == spec) else {
        return Ok(SEEDS.to_vec());
    };
    let mut count = SEEDS.len();
    if n >= FULL_N
        && let Some(amp) = closed_form_amp_um(spec)?
    {
        let floor = closed_form_noise_um(spec, n as usize)?;
        if amp / floor >= AMP_MIN_SNR {
            let sd = floor * (2.0 / std::f64::consts::PI).sqrt();
            let want = (K * sd / AMP_BIAS_UM).powi(2).ceil() as usize;
            count = want.clamp(SEEDS.len(), MAX_SEEDS);
        }
    }
    let base = 1000 * (i as u64 + 1);
    Ok((base..base + count as u64).collect())
}
/// Relative tolerance of the noise rows.
pub const NOISE_REL: f64 = 0.05;

/// One row of Table 2 as printed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    pub sigma_s_mm: f64,
    pub rho_s: f64,
    pub rho_b: f64,
    /// Tone amplitude (µm) at [`F0_HZ`], or none.
    pub amp_um: Option<f64>,
    /// The paper's DFT noise floor (µm).
    pub paper_noise_um: f64,
    /// The paper's DFT measured amplitude (µm).
    pub paper_amp_um: Option<f64>,
    /// The paper's ΣΔ noise floor (µm), where it prints one.
    pub paper_sd_noise_um: Option<f64>,
}

const fn row(s: f64, rs: f64, rb: f64, a: f64, noise: f64, meas: f64) -> Spec {
    Spec {
        sigma_s_mm: s,
        rho_s: rs,
        rho_b: rb,
        amp_um: if a > 0.0 { Some(a) } else { None },
        paper_noise_um: noise,
        paper_amp_um: if a > 0.0 { Some(meas) } else { None },
        paper_sd_noise_um: None,
    }
}

/// A row whose ΣΔ noise the paper prints beside the DFT one.
const fn row_sd(s: f64, noise: f64, sd: f64) -> Spec {
    let mut r = row(s, 1.0, 0.0, 0.0, noise, 0.0);
    r.paper_sd_noise_um = Some(sd);
    r
}

/// Every DFT row of Table 2 (DESIGN.md, "Numbers to reproduce").
pub const ROWS: &[Spec] = &[
    row_sd(3.0, 2.25, 2.26),
    row_sd(7.5, 5.47, 5.49),
    row_sd(15.0, 10.85, 10.88),
    row_sd(30.0, 22.24, 22.32),
    row(3.0, 1.0, 0.0, 10.0, 2.26, 8.27),
    row(3.0, 1.0, 0.0, 30.0, 2.23, 30.49),
    row(3.0, 1.0, 0.0, 100.0, 2.19, 97.65),
    row(3.0, 1.0, 0.0, 300.0, 2.23, 298.34),
    row(7.5, 1.0, 0.0, 100.0, 5.52, 102.3),
    row(7.5, 0.3, 0.0, 100.0, 13.11, 102.2),
    row(7.5, 0.1, 0.0, 100.0, 23.57, 114.8),
    row(7.5, 0.03, 0.0, 100.0, 44.42, 131.3),
    row(7.5, 0.3, 0.01, 100.0, 13.95, 99.6),
    row(7.5, 0.3, 0.025, 100.0, 14.59, 95.7),
    row(7.5, 0.3, 0.05, 100.0, 15.29, 92.6),
    row(7.5, 0.3, 0.075, 100.0, 16.12, 88.8),
    row(7.5, 0.3, 0.1, 100.0, 16.33, 98.3),
    row(7.5, 0.3, 0.3, 100.0, 16.93, 55.1),
];

impl Spec {
    pub fn setup(&self) -> Setup {
        Setup {
            sigma_s_mm: self.sigma_s_mm,
            lsb_mm: LSB_MM,
            rho_s: self.rho_s,
            rho_b: self.rho_b,
            window_mm: Setup::window_for(self.sigma_s_mm, self.rho_b),
            tone: self.amp_um.map(|a| (F0_HZ, a * 1e-3)),
        }
    }

    pub fn label(&self) -> String {
        let tone = self
            .amp_um
            .map_or_else(|| "no tone".into(), |a| format!("A={a} µm@{F0_HZ} Hz"));
        format!(
            "σ_s={} mm ρ_s={} ρ_b={} {tone}",
            self.sigma_s_mm, self.rho_s, self.rho_b
        )
    }
}

/// What a column measures on one record: noise floor and (tone rows) amplitude, µm.
/// Columns that read the shared probe bins also return their phasors there (tone bin
/// first, mm) so that the table can compare columns bin by bin on the same record.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub noise_um: f64,
    pub amp_um: Option<f64>,
    /// Phasors at the probe bins of [`ProbeSetup`] (mm), empty if not measured.
    pub phasors: Vec<Phasor>,
    /// Bit-true column: its check against the float ΣΔ.
    pub bit_true: Option<sigma_delta::BitTrue>,
}

/// The data a column sees: the row, its source, the detections of the whole record, and
/// the probe ROM shared by all rows of the same N (built once by the caller; `None` when
/// only the DFT column runs).
#[derive(Debug)]
pub struct RowRecord<'a> {
    pub spec: &'a Spec,
    pub source: &'a PhotonSource,
    pub detections: &'a [Option<u32>],
    pub probe: Option<&'a ProbeSetup>,
}

impl RowRecord<'_> {
    /// The shared probe ROM the ΣΔ columns read.
    fn probe(&self) -> Result<&ProbeSetup, ExperimentError> {
        self.probe.ok_or_else(|| {
            ExperimentError::option(
                "columns",
                "ΣΔ",
                "the DFT column alone without a ProbeSetup (run_all_with(n, None, …))",
            )
        })
    }
}

/// A column of the table: a name, the fidelity level it measures at and a function from a
/// row's record to a measurement (`None`: the column does not apply to this row).
#[derive(Debug, Clone, Copy)]
pub struct Column {
    pub name: &'static str,
    /// The level of the registry ([`crate::level`]) this column reads.
    pub level: crate::level::Level,
    pub measure: fn(&RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError>,
}

/// Column names.
pub const DFT: &str = "DFT";
pub const SD: &str = "ΣΔ";
/// The float ΣΔ level read without dividing the prefilter's gain out (the paper's point
/// that the correction is needed).
pub const SD_RAW: &str = "ΣΔ no prefilter";
pub const BIT_TRUE: &str = "bit-true";

/// The columns measured from seed 0 of every row.
pub const COLUMNS: &[Column] = &[
    Column {
        name: DFT,
        level: crate::level::Level::FullDft,
        measure: dft_column,
    },
    Column {
        name: SD,
        level: crate::level::Level::FloatSd,
        measure: sd_column,
    },
    Column {
        name: SD_RAW,
        level: crate::level::Level::FloatSd,
        measure: sd_raw_column,
    },
    Column {
        name: BIT_TRUE,
        level: crate::level::Level::BitTrue,
        measure: bit_true_column,
    },
];

/// Bin of the tone in an N-point record.
fn tone_bin(n: usize) -> usize {
    (F0_HZ * n as f64 / FS_HZ).round() as usize
}

/// The held depth of a whole record (mm, from the window start), unprimed pulses 0.
pub fn held_record(rec: &RowRecord<'_>) -> Result<Vec<f64>, ExperimentError> {
    crate::records::held_record(rec.source, rec.detections, 0.0)
}

/// The full-FFT column: noise floor over the band, peak by quadratic interpolation, and
/// the normalised complex bins 2/(N·G)·X[k] at the probe bins.
pub fn dft_column(rec: &RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError> {
    let held = held_record(rec)?;
    let n = held.len();
    let half = windowed_dft_half(&held, WINDOW)?;
    drop(held);
    let phasors = sigma_delta::probe_bins(n as u64)
        .iter()
        .map(|&k| {
            let y = half[k as usize] * amplitude_scale(k as usize, n, WINDOW);
            [y.re, y.im]
        })
        .collect();
    let spectrum: Vec<f64> = half
        .iter()
        .enumerate()
        .map(|(k, c)| c.norm() * amplitude_scale(k, n, WINDOW))
        .collect();
    drop(half);
    let mut m = measure_spectrum(&spectrum, n, rec.spec.amp_um.is_some())?;
    m.phasors = phasors;
    Ok(Some(m))
}

/// Measurement of a probe readout: noise = mean magnitude of the noise bins, amplitude =
/// magnitude of the tone bin (tone rows).
fn probe_measurement(rec: &RowRecord<'_>, phasors: Vec<Phasor>) -> Measurement {
    Measurement {
        noise_um: sigma_delta::noise_um(&phasors),
        amp_um: rec.spec.amp_um.map(|_| sigma_delta::norm(phasors[0]) * 1e3),
        phasors,
        bit_true: None,
    }
}

/// Float ΣΔ probing of the record's detections by the pixel's rules — the one float front
/// end's hold, priming and prefilter (α = 2^−S), or the hold alone with `alpha = None` —
/// the pixel's float twin, zoomed to the static depth δ0 (the pixel's zoom Z): the
/// priming pulse adds nothing, so an unzoomed 30 mm offset would leave s_r(0)·δ0 in every
/// register, ≈ 14 µm at 150 kHz for N = 2^16 (negligible at 10^7, but not the DFT's).
fn sd_probe(rec: &RowRecord<'_>, alpha: Option<f64>) -> Result<Measurement, ExperimentError> {
    let probe = rec.probe()?;
    let zoom = rec.spec.setup().depth_mm();
    let depths = rec
        .detections
        .iter()
        .map(|d| d.map(|c| rec.source.code_to_depth_mm(c) - zoom));
    let sums = tofprobe_dsp::sd::probe_detections(&probe.rom, depths, alpha);
    Ok(probe_measurement(rec, probe.phasors(&sums, alpha)))
}

/// The float ΣΔ column: the held record prefiltered (α = 1/32) and probed by the ROM.
pub fn sd_column(rec: &RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError> {
    sd_probe(rec, Some(sigma_delta::alpha())).map(Some)
}

/// The float ΣΔ column without the prefilter: the paper's observation that its error is
/// several times the floor. Run on the ρ_s = 1, ρ_b = 0 rows only (the setting of the
/// paper's remark; it costs a full probing pass per row).
pub fn sd_raw_column(rec: &RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError> {
    if rec.spec.rho_s < 1.0 || rec.spec.rho_b > 0.0 {
        return Ok(None);
    }
    sd_probe(rec, None).map(Some)
}

/// The bit-true column: the record's TDC codes through the transaction model.
pub fn bit_true_column(rec: &RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError> {
    let codes = (rec.spec.setup().window_mm / LSB_MM).ceil() as u32;
    let probe = rec.probe()?;
    let bt = sigma_delta::bit_true(probe, rec.detections, codes)?;
    // Codes are 1 mm (LSB_MM), so the phasors are already in mm.
    let mut m = probe_measurement(
        rec,
        bt.phasors.iter().map(|p| p.map(|v| v * LSB_MM)).collect(),
    );
    m.bit_true = Some(bt);
    Ok(Some(m))
}

/// Noise floor and amplitude of a one-sided amplitude spectrum (mm) → µm.
pub fn measure_spectrum(
    spectrum: &[f64],
    n: usize,
    tone: bool,
) -> Result<Measurement, ExperimentError> {
    let k0 = tone_bin(n);
    let tones: Vec<f64> = if tone { vec![k0 as f64] } else { vec![] };
    let noise = noise_floor(spectrum, n, FS_HZ, &NoiseBand::new(BAND.0, BAND.1), &tones)?;
    let amp = if tone {
        Some(interpolate_peak(spectrum, k0, 2)?.amplitude * 1e3)
    } else {
        None
    };
    Ok(Measurement {
        noise_um: noise * 1e3,
        amp_um: amp,
        phasors: Vec::new(),
        bit_true: None,
    })
}

/// One seed's record: the DFT column's noise floor and amplitude (µm) and, when the ΣΔ
/// column runs (`probe_sd`), the DFT and float-ΣΔ measurements at the shared probe bins.
fn seed_measurement(
    spec: &Spec,
    n: u64,
    seed: u64,
    probe_sd: Option<&ProbeSetup>,
) -> Result<(Measurement, Option<Measurement>), ExperimentError> {
    let source = spec.setup().source(seed)?;
    let detections = source.record(n);
    if let Some(probe) = probe_sd {
        let rec = RowRecord {
            spec,
            source: &source,
            detections: &detections,
            probe: Some(probe),
        };
        let dft =
            dft_column(&rec)?.ok_or_else(|| ExperimentError::option("columns", DFT, "DFT"))?;
        let sd = sd_column(&rec)?;
        return Ok((dft, sd));
    }
    let held = crate::records::held_record(&source, &detections, 0.0)?;
    drop(detections);
    let spectrum = amplitude_spectrum(&held, WINDOW)?;
    drop(held);
    Ok((
        measure_spectrum(&spectrum, n as usize, spec.amp_um.is_some())?,
        None,
    ))
}

/// Everything measured for one row.
#[derive(Debug, Clone)]
pub struct RowResult {
    pub spec: Spec,
    /// Per column, the seed-0 measurement.
    pub columns: Vec<(&'static str, Measurement)>,
    /// The row's seeds ([`seeds_for`]).
    pub seeds: Vec<u64>,
    /// DFT noise floors of all seeds (`seeds` order), µm.
    pub noises_um: Vec<f64>,
    /// Band bins the floor averages.
    pub band_bins: usize,
    /// Amplitudes of all seeds (DFT), µm.
    pub amps_um: Vec<f64>,
    pub closed_form_um: f64,
    /// Closed-form expected amplitude g·|H(ρ_v, ω0)|·A (µm), tone rows.
    pub amp_closed_um: Option<f64>,
    /// Seed-0 spectrum, decimated for plotting: the mean |Y| of each log-spaced group of
    /// bins (Hz, µm) — the level a reader reads as the spectrum.
    pub spectrum: Vec<(f64, f64)>,
    /// The same groups' largest bin (Hz, µm): where a tone is, its height.
    pub spectrum_max: Vec<(f64, f64)>,
    /// Per seed of the first [`SD_SEEDS`] of `seeds` (when the ΣΔ column ran): the DFT and the float ΣΔ (with the
    /// prefilter) of that seed's record at the shared probe bins.
    pub probe_seeds: Vec<(Measurement, Measurement)>,
}

/// Runs one row with the given columns ([`COLUMNS`] for the full table; the first must be
/// the DFT column, which the seed statistics use): seed 0 in full, the other seeds of
/// the row's seeds ([`seeds_for`]) through the DFT column (noise floor and amplitude) and, if the ΣΔ column is
/// among `columns_to_run`, the float ΣΔ column too (the ΣΔ rows are means over the seeds;
/// the unprefiltered and bit-true columns stay seed 0). `bench dsp` times the DFT rows
/// alone this way.
pub fn run_row_with(
    spec: &Spec,
    n: u64,
    probe: Option<&ProbeSetup>,
    columns_to_run: &[Column],
) -> Result<RowResult, ExperimentError> {
    let setup = spec.setup();
    let seeds = seeds_for(spec, n)?;
    let source = setup.source(seeds[0])?;
    let detections = source.record(n);
    let rec = RowRecord {
        spec,
        source: &source,
        detections: &detections,
        probe,
    };
    let mut columns = Vec::new();
    for c in columns_to_run {
        if let Some(m) = (c.measure)(&rec)? {
            columns.push((c.name, m));
        }
    }
    // The seed-0 spectrum again for the plot (cheap next to the Monte Carlo; keeps
    // the column functions pure).
    let held = held_record(&rec)?;
    drop(detections);
    let spectrum = amplitude_spectrum(&held, WINDOW)?;
    drop(held);
    let (plot, plot_max) = decimate(&spectrum, n as usize);
    let probe_sd = probe.filter(|_| columns_to_run.iter().any(|c| c.name == SD));
    let rest: Result<Vec<(Measurement, Option<Measurement>)>, ExperimentError> = seeds[1..]
        .par_iter()
        .enumerate()
        .map(|(i, &s)| seed_measurement(spec, n, s, probe_sd.filter(|_| i + 1 < SD_SEEDS)))
        .collect();
    let rest = rest?;
    let seed_ms: Vec<&Measurement> = std::iter::once(&columns[0].1)
        .chain(rest.iter().map(|r| &r.0))
        .collect();
    let seed0_sd = columns.iter().find(|(c, _)| *c == SD).map(|(_, m)| m);
    let probe_seeds: Vec<(Measurement, Measurement)> = match seed0_sd {
        Some(sd0) if probe_sd.is_some() => std::iter::once((columns[0].1.clone(), sd0.clone()))
            .chain(
                rest.iter()
                    .filter_map(|(d, sd)| sd.as_ref().map(|sd| (d.clone(), sd.clone()))),
            )
            .collect(),
        _ => Vec::new(),
    };
    let noises_um: Vec<f64> = seed_ms.iter().map(|m| m.noise_um).collect();
    let amps_um: Vec<f64> = seed_ms.iter().filter_map(|m| m.amp_um).collect();
    Ok(RowResult {
        spec: *spec,
        seeds,
        columns,
        noises_um,
        band_bins: band_bins(spec, n as usize)?,
        amps_um,
        closed_form_um: closed_form_noise_um(spec, n as usize)?,
        amp_closed_um: closed_form_amp_um(spec)?,
        spectrum: plot,
        spectrum_max: plot_max,
        probe_seeds,
    })
}

/// The spectrum up to 50 kHz in log-spaced groups of bins (2 % wide, ~400 points for an
/// SVG plot), µm: each group's mean |Y| at its first bin's frequency, and its largest bin.
/// The mean is the spectrum's level (a group of M bins of a flat floor averages to the
/// floor); the maximum of M Rayleigh bins grows like sqrt(ln M) and drew a flat 5.5 µm
/// floor rising to 16.7 µm, so it is kept for the tone's height only.
pub fn decimate(spectrum: &[f64], n: usize) -> (Curve, Curve) {
    let df = FS_HZ / n as f64;
    let kmax = ((50_000.0 / df) as usize).min(spectrum.len().saturating_sub(1));
    let (mut mean, mut max) = (Vec::new(), Vec::new());
    let mut k = 1usize;
    while k <= kmax {
        let next = ((k as f64 * 1.02).ceil() as usize).max(k + 1).min(kmax + 1);
        let group = &spectrum[k..next];
        let m = group.iter().sum::<f64>() / group.len() as f64;
        mean.push((k as f64 * df, m * 1e3));
        max.push((
            k as f64 * df,
            group.iter().copied().fold(0.0, f64::max) * 1e3,
        ));
        k = next;
    }
    (mean, max)
}

/// Runs every row (rayon across rows), all sharing the probe ROM `probe` (N = `probe.n`).
pub fn run_all(probe: &ProbeSetup) -> Result<Vec<RowResult>, ExperimentError> {
    run_all_with(probe.n, Some(probe), COLUMNS)
}

/// [`run_all`] with a chosen set of columns (see [`run_row_with`]); the ΣΔ columns need
/// `probe`, built for N = `n`.
pub fn run_all_with(
    n: u64,
    probe: Option<&ProbeSetup>,
    columns: &[Column],
) -> Result<Vec<RowResult>, ExperimentError> {
    ROWS.par_iter()
        .map(|s| run_row_with(s, n, probe, columns))
        .collect()
}

#[cfg(test)]
mod tests;
