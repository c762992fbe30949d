//! The naive reference that judges the full-band fast path: each stream's probe input run
//! through the scalar [`Modulator::run`] one stream at a time, and Σ x\[n\]·v\[n\] accumulated
//! sample by sample. The f64 fast path must equal it exactly (same bits, same sums); a
//! difference is reported with the first bin, stream and sample where the bits part.
//!
//! The reference is fed the rotator's inputs (`PairGroup::inputs`, the kernel's own
//! arithmetic), not direct trigonometry: the two differ by ≤ 1e-12 (checked in `pairs`),
//! but while the bits agree the modulator is a chain of integrators open to an input
//! difference, so over 10⁴ samples it grows to ≈ 1e-7 in the last state and eventually
//! flips a decision that sat that close to the threshold (seen at sample 14,104 of bin 1 Q
//! at N = 2^14). Inputs and modulator are therefore judged separately, each exactly or
//! against its own bound.

use super::fullband::FullBandProber;
use super::modulator::Modulator;
use super::probe::ProbeDesign;
use super::simd::Isa;
use super::simd::pairs::{
    Coeffs, LANES_F32, LANES_F32_AVX2, LANES_F32_AVX512, LANES_F64, LANES_F64_AVX2,
    LANES_F64_AVX512, Lane, LanePrecision, PairGroup,
};
use crate::error::DspError;

/// Where the fast path and the naive reference part.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// Bin index k.
    pub bin: u64,
    /// Q (sine) stream rather than I.
    pub quadrature: bool,
    /// First sample whose bit differs (`None`: same bits, different sums).
    pub sample: Option<usize>,
    /// The two sums of that stream.
    pub fast: f64,
    pub naive: f64,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "bin {} {}: fast sum {} vs naive {}",
            self.bin,
            if self.quadrature { "Q" } else { "I" },
            self.fast,
            self.naive
        )?;
        match self.sample {
            Some(n) => write!(f, ", bits first differ at sample {n}"),
            None => write!(f, ", same bits"),
        }
    }
}

/// A·w\[n\] for the first `len` samples of the frame.
fn amplitude_window(design: &ProbeDesign, frame: u64, len: usize) -> Vec<f64> {
    let (amp, window, c) = (
        design.config.amplitude,
        design.config.window,
        design.config.convention,
    );
    (0..len)
        .map(|n| amp * c.window_value(window, n, frame as usize))
        .collect()
}

/// One bin of the naive reference.
#[derive(Debug, Clone, PartialEq)]
pub struct NaiveBin {
    /// (I, Q) sums.
    pub sums: (f64, f64),
    /// The I and Q bitstreams (true = +1).
    pub bits: [Vec<bool>; 2],
}

/// The naive reference: per bin its (I, Q) sums and the two bitstreams.
pub fn naive_sums(
    design: &ProbeDesign,
    frame: u64,
    bins: &[u64],
    x: &[f64],
) -> Result<Vec<NaiveBin>, DspError> {
    let m: &Modulator = &design.modulator;
    let amp = design.config.amplitude;
    let aw = amplitude_window(design, frame, x.len());
    bins.iter()
        .map(|&k| {
            let inputs =
                PairGroup::<f64, LANES_F64>::new(&[k], frame, m.order, Isa::Scalar).inputs(0, &aw);
            let mut sums = [0.0; 2];
            let mut bits = [Vec::new(), Vec::new()];
            for (q, (sum, b)) in sums.iter_mut().zip(bits.iter_mut()).enumerate() {
                let lane = PairGroup::<f64, LANES_F64>::lane(0, q == 1);
                let u: Vec<f64> = inputs.iter().map(|r| r[lane]).collect();
                let mut v = vec![0.0; x.len()];
                m.run(&u, &mut m.zero_state(), &mut v, amp, 0)?;
                for (xn, vn) in x.iter().zip(&v) {
                    *sum += xn * vn;
                }
                *b = v.iter().map(|&vn| vn > 0.0).collect();
            }
            Ok(NaiveBin {
                sums: (sums[0], sums[1]),
                bits,
            })
        })
        .collect()
}

