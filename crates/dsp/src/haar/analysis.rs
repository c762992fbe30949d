//! Readout → coefficients: the pixel's Haar registers (integer sums of the held, zoomed TDC
//! codes) as normalised coefficients w_{u,v} in mm with their time supports — the
//! scalogram's data, serialisable as JSON.
//!
//! Register r = 2^u − 1 + v holds Y = Σ_{+ half} h\[n\] − Σ_{− half} h\[n\] over the held codes
//! h\[n\] = code − Z (docs/pixel-contract.md, Haar mode: no prefilter, F = 0). A held code is
//! the depth (h + Z + ½)·a + window start in mm (a = tdc_lsb_ps × 0.15 mm/ps, the bin
//! centre), so
//!
//! w_{u,v} = a·Y / len(u, v)   (mm),
//!
//! len the wavelet's number of samples: the constant offset (Z + ½)·a + window start is
//! weighted by (#plus − #minus)/len, which is 0 when the two halves are equal (N divisible
//! by 2^(U+1), always so for the pixel's power-of-two frames). The result equals the float
//! Haar ([`super::haar_coefficients`]) of the held record in mm up to rounding.
//!
//! Sign convention (the paper's): w > 0 when the depth is larger in the first half, i.e. a
//! *decrease* of depth gives a positive coefficient.

use serde::{Deserialize, Serialize};

use super::{check_scales, haar_coefficients, normalise, register_count, register_index, support};
use crate::error::DspError;

/// One normalised Haar coefficient with its place in time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Coefficient {
    /// Scale (0 = the whole frame, U = the finest).
    pub u: u32,
    /// Shift within the scale, 0..2^u.
    pub v: usize,
    /// w_{u,v} in mm: mean depth of the first half minus that of the second, halved
    /// (positive when the depth decreases).
    pub value_mm: f64,
    /// Time of the wavelet's first pulse (s from the frame start).
    pub start_s: f64,
    /// Time of the pulse after the wavelet's last one (s): the support is [start_s, end_s).
    pub end_s: f64,
}

impl Coefficient {
    /// Register index 2^u − 1 + v.
    pub fn register(&self) -> usize {
        register_index(self.u, self.v)
    }
    /// The wavelet's duration T/2^u (s).
    pub fn duration_s(&self) -> f64 {
        self.end_s - self.start_s
    }
    /// The middle of the support (s).
    pub fn centre_s(&self) -> f64 {
        0.5 * (self.start_s + self.end_s)
    }
}

/// The Haar readout of one frame as coefficients in mm, register order (scale 0 first).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scalogram {
    /// N: pulses in the frame.
    pub pulses: u64,
    /// U: the finest scale.
    pub scales: u32,
    /// Laser pulse rate f_s (Hz): pulse n is at n/f_s.
    pub laser_rate_hz: f64,
    /// 2^(U+1) − 1 coefficients in register order.
    pub coefficients: Vec<Coefficient>,
}

fn check_positive(field: &'static str, v: f64) -> Result<(), DspError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(DspError::out_of_range(field, v, "a finite number > 0"))
    }
}

fn pulses_usize(pulses: u64) -> Result<usize, DspError> {
    usize::try_from(pulses).map_err(|_| {
        DspError::out_of_range(
            "pulses",
            pulses,
            format!("≤ {} on this machine", usize::MAX),
        )
    })
}

impl Scalogram {
    /// The inverse Haar transform: the mean depth (mm, relative to the frame's mean) of
    /// each of the 2^(U+1) half-wavelets of the finest scale, in time order. A coefficient
    /// w (mean of its first half − mean of its second, halved) adds +w to the cells of its
    /// first half and −w to those of its second; exact for the pixel's power-of-two frames.
    pub fn cell_means_mm(&self) -> Vec<f64> {
        let nc = 1usize << (self.scales + 1);
        let mut cells = vec![0.0; nc];
        for c in &self.coefficients {
            let per = nc >> c.u;
            let st = c.v * per;
            for (k, x) in cells[st..st + per].iter_mut().enumerate() {
                *x += if k < per / 2 { c.value_mm } else { -c.value_mm };
            }
        }
        cells
    }

