//! The probe columns of a Table 2 row — the float ΣΔ and the bit-true pixel — each on its
//! own seeds ([`SeedSet`]): every record is probed at the shared probe bins and read by the
//! DFT on the same bins (the same-record reference), and on a row without a tone both read
//! their largest value ("A meas.") too. The first record of a column also runs its one-off
//! check: the ΣΔ without the prefilter (ρ_s = 1 rows), the bit-true registers against the
//! float ΣΔ on the same codes.

use rayon::prelude::*;
use tofprobe_dsp::preprocess::{FrontEnd, FrontEndOutput};
use tofprobe_dsp::sd::{FullBandProber, Isa, LanePrecision};
use tofprobe_dsp::stats::interpolate_peak;

use super::super::sigma_delta::{self, BitTrue, ProbeSetup};
use super::{
    BIT_TRUE, Measurement, RowRecord, SD, SeedSet, Spec, bit_true_column, bit_true_readout,
    dft_column, sd_column, sd_raw_column, seeds_for_set,
};
use crate::ExperimentError;

/// One record of a probe column.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeRecord {
    pub seed: u64,
    /// The probe's readout: noise on the probe's noise bins, "A meas." (the tone bin, or
    /// the largest value of a row without a tone; none for the bit-true pixel there: its
    /// registers hold only the probe bins).
    pub probe: Measurement,
    /// The same record read by the DFT: its phasors on the probe bins, the noise on the
    /// same bins, and "A meas." read the probe's way (the tone bin's magnitude, or the
    /// spectrum's largest value over `PEAK_BAND`).
    pub dft: Measurement,
}

/// One probe column of a row over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeRun {
    /// [`SD`] or [`BIT_TRUE`].
    pub column: &'static str,
    pub seeds: Vec<u64>,
    /// Per seed (`seeds` order).
    pub records: Vec<ProbeRecord>,
    /// ΣΔ: the first record probed without the prefilter (ρ_s = 1, ρ_b = 0 rows).
    pub raw: Option<Measurement>,
    /// Bit-true: the first record's registers against the float ΣΔ on the same codes.
    pub check: Option<BitTrue>,
}

impl ProbeRun {
    /// The float ΣΔ column over its seeds; `raw`: probe the first record without the
    /// prefilter too (where `sd_raw_column` applies).
    pub fn float_sd(
        spec: &Spec,
        n: u64,
        probe: &ProbeSetup,
        raw: bool,
    ) -> Result<ProbeRun, ExperimentError> {
        let seeds = seeds_for_set(spec, n, SeedSet::FloatSd)?;
        let runs: Result<Vec<(ProbeRecord, Option<Measurement>)>, ExperimentError> = seeds
            .par_iter()
            .enumerate()
            .map(|(i, &seed)| {
                with_record(spec, n, seed, probe, |rec, dft| {
                    let mut sd = sd_column(rec)?.ok_or_else(|| column_error(SD))?;
                    if spec.amp_um.is_none() {
                        sd.amp_um = Some(sd_largest_um(rec, probe, &dft.top_bins)?);
                    }
                    let raw = if raw && i == 0 {
                        sd_raw_column(rec)?
                    } else {
                        None
                    };
                    Ok((sd, raw))
                })
                .map(|((sd, raw), dft)| {
                    (
                        ProbeRecord {
                            seed,
                            probe: sd,
                            dft,
                        },
                        raw,
                    )
                })
            })
            .collect();
        let mut runs = runs?;
        let raw = runs.first_mut().and_then(|r| r.1.take());
        Ok(ProbeRun {
            column: SD,
            seeds,
            records: runs.into_iter().map(|r| r.0).collect(),
            raw,
            check: None,
        })
    }

    /// The bit-true column over its seeds; the first record's registers are checked
    /// against the float ΣΔ on the same codes.
    pub fn bit_true(spec: &Spec, n: u64, probe: &ProbeSetup) -> Result<ProbeRun, ExperimentError> {
        let seeds = seeds_for_set(spec, n, SeedSet::BitTrue)?;
        let runs: Result<Vec<ProbeRecord>, ExperimentError> = seeds
            .par_iter()
            .enumerate()
            .map(|(i, &seed)| {
                with_record(spec, n, seed, probe, |rec, _| {
                    let mut m = if i == 0 {
                        bit_true_column(rec)?.ok_or_else(|| column_error(BIT_TRUE))?
                    } else {
                        bit_true_readout(rec)?
                    };
                    if spec.amp_um.is_none() {
                        m.amp_um = None;
                    }
                    Ok(m)
                })
                .map(|(m, dft)| ProbeRecord {
                    seed,
                    probe: m,
                    dft,
                })
            })
            .collect();
        let mut records = runs?;
        let check = records.first_mut().and_then(|r| r.probe.bit_true.take());
        Ok(ProbeRun {
            column: BIT_TRUE,
            seeds,
            records,
            raw: None,
            check,
        })
    }