/// The fast path's bitstreams per bin (I, Q), from the same kernel with tracing on, in a
/// precision on an instruction path (an error if this CPU cannot run it).
pub fn fast_bits(
    design: &ProbeDesign,
    frame: u64,
    bins: &[u64],
    x: &[f64],
    precision: LanePrecision,
    path: Isa,
) -> Result<Vec<[Vec<bool>; 2]>, DspError> {
    let path = super::simd::require(path)?;
    let k = Coeffs::new(&design.modulator.ss)?;
    let aw = amplitude_window(design, frame, x.len());
    let narrow = |v: &[f64]| v.iter().map(|&v| v as f32).collect::<Vec<f32>>();
    match (precision, path) {
        (LanePrecision::F64, Isa::Scalar) => {
            traced::<f64, LANES_F64>(&k, frame, bins, &aw, x, path)
        }
        (LanePrecision::F64, Isa::Avx2) => {
            traced::<f64, LANES_F64_AVX2>(&k, frame, bins, &aw, x, path)
        }
        (LanePrecision::F32, Isa::Scalar) => {
            traced::<f32, LANES_F32>(&k, frame, bins, &narrow(&aw), &narrow(x), path)
        }
        (LanePrecision::F32, Isa::Avx2) => {
            traced::<f32, LANES_F32_AVX2>(&k, frame, bins, &narrow(&aw), &narrow(x), path)
        }
        (LanePrecision::F64, Isa::Avx512) => {
            traced::<f64, LANES_F64_AVX512>(&k, frame, bins, &aw, x, path)
        }
        (LanePrecision::F32, Isa::Avx512) => {
            traced::<f32, LANES_F32_AVX512>(&k, frame, bins, &narrow(&aw), &narrow(x), path)
        }
    }
}

fn traced<T: Lane, const L: usize>(
    k: &Coeffs,
    frame: u64,
    bins: &[u64],
    aw: &[T],
    x: &[T],
    path: Isa,
) -> Result<Vec<[Vec<bool>; 2]>, DspError> {
    let mut out = Vec::new();
    for chunk in bins.chunks(L / 2) {
        let mut g = PairGroup::<T, L>::new(chunk, frame, k.order, path);
        let mut trace = vec![0u32; x.len()];
        g.run(k, 0, aw, x, &mut trace)?;
        for p in 0..chunk.len() {
            out.push(
                [false, true]
                    .map(|q| PairGroup::<T, L>::lane(p, q))
                    .map(|l| trace.iter().map(|w| (w >> l) & 1 == 1).collect()),
            );
        }
    }
    Ok(out)
}