    /// From the pixel's Haar registers (register order 2^u − 1 + v, sign-extended): each
    /// divided by its wavelet's length and multiplied by `mm_per_code` (the TDC LSB in mm,
    /// `SensorConfig::tdc_lsb_mm()`).
    pub fn from_registers(
        registers: &[i64],
        pulses: u64,
        u_max: u32,
        mm_per_code: f64,
        laser_rate_hz: f64,
    ) -> Result<Scalogram, DspError> {
        check_positive("mm_per_code", mm_per_code)?;
        let n = pulses_usize(pulses)?;
        check_scales(n, u_max)?;
        if registers.len() != register_count(u_max) {
            return Err(DspError::out_of_range(
                "Haar registers",
                registers.len(),
                format!("= 2^(U+1) − 1 = {} for U = {u_max}", register_count(u_max)),
            ));
        }
        let sums: Vec<f64> = registers.iter().map(|&y| y as f64).collect();
        let w: Vec<f64> = normalise(&sums, n, u_max)?
            .into_iter()
            .map(|c| c * mm_per_code)
            .collect();
        Scalogram::from_values_mm(&w, pulses, u_max, laser_rate_hz)
    }

    /// From coefficients already normalised and in mm (register order).
    pub fn from_values_mm(
        values_mm: &[f64],
        pulses: u64,
        u_max: u32,
        laser_rate_hz: f64,
    ) -> Result<Scalogram, DspError> {
        check_positive("laser_rate_hz", laser_rate_hz)?;
        let n = pulses_usize(pulses)?;
        check_scales(n, u_max)?;
        if values_mm.len() != register_count(u_max) {
            return Err(DspError::out_of_range(
                "Haar coefficients",
                values_mm.len(),
                format!("= 2^(U+1) − 1 = {} for U = {u_max}", register_count(u_max)),
            ));
        }
        if let Some(i) = values_mm.iter().position(|v| !v.is_finite()) {
            return Err(DspError::out_of_range(
                "Haar coefficient",
                format!("{} (register {i})", values_mm[i]),
                "a finite number",
            ));
        }
        let mut coefficients = Vec::with_capacity(values_mm.len());
        for u in 0..=u_max {
            for v in 0..(1usize << u) {
                let (s, _, e) = support(n, u, v);
                coefficients.push(Coefficient {
                    u,
                    v,
                    value_mm: values_mm[register_index(u, v)],
                    start_s: s as f64 / laser_rate_hz,
                    end_s: e as f64 / laser_rate_hz,
                });
            }
        }
        Ok(Scalogram {
            pulses,
            scales: u_max,
            laser_rate_hz,
            coefficients,
        })
    }

    /// The float Haar of a depth record in mm (any N ≥ 2^(U+1), powers of two or not).
    pub fn from_depths_mm(
        depths_mm: &[f64],
        u_max: u32,
        laser_rate_hz: f64,
    ) -> Result<Scalogram, DspError> {
        let w = haar_coefficients(depths_mm, u_max)?;
        Scalogram::from_values_mm(&w, depths_mm.len() as u64, u_max, laser_rate_hz)
    }

    /// Coefficient (u, v); None outside 0..=U, 0..2^u.
    pub fn get(&self, u: u32, v: usize) -> Option<&Coefficient> {
        (u <= self.scales && v < (1usize << u)).then(|| &self.coefficients[register_index(u, v)])
    }

    /// The 2^u coefficients of scale u (empty beyond U).
    pub fn scale(&self, u: u32) -> &[Coefficient] {
        if u > self.scales {
            return &[];
        }
        let s = register_index(u, 0);
        &self.coefficients[s..s + (1usize << u)]
    }

    /// The values in mm, register order.
    pub fn values_mm(&self) -> Vec<f64> {
        self.coefficients.iter().map(|c| c.value_mm).collect()
    }

    /// The frame's duration T = N/f_s (s).
    pub fn duration_s(&self) -> f64 {
        self.pulses as f64 / self.laser_rate_hz
    }

    /// The nominal wavelet duration of scale u, T/2^u (s).
    pub fn wavelet_duration_s(&self, u: u32) -> f64 {
        self.duration_s() / (1u64 << u) as f64
    }

    /// The heat map's cells: U+1 rows (u = 0 first) of 2^U columns, a coarse coefficient
    /// repeated over the finest cells it covers.
    pub fn grid_mm(&self) -> Vec<Vec<f64>> {
        let cols = 1usize << self.scales;
        (0..=self.scales)
            .map(|u| {
                (0..cols)
                    .map(|c| self.coefficients[register_index(u, c >> (self.scales - u))].value_mm)
                    .collect()
            })
            .collect()
    }

    /// The largest |w| (the coefficient itself), scale 0 first on ties.
    pub fn largest(&self) -> &Coefficient {
        self.coefficients
            .iter()
            .reduce(|a, b| {
                if b.value_mm.abs() > a.value_mm.abs() {
                    b
                } else {
                    a
                }
            })
            .unwrap_or(&self.coefficients[0])
    }

