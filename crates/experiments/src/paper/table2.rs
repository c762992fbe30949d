//! Table 2 (1 s, f_s = 10 MHz, Blackman): every printed value — the DFT and two-level ΣΔ
//! noise floor, measured amplitude and SNR — re-measured, each row beside the paper's value
//! (`data/paper/table2.tsv`, [`printed`]) and judged against the closed form (eq. 12
//! extended for the hold and the background mixture, `tofprobe_dsp::closed_form`).
//!
//! Three columns, each on its own records ([`spec::seeds_for_set`]): the DFT (a full record
//! → 1NN hold (raw held depth, no prefilter) → full Blackman FFT → noise floor = mean |Y|
//! over 1–10 kHz with DC and ±8 bins around the tone excluded, and "A meas." = the
//! interpolated peak: the tone, or on a row without one the spectrum's largest value over
//! [`PEAK_BAND`]); the float ΣΔ and the bit-true pixel (`super::sigma_delta`: the same
//! kind of record probed at the shared probe bins, each record also read by the DFT on
//! those bins — the same-record reference). The rows show mean ± sd over a column's seeds
//! and are judged by `super::stats` (tolerance from the spread). Every column is a
//! [`Column`]: a function from a record to a [`Measurement`].

use rayon::prelude::*;
use tofprobe_dsp::Window;
use tofprobe_dsp::dft::{amplitude_scale, amplitude_spectrum, windowed_dft_half};
use tofprobe_dsp::stats::{NoiseBand, interpolate_peak, noise_floor};
use tofprobe_scene::PhotonSource;

use super::chart::Curve;
pub use super::setup::{BAND, F0_HZ};
use super::setup::{FS_HZ, LSB_MM};
use super::sigma_delta::{self, Phasor, ProbeSetup};
use super::stats;
use crate::ExperimentError;

mod closed_form;
pub mod printed;
mod probe_runs;
mod rows;
mod spec;
pub use closed_form::{
    band_bins, closed_form_amp_for, closed_form_amp_um, closed_form_noise_on_bins_for,
    closed_form_noise_on_bins_um, closed_form_noise_um, largest_bin_um, peak_band_bins,
    snr_closed_db,
};
pub use probe_runs::{ProbeRecord, ProbeRun};
pub use rows::{
    amplitude_row, eq12_row, largest_value_row, noise_row, paper_note, rms_over_mean_db, rows_of,
    snr_row,
};
pub use spec::{
    AMP_BIAS_UM, AMP_MIN_SNR, FULL_N, MAX_SEEDS, NOISE_BIAS, PROBE_EPS2_MAX, ROWS, SeedSet,
    probe_noise_seeds, seeds_for, seeds_for_set,
};

/// One row of Table 2: its configuration and what the paper prints for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    pub sigma_s_mm: f64,
    pub rho_s: f64,
    pub rho_b: f64,
    /// Tone amplitude (µm) at [`F0_HZ`], or none.
    pub amp_um: Option<f64>,
    /// The paper's values (`data/paper/table2.tsv`).
    pub printed: printed::Printed,
}

/// The analysis window of Table 2.
pub const WINDOW: Window = Window::Blackman;
/// Where a row without a tone reads its "A meas." (the spectrum's largest value, Hz): the
/// paper truncates its spectra at 20 kHz; from the noise band's lower edge, where a static
/// depth's leakage through the Blackman sidelobes is gone.
pub const PEAK_BAND: (f64, f64) = (BAND.0, 20_000.0);
/// The spectrum's largest bins a row without a tone hands to the probe columns (largest
/// first): the probe reads them and their neighbours to find its own largest value.
pub const TOP_BINS: usize = 16;
/// The seeds of a row not in [`ROWS`] (tests' own specs), and the count every row has at
/// least: noise floor and amplitude are means over a row's seeds ([`seeds_for`]).
pub const SEEDS: &[u64] = stats::SEEDS;
/// Relative tolerance of the eq. 12 row.
pub const NOISE_REL: f64 = 0.05;

/// What a column measures on one record: noise floor and "A meas." (µm). Columns that read
/// the shared probe bins also return their phasors there (tone bin first, mm) so that the
/// table can compare columns bin by bin on the same record.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub noise_um: f64,
    /// "A meas.": the tone's amplitude, or on a row without a tone the spectrum's largest
    /// value over [`PEAK_BAND`] (the paper's definition for both).
    pub amp_um: Option<f64>,
    /// Phasors at the probe bins of [`ProbeSetup`] (mm), empty if not measured.
    pub phasors: Vec<Phasor>,
    /// Bit-true column: its check against the float ΣΔ.
    pub bit_true: Option<sigma_delta::BitTrue>,
    /// A row without a tone, DFT: the [`TOP_BINS`] largest bins over [`PEAK_BAND`].
    pub top_bins: Vec<u64>,
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

