//! The rows of Table 2 (configurations and printed values from [`super::printed`]) and the
//! seeds each column of a row runs on: the DFT, the float ΣΔ and the bit-true pixel each
//! have their own records (no column reuses another's), as many as the row's tests need to
//! catch a stated bias.

use std::sync::LazyLock;

use super::super::setup::{LSB_MM, Setup};
use super::super::sigma_delta::probe_bins;
use super::super::stats::{K, SEEDS};
use super::printed::{TSV, parse};
use super::{F0_HZ, Spec, closed_form_amp_um, closed_form_noise_on_bins_um, closed_form_noise_um};
use crate::ExperimentError;

/// The amplitude bias a full-length tested amplitude row must catch (µm): its seed count
/// makes K·se ≤ this.
pub const AMP_BIAS_UM: f64 = 10.0;
/// The relative noise bias a full-length probe (ΣΔ, bit-true) noise row must catch: its
/// seed count makes K·se ≤ this fraction of the floor.
pub const NOISE_BIAS: f64 = 0.05;
/// The most seeds a column of a row gets (a full record costs ≈ 1 s of CPU per seed).
pub const MAX_SEEDS: usize = 64;
/// Record length from which rows get their powered seed counts (shorter `--quick`
/// records keep [`SEEDS`]'s count: their floors are too high for a 10 µm test anyway).
pub const FULL_N: u64 = 10_000_000;
/// Amplitude rows are tested only where the tone stands this many floors above the noise.
pub const AMP_MIN_SNR: f64 = 3.0;

/// Every row of Table 2, in the paper's order, from the compiled-in table file (its parse
/// is checked by `printed`'s tests, so it cannot fail at run time).
pub static ROWS: LazyLock<Vec<Spec>> = LazyLock::new(|| {
    parse(TSV).unwrap_or_else(|e| panic!("the compiled-in data/paper/table2.tsv: {e}"))
});

/// Which records a row's column runs on. Each has its own seeds, so the columns'
/// statistics are independent and each can fail on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeedSet {
    /// The DFT column (noise floor and amplitude over the band).
    Dft,
    /// The float ΣΔ column.
    FloatSd,
    /// The bit-true pixel.
    BitTrue,
}

impl SeedSet {
    /// First seed of the set within a row's block of 1000 (row i of [`ROWS`] owns
    /// 1000·(i + 1) .. 1000·(i + 2)): the sets never meet (each holds ≤ [`MAX_SEEDS`]).
    fn offset(self) -> u64 {
        match self {
            SeedSet::Dft => 0,
            SeedSet::FloatSd => 100,
            SeedSet::BitTrue => 200,
        }
    }
}

/// The largest share of the probe's own error in a probe column's floor the seed counts
/// allow for: ε² ≤ 0.1 (ε is measured at 0.1–0.2; `sigma_delta::rows`), i.e. the probe's
/// floor up to sqrt(1.1) = 1.049× the depth noise's.
pub const PROBE_EPS2_MAX: f64 = 0.1;

/// The seed count that makes a tested amplitude row of column set `set` catch an
/// [`AMP_BIAS_UM`] bias: S = ⌈(K·sd/bias)²⌉ with sd = floor·sqrt(2/π) the predicted sd of
/// one seed's amplitude (`rows::amplitude_row`), the floor the DFT's over the band or, for
/// a probe column, the depth noise at the tone bin grown by sqrt(1 + [`PROBE_EPS2_MAX`]);
/// `None` where the amplitude is not tested (no tone, or the tone below [`AMP_MIN_SNR`]
/// floors).
fn amplitude_seeds(spec: &Spec, n: u64, set: SeedSet) -> Result<Option<usize>, ExperimentError> {
    let Some(amp) = closed_form_amp_um(spec)? else {
        return Ok(None);
    };
    let floor = match set {
        SeedSet::Dft => closed_form_noise_um(spec, n as usize)?,
        SeedSet::FloatSd | SeedSet::BitTrue => {
            closed_form_noise_on_bins_um(spec, n as usize, &probe_bins(n)[..1])?
                * (1.0 + PROBE_EPS2_MAX).sqrt()
        }
    };
    if amp / floor < AMP_MIN_SNR {
        return Ok(None);
    }
    let sd = floor * (2.0 / std::f64::consts::PI).sqrt();
    Ok(Some((K * sd / AMP_BIAS_UM).powi(2).ceil() as usize))
}

/// The seed count that makes a probe noise row catch a [`NOISE_BIAS`]: the probe reads
/// the floor on M noise bins ≥ 140 Hz apart (independent), so one seed's relative sd is
/// rel = sqrt((4/π − 1)/M) (`stats`); a floor biased by b has its sd grown by 1 + b too,
/// so K·rel·(1 + b)/√S ≤ b: S = ⌈(K·rel·(1 + b)/b)²⌉ (M = 50 at N = 10^7: 22 seeds).
pub fn probe_noise_seeds(n: u64) -> usize {
    let m = probe_bins(n).len().saturating_sub(1).max(1) as f64;
    let rel = ((4.0 / std::f64::consts::PI - 1.0) / m).sqrt();
    (K * rel * (1.0 + NOISE_BIAS) / NOISE_BIAS).powi(2).ceil() as usize
}

/// A row's seeds for column set `set` at N = `n`: rows share none, columns share none. At
/// full length ([`FULL_N`]) the DFT column has enough that an [`AMP_BIAS_UM`] bias fails
/// its amplitude test (its noise floor over ≈ 9000 band bins needs no more than
/// [`SEEDS`]); the probe columns (ΣΔ, bit-true) read the noise on a few dozen bins, so
/// they need the larger of that count and [`probe_noise_seeds`] for a [`NOISE_BIAS`] to
/// fail; all between [`SEEDS`]'s count and [`MAX_SEEDS`]. A spec outside [`ROWS`] (a
/// test's own) gets [`SEEDS`]'s count from the set's offset.
pub fn seeds_for_set(spec: &Spec, n: u64, set: SeedSet) -> Result<Vec<u64>, ExperimentError> {
    let Some(i) = ROWS.iter().position(|r| r == spec) else {
        let base = set.offset();
        return Ok((base..base + SEEDS.len() as u64).collect());
    };
    let mut count = SEEDS.len();
    if n >= FULL_N {
        let amp = amplitude_seeds(spec, n, set)?.unwrap_or(0);
        let noise = match set {
            SeedSet::Dft => 0,
            SeedSet::FloatSd | SeedSet::BitTrue => probe_noise_seeds(n),
        };
        count = amp.max(noise).clamp(SEEDS.len(), MAX_SEEDS);
    }
    let base = 1000 * (i as u64 + 1) + set.offset();
    Ok((base..base + count as u64).collect())
}

/// The DFT column's seeds ([`seeds_for_set`] with [`SeedSet::Dft`]).
pub fn seeds_for(spec: &Spec, n: u64) -> Result<Vec<u64>, ExperimentError> {
    seeds_for_set(spec, n, SeedSet::Dft)
}

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