    /// The probe's values of `what` per record (records without one left out).
    pub fn probe_values(&self, what: fn(&Measurement) -> Option<f64>) -> Vec<f64> {
        self.records.iter().filter_map(|r| what(&r.probe)).collect()
    }

    /// The same records' DFT values of `what`.
    pub fn dft_values(&self, what: fn(&Measurement) -> Option<f64>) -> Vec<f64> {
        self.records.iter().filter_map(|r| what(&r.dft)).collect()
    }
}

fn column_error(name: &str) -> ExperimentError {
    ExperimentError::option("columns", name, "a column that applies to every row")
}

/// Draws the record of `seed`, reads it by the DFT (on the probe bins, see
/// [`ProbeRecord::dft`]) and hands both to `probe_it`.
fn with_record<T>(
    spec: &Spec,
    n: u64,
    seed: u64,
    probe: &ProbeSetup,
    probe_it: impl FnOnce(&RowRecord<'_>, &Measurement) -> Result<T, ExperimentError>,
) -> Result<(T, Measurement), ExperimentError> {
    let source = spec.setup().source(seed)?;
    let detections = source.record(n);
    let rec = RowRecord {
        spec,
        source: &source,
        detections: &detections,
        probe: Some(probe),
    };
    let full = dft_column(&rec)?.ok_or_else(|| column_error(super::DFT))?;
    let dft = Measurement {
        noise_um: sigma_delta::noise_um(&full.phasors),
        amp_um: if spec.amp_um.is_some() {
            Some(sigma_delta::norm(full.phasors[0]) * 1e3)
        } else {
            full.amp_um
        },
        phasors: full.phasors,
        bit_true: None,
        top_bins: full.top_bins,
    };
    let out = probe_it(&rec, &dft)?;
    Ok((out, dft))
}

/// The float ΣΔ's largest value over the band of a row without a tone (µm): the record's
/// [`super::TOP_BINS`] largest DFT bins and their neighbours probed by the full-band
/// prober (the same probe design), the largest of the top bins interpolated with its
/// neighbours as the DFT's is. The ΣΔ's own largest bin is among the DFT's top 16: the
/// 16th largest of the ≈ 19,000 Rayleigh bins of 1–20 kHz lies ≈ 0.5 floors below the
/// largest, while the ΣΔ error moves a bin by ≈ 0.1–0.2 floors.
fn sd_largest_um(
    rec: &RowRecord<'_>,
    probe: &ProbeSetup,
    top: &[u64],
) -> Result<f64, ExperimentError> {
    let mut bins: Vec<u64> = top
        .iter()
        .flat_map(|&k| [k - 1, k, k + 1])
        .filter(|&k| k >= 1)
        .collect();
    bins.sort_unstable();
    bins.dedup();
    let alpha = sigma_delta::alpha();
    let zoom = rec.spec.setup().depth_mm();
    let mut fe = FrontEnd::new(zoom, FrontEndOutput::Prefiltered { alpha })?;
    let x: Vec<f64> = rec
        .detections
        .iter()
        .map(|d| fe.step(d.map(|c| rec.source.code_to_depth_mm(c))))
        .collect();
    let mut prober = FullBandProber::on_path(
        &probe.design,
        x.len() as u64,
        &bins,
        LanePrecision::F64,
        Isa::current(),
    )?;
    for c in x.chunks(1 << 16) {
        prober.push(c)?;
    }
    drop(x);
    let mag: Vec<f64> = prober
        .readout(Some(alpha))
        .iter()
        .map(|y| y.norm())
        .collect();
    let at = |k: u64| bins.binary_search(&k).map(|i| mag[i]).unwrap_or(0.0);
    let best = top
        .iter()
        .copied()
        .max_by(|&a, &b| at(a).total_cmp(&at(b)))
        .ok_or_else(|| {
            ExperimentError::option("pulses", rec.detections.len(), "a longer record")
        })?;
    let peak = interpolate_peak(&[at(best - 1), at(best), at(best + 1)], 1, 0)?;
    Ok(peak.amplitude * 1e3)
}