    /// Compression: N raw samples against 2^(U+1) − 1 registers.
    pub fn compression_ratio(&self) -> f64 {
        super::compression_ratio(self.pulses, self.scales)
    }
}

/// The held, zoomed codes the pixel's Haar mode accumulates (docs/pixel-contract.md):
/// h = code − Z for a detection, else the previous h; pulses before the first detection
/// contribute nothing (0). `held_codes` of a record and [`super::haar_sums`] give the
/// pixel's registers exactly (crates/pixel/tests/haar.rs).
pub fn held_codes(detections: &[Option<u32>], zoom: u32) -> Vec<i64> {
    let mut held = 0i64;
    detections
        .iter()
        .map(|d| {
            if let Some(c) = d {
                held = i64::from(*c) - i64::from(zoom);
            }
            held
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::haar::haar_sums;

    /// Held codes with misses, zoom 7, a = 0.75 mm: the integer sums are the naive
    /// streaming ones exactly, and the normalised values equal the float Haar of the held
    /// record in mm (codes → mm by the bin centre plus the window start) to rounding
    /// (1e-12 mm: a few ulps of values ≤ 100 mm), the offset cancelling for N = 2^k.
    #[test]
    fn registers_equal_float_haar_of_the_held_record() {
        let n = 1usize << 12;
        let u = 6;
        let (zoom, lsb, ws, fs) = (7u32, 0.75, 4.5, 1e7);
        let mut det: Vec<Option<u32>> = (0..n as u64)
            .map(|i| {
                let r = i
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((r >> 33) % 4 != 0).then_some(20 + ((r >> 40) % 40) as u32 + (i / 1000) as u32)
            })
            .collect();
        det[0] = Some(30);
        let held = held_codes(&det, zoom);
        let regs = haar_sums(&held, u).unwrap();
        let s = Scalogram::from_registers(&regs, n as u64, u, lsb, fs).unwrap();
        // The record is primed from pulse 0 (before priming the pixel adds 0, which has no
        // depth in mm to compare with).
        let depth_mm: Vec<f64> = held
            .iter()
            .map(|&h| (h as f64 + f64::from(zoom) + 0.5) * lsb + ws)
            .collect();
        let float = Scalogram::from_depths_mm(&depth_mm, u, fs).unwrap();
        for (a, b) in s.coefficients.iter().zip(&float.coefficients) {
            assert_eq!(
                (a.u, a.v, a.start_s, a.end_s),
                (b.u, b.v, b.start_s, b.end_s)
            );
            assert!((a.value_mm - b.value_mm).abs() < 1e-12, "{a:?} {b:?}");
        }
        // Times: wavelet (6, 3) covers pulses 192..256 of 4096 → 19.2..25.6 µs.
        let c = s.get(6, 3).unwrap();
        assert_eq!(c.register(), 66);
        assert!((c.start_s - 19.2e-6).abs() < 1e-18 && (c.end_s - 25.6e-6).abs() < 1e-18);
        assert_eq!(s.scale(6).len(), 64);
        assert!(s.get(7, 0).is_none() && s.get(2, 4).is_none());
        // A broken readout (one register off by one code) is visible at 1e-12.
        let mut bad = regs.clone();
        bad[66] += 1;
        let b = Scalogram::from_registers(&bad, n as u64, u, lsb, fs).unwrap();
        assert!((b.coefficients[66].value_mm - float.coefficients[66].value_mm).abs() > 1e-3);
    }

    #[test]
    fn grid_and_bad_input() {
        let w: Vec<f64> = (0..7).map(f64::from).collect();
        let s = Scalogram::from_values_mm(&w, 8, 2, 1e7).unwrap();
        assert_eq!(s.grid_mm()[1], vec![1.0, 1.0, 2.0, 2.0]);
        assert_eq!(s.largest().register(), 6);
        assert!((s.wavelet_duration_s(2) - 2e-7).abs() < 1e-20);
        assert!((s.compression_ratio() - 8.0 / 7.0).abs() < 1e-15);
        assert!(Scalogram::from_values_mm(&w, 8, 3, 1e7).is_err()); // 2^4 > 8
        assert!(Scalogram::from_values_mm(&w[..6], 8, 2, 1e7).is_err());
        assert!(Scalogram::from_values_mm(&w, 8, 2, 0.0).is_err());
        let mut nan = w.clone();
        nan[3] = f64::NAN;
        assert!(Scalogram::from_values_mm(&nan, 8, 2, 1e7).is_err());
        assert!(Scalogram::from_registers(&[0; 7], 8, 2, -1.0, 1e7).is_err());
    }
}