/// The columns of the table (the first is the DFT, which the row's seed statistics use).
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
pub fn tone_bin(n: usize) -> usize {
    (F0_HZ * n as f64 / FS_HZ).round() as usize
}

/// The held depth of a whole record (mm, from the window start), unprimed pulses 0.
pub fn held_record(rec: &RowRecord<'_>) -> Result<Vec<f64>, ExperimentError> {
    crate::records::held_record(rec.source, rec.detections, 0.0)
}

/// The full-FFT column: noise floor over the band, "A meas." by quadratic interpolation,
/// and the normalised complex bins 2/(N·G)·X\[k\] at the probe bins.
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
/// magnitude of the tone bin (tone rows; a row without one reads its largest value
/// separately, `probe_runs`).
fn probe_measurement(rec: &RowRecord<'_>, phasors: Vec<Phasor>) -> Measurement {
    Measurement {
        noise_um: sigma_delta::noise_um(&phasors),
        amp_um: rec.spec.amp_um.map(|_| sigma_delta::norm(phasors[0]) * 1e3),
        phasors,
        bit_true: None,
        top_bins: Vec::new(),
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

/// The TDC codes a row's records hold (0..codes).
fn codes_of(spec: &Spec) -> u32 {
    (spec.setup().window_mm / LSB_MM).ceil() as u32
}

/// The bit-true column: the record's TDC codes through the transaction model, checked
/// register by register against the float ΣΔ on the same codes.
pub fn bit_true_column(rec: &RowRecord<'_>) -> Result<Option<Measurement>, ExperimentError> {
    let probe = rec.probe()?;
    let bt = sigma_delta::bit_true(probe, rec.detections, codes_of(rec.spec))?;
    // Codes are 1 mm (LSB_MM), so the phasors are already in mm.
    let mut m = probe_measurement(
        rec,
        bt.phasors.iter().map(|p| p.map(|v| v * LSB_MM)).collect(),
    );
    m.bit_true = Some(bt);
    Ok(Some(m))
}

/// The bit-true pixel's readout of the record without the float check (the rows' other
/// seeds: the check's bound holds per register whatever the record, and the first seed
/// runs it).
pub fn bit_true_readout(rec: &RowRecord<'_>) -> Result<Measurement, ExperimentError> {
    let probe = rec.probe()?;
    let phasors = sigma_delta::bit_true_phasors(probe, rec.detections, codes_of(rec.spec))?;
    Ok(probe_measurement(
        rec,
        phasors.iter().map(|p| p.map(|v| v * LSB_MM)).collect(),
    ))
}

/// Noise floor and "A meas." of a one-sided amplitude spectrum (mm) → µm: the tone's
/// interpolated peak, or without a tone the largest bin over [`PEAK_BAND`] interpolated the
/// same way (with the [`TOP_BINS`] largest bins kept for the probe columns).
pub fn measure_spectrum(
    spectrum: &[f64],
    n: usize,
    tone: bool,
) -> Result<Measurement, ExperimentError> {
    let k0 = tone_bin(n);
    let tones: Vec<f64> = if tone { vec![k0 as f64] } else { vec![] };
    let noise = noise_floor(spectrum, n, FS_HZ, &NoiseBand::new(BAND.0, BAND.1), &tones)?;
    let (amp, top_bins) = if tone {
        (interpolate_peak(spectrum, k0, 2)?.amplitude, Vec::new())
    } else {
        let top = largest_bins(spectrum, n, TOP_BINS);
        let k = *top.first().ok_or_else(|| {
            ExperimentError::option("pulses", n, "a record whose bins reach 1–20 kHz")
        })?;
        (interpolate_peak(spectrum, k as usize, 0)?.amplitude, top)
    };
    Ok(Measurement {
        noise_um: noise * 1e3,
        amp_um: Some(amp * 1e3),
        phasors: Vec::new(),
        bit_true: None,
        top_bins,
    })
}

/// The `count` largest bins of `spectrum` over [`PEAK_BAND`], largest first (bins whose
/// both neighbours exist).
pub fn largest_bins(spectrum: &[f64], n: usize, count: usize) -> Vec<u64> {
    let df = FS_HZ / n as f64;
    let lo = ((PEAK_BAND.0 / df).ceil() as usize).max(1);
    let hi = ((PEAK_BAND.1 / df).floor() as usize).min(spectrum.len().saturating_sub(2));
    let mut bins: Vec<usize> = (lo..=hi).collect();
    bins.sort_by(|&a, &b| spectrum[b].total_cmp(&spectrum[a]));
    bins.into_iter().take(count).map(|k| k as u64).collect()
}

/// Everything measured for one row.
#[derive(Debug, Clone)]
pub struct RowResult {
    pub spec: Spec,
    /// Pulses of every record of the row (N).
    pub pulses: u64,
    /// The DFT column's seed-0 measurement (phasors at the probe bins included).
    pub dft0: Measurement,
    /// The DFT column's seeds ([`seeds_for`]).
    pub seeds: Vec<u64>,
    /// DFT noise floors of all seeds (`seeds` order), µm.
    pub noises_um: Vec<f64>,
    /// Band bins the floor averages.
    pub band_bins: usize,
    /// DFT "A meas." of all seeds (the tone, or the largest value without one), µm.
    pub amps_um: Vec<f64>,
    pub closed_form_um: f64,
    /// Closed-form expected amplitude g·|H(ρ_v, ω0)|·A (µm), tone rows.
    pub amp_closed_um: Option<f64>,
    /// Seed-0 spectrum, decimated for plotting: the mean |Y| of each log-spaced group of
    /// bins (Hz, µm) — the level a reader reads as the spectrum.
    pub spectrum: Vec<(f64, f64)>,
    /// The same groups' largest bin (Hz, µm): where a tone is, its height.
    pub spectrum_max: Vec<(f64, f64)>,
    /// The probe columns that ran (float ΣΔ, bit-true), each on its own seeds.
    pub probes: Vec<ProbeRun>,
}

impl RowResult {
    /// The probe column `name` ([`SD`], [`BIT_TRUE`]), if it ran.
    pub fn probe(&self, name: &str) -> Option<&ProbeRun> {
        self.probes.iter().find(|p| p.column == name)
    }
}

/// One DFT seed's noise floor and "A meas." (µm).
fn dft_seed(spec: &Spec, n: u64, seed: u64) -> Result<Measurement, ExperimentError> {
    let source = spec.setup().source(seed)?;
    let detections = source.record(n);
    let held = crate::records::held_record(&source, &detections, 0.0)?;
    drop(detections);
    let spectrum = amplitude_spectrum(&held, WINDOW)?;
    drop(held);
    measure_spectrum(&spectrum, n as usize, spec.amp_um.is_some())
}

/// Runs one row with the given columns ([`COLUMNS`] for the full table; the first must be
/// the DFT column, which the seed statistics use): the DFT column on its seeds
/// ([`seeds_for`]; seed 0 in full, with the plotted spectrum), then each probe column
/// among `columns_to_run` (ΣΔ, bit-true; they need `probe`) on its own seeds
/// (`probe_runs`). `bench dsp` times the DFT rows alone this way.
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
    let dft0 = dft_column(&rec)?.ok_or_else(|| ExperimentError::option("columns", DFT, DFT))?;
    // The seed-0 spectrum again for the plot (cheap next to the Monte Carlo; keeps
    // the column functions pure).
    let held = held_record(&rec)?;
    drop(detections);
    let spectrum = amplitude_spectrum(&held, WINDOW)?;
    drop(held);
    let (plot, plot_max) = decimate(&spectrum, n as usize);
    drop(spectrum);
    let rest: Result<Vec<Measurement>, ExperimentError> = seeds[1..]
        .par_iter()
        .map(|&s| dft_seed(spec, n, s))
        .collect();
    let rest = rest?;
    let seed_ms: Vec<&Measurement> = std::iter::once(&dft0).chain(rest.iter()).collect();
    let noises_um: Vec<f64> = seed_ms.iter().map(|m| m.noise_um).collect();
    let amps_um: Vec<f64> = seed_ms.iter().filter_map(|m| m.amp_um).collect();
    let mut probes = Vec::new();
    if let Some(probe) = probe {
        let has = |name: &str| columns_to_run.iter().any(|c| c.name == name);
        if has(SD) {
            probes.push(ProbeRun::float_sd(spec, n, probe, has(SD_RAW))?);
        }
        if has(BIT_TRUE) {
            probes.push(ProbeRun::bit_true(spec, n, probe)?);
        }
    }
    Ok(RowResult {
        spec: *spec,
        pulses: n,
        dft0,
        seeds,
        noises_um,
        band_bins: band_bins(spec, n as usize)?,
        amps_um,
        closed_form_um: closed_form_noise_um(spec, n as usize)?,
        amp_closed_um: closed_form_amp_um(spec)?,
        spectrum: plot,
        spectrum_max: plot_max,
        probes,
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