/// Runs the f64 fast path on `path` over `x` (pushed in chunks of `chunk`) for `bins` and
/// the naive reference for `naive_bins` (the same bins, unless a test breaks them on
/// purpose), and returns the first stream whose sums differ, with the first sample where
/// its bits differ.
pub fn compare(
    design: &ProbeDesign,
    frame: u64,
    bins: &[u64],
    naive_bins: &[u64],
    x: &[f64],
    chunk: usize,
    path: Isa,
) -> Result<Option<Mismatch>, DspError> {
    let mut fast = FullBandProber::on_path(design, frame, bins, LanePrecision::F64, path)?;
    for c in x.chunks(chunk.max(1)) {
        fast.push(c)?;
    }
    let naive = naive_sums(design, frame, naive_bins, x)?;
    for (i, (&(fi, fq), (&k, nb))) in fast.sums().iter().zip(bins.iter().zip(&naive)).enumerate() {
        let (ni, nq) = nb.sums;
        for (q, (f, n)) in [(fi, ni), (fq, nq)].into_iter().enumerate() {
            if f.to_bits() != n.to_bits() {
                let fb = fast_bits(
                    design,
                    frame,
                    &bins[i..=i],
                    x,
                    LanePrecision::F64,
                    fast.path(),
                )?;
                let sample = fb[0][q].iter().zip(&nb.bits[q]).position(|(a, b)| a != b);
                return Ok(Some(Mismatch {
                    bin: k,
                    quadrature: q == 1,
                    sample,
                    fast: f,
                    naive: n,
                }));
            }
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::super::config::ProbeConfig;
    use super::super::fullband::{bin_scale, gain};
    use super::super::probe::ProbeRom;
    use super::super::probing::{ProbeAccumulator, normalise};
    use super::*;
    use crate::preprocess::{FrontEnd, FrontEndOutput};
    use crate::window::Window;
    use rustfft::num_complex::Complex64;
    use std::f64::consts::PI;

    fn design() -> ProbeDesign {
        // The default design's measured limit (≈ 0.77 at 1 kHz, see `Modulator` tests):
        // skips the stability sweep, slow in a debug build.
        ProbeDesign::with_known_limit(&ProbeConfig::default(), 0.77, 1e-4).unwrap()
    }

    /// 30 mm + a tone of 1 mm on bin `k` + Gaussian noise σ, from a tiny deterministic
    /// generator (xorshift + Box–Muller), so no RNG crate is needed.
    fn depths(n: usize, k: u64, sigma: f64, mut s: u64) -> Vec<f64> {
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let g = (-2.0 * u().ln()).sqrt() * (2.0 * PI * u()).cos();
                30.0 + sigma * g + (2.0 * PI * (k * i as u64) as f64 / n as f64 + 0.3).cos()
            })
            .collect()
    }

    const N: u64 = 1 << 14;
    /// DC, the first bins (window main lobe of the DC), a middle one, both group slots
    /// and the last bin below f_s/(2·OSR) = N/64.
    const BINS: [u64; 7] = [0, 1, 2, 7, 100, 101, 255];

    #[test]
    fn f64_fast_path_equals_the_naive_reference() {
        let d = design();
        let x = depths(N as usize, 100, 3.0, 0x9e37_79b9_7f4a_7c15);
        // Chunks of 1000 cross the anchor (1024) and block boundaries off-grid.
        for path in Isa::ALL {
            if !path.available() {
                eprintln!("skipped: this CPU cannot run the {} path", path.name());
                continue;
            }
            let m = compare(&d, N, &BINS, &BINS, &x, 1000, path).unwrap();
            assert_eq!(
                m,
                None,
                "{}: {}",
                path.name(),
                m.as_ref().map(|m| m.to_string()).unwrap_or_default()
            );
        }
    }

    /// A deliberately wrong input (the reference probes bin 8 where the fast path probes
    /// 7) must fail the check and name the bin and the first differing sample.
    #[test]
    fn a_wrong_bin_fails_the_check() {
        let d = design();
        let x = depths(N as usize, 100, 3.0, 5);
        let mut wrong = BINS;
        wrong[3] = 8;
        let m = compare(&d, N, &BINS, &wrong, &x, 4096, Isa::current())
            .unwrap()
            .expect("must differ");
        assert_eq!((m.bin, m.quadrature), (7, false), "{m}");
        let n = m.sample.expect("bits differ");
        assert!(n < 1000, "{m}");
        assert!(m.to_string().contains("bin 7 I"), "{m}");
    }

    /// The sums do not depend on how the record is chunked nor on the thread count.
    #[test]
    fn sums_do_not_depend_on_chunking_or_threads() {
        let d = design();
        let x = depths(N as usize, 100, 3.0, 9);
        for precision in [LanePrecision::F64, LanePrecision::F32] {
            let run = |chunk: usize| {
                let mut p = FullBandProber::new(&d, N, &BINS, precision).unwrap();
                for c in x.chunks(chunk) {
                    p.push(c).unwrap();
                }
                p.sums()
            };
            let whole = run(x.len());
            assert_eq!(run(777), whole, "{precision:?}");
            let one = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap();
            assert_eq!(one.install(|| run(5000)), whole, "{precision:?}");
        }
    }

    /// The f32 lanes' bits differ from f64's, but their readout is as good a ΣΔ estimate
    /// of the DFT as f64's and as the chip-ROM path's (`ProbeRom` windowed +
    /// `ProbeAccumulator`, the established float ΣΔ). Record: a 1 mm tone in 3 mm noise on
    /// 30 mm, prefiltered (α = 1/32) by the float front end, N = 2^15, 40 noise bins over
    /// 6–150 kHz. Each path's mean error |Y − Y_DFT| is ≈ 0.8 × the noise floor here (it
    /// grows towards the band edge, where 1/H_pre amplifies it, and falls as 1/√N relative
    /// to the floor for its DC part: ≈ 0.3 at 2^17). The paths are different realisations
    /// of the quantisation noise, and a 40-bin mean of |error| (per-bin spread ≈ 50%)
    /// varies by ≈ 8%, so the ratio of two paths' errors is held to [0.7, 1.4] (≈ 3σ).
    /// The tone must read within 5% of the DFT's (the error is ≈ 3% of it here).
    #[test]
    fn f32_lanes_track_the_dft_like_f64_and_the_rom_path() {
        let n = 1usize << 15;
        let d = design();
        let tone = 300u64;
        let bins: Vec<u64> = std::iter::once(tone)
            .chain((0..40).map(|i| 20 + 12 * i))
            .collect();
        let raw = depths(n, tone, 3.0, 77);
        let alpha = 1.0 / 32.0;
        let mut fe = FrontEnd::new(0.0, FrontEndOutput::Prefiltered { alpha }).unwrap();
        let x: Vec<f64> = raw.iter().map(|&v| fe.step(Some(v))).collect();
        let read = |p: LanePrecision| {
            let mut pr = FullBandProber::new(&d, n as u64, &bins, p).unwrap();
            pr.push(&x).unwrap();
            pr.readout(Some(alpha))
        };
        let (y64, y32) = (read(LanePrecision::F64), read(LanePrecision::F32));
        let rom = ProbeRom::generate(&d, 10e6, n as u64, &bins).unwrap();
        let mut acc = ProbeAccumulator::new(&rom, None);
        acc.push(&x);
        let y_rom = normalise(&rom, &acc.sums(), n as u64, Some(alpha));
        let dft: Vec<Complex64> = bins
            .iter()
            .map(|&k| {
                let mut acc = Complex64::new(0.0, 0.0);
                for (i, &v) in x.iter().enumerate() {
                    let th = 2.0 * PI * ((k * i as u64) % n as u64) as f64 / n as f64;
                    acc += Complex64::from_polar(v * Window::Blackman.value(i, n), -th);
                }
                acc * bin_scale(k, n as u64)
                    / Window::Blackman.coherent_gain()
                    / gain(Some(alpha), k, n as u64)
            })
            .collect();
        let floor = dft[1..].iter().map(|y| y.norm()).sum::<f64>() / 40.0;
        let err = |y: &[Complex64]| {
            (1..y.len()).map(|i| (y[i] - dft[i]).norm()).sum::<f64>() / 40.0 / floor
        };
        let (e64, e32, erom) = (err(&y64), err(&y32), err(&y_rom));
        for (name, e) in [("f64", e64), ("f32", e32)] {
            let r = e / erom;
            assert!(
                (0.7..=1.4).contains(&r),
                "{name}: {e} × floor vs ROM path {erom}"
            );
        }
        for y in [&y64, &y32] {
            assert!(
                (y[0].norm() / dft[0].norm() - 1.0).abs() < 0.05,
                "{} vs {}",
                y[0],
                dft[0]
            );
        }
        // The f32 streams are other bitstreams, not a rounding of the f64 ones.
        assert_ne!(y32[1], y64[1]);
    }
}
