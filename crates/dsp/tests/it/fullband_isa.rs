//! The full-band kernel's instruction paths (x86-64 baseline, AVX2 and AVX-512 with its
//! σ-FMA, chosen at run time) must give the same bitstreams and the same sums, bit for
//! bit, in both precisions and for CIFB loops with and without resonators; each wider path
//! must equal the naive scalar reference too. Every path this CPU runs is checked by name;
//! one it lacks is skipped with a message (and refused, not run).

use tofprobe_dsp::sd::fullband_check::{compare, fast_bits};
use tofprobe_dsp::sd::{FullBandProber, Isa, LanePrecision, ProbeConfig, ProbeDesign};

const N: u64 = 1 << 14;
/// DC, the DC main lobe, both slots of a group, a group boundary at every width (4, 8,
/// 16, 32 lanes: 2, 4, 8, 16 bins per group) and the last bin below N/(2·OSR) = 256 at
/// OSR 32: 19 bins leave every width's last group partly idle.
const BINS: [u64; 19] = [
    0, 1, 2, 3, 7, 8, 33, 64, 99, 100, 101, 128, 150, 199, 200, 201, 230, 254, 255,
];

/// Designs: the default (order 3, zeros at DC, no resonator) and two with optimised zeros
/// (order 4: two resonators; order 5: two resonators and a plain integrator). The measured
/// stable limit is passed in (0.77 for all three is conservative enough for A = 0.5; the
/// runs would fail with `Unstable` otherwise) to skip the slow stability sweep.
fn designs() -> Vec<ProbeDesign> {
    [(3, false), (4, true), (5, true)]
        .into_iter()
        .map(|(order, optimised_zeros)| {
            let cfg = ProbeConfig {
                order,
                optimised_zeros,
                ..ProbeConfig::default()
            };
            ProbeDesign::with_known_limit(&cfg, 0.77, 1e-4).expect("valid design")
        })
        .collect()
}

/// 30 mm + a 1 mm tone + xorshift noise: any record works, the bits do not depend on it
/// and the sums do.
fn record(n: usize) -> Vec<f64> {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    (0..n)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            30.0 + (i as f64 * 0.0123).cos() + 3.0 * noise
        })
        .collect()
}

/// First (bin index, stream 0 = I / 1 = Q, sample) where two sets of bitstreams part.
fn first_difference(a: &[[Vec<bool>; 2]], b: &[[Vec<bool>; 2]]) -> Option<(usize, usize, usize)> {
    assert_eq!(a.len(), b.len());
    for (i, (sa, sb)) in a.iter().zip(b).enumerate() {
        for q in 0..2 {
            if let Some(n) = sa[q].iter().zip(&sb[q]).position(|(x, y)| x != y) {
                return Some((i, q, n));
            }
        }
    }
    None
}

fn sums(d: &ProbeDesign, p: LanePrecision, path: Isa, x: &[f64], chunk: usize) -> Vec<u64> {
    let mut pr = FullBandProber::on_path(d, N, &BINS, p, path).expect("prober");
    assert_eq!(pr.path(), path);
    for c in x.chunks(chunk) {
        pr.push(c).expect("stable");
    }
    pr.sums()
        .iter()
        .flat_map(|&(i, q)| [i.to_bits(), q.to_bits()])
        .collect()
}

/// `path`'s bits and sums equal the baseline's, in both precisions, for every design.
fn same_as_baseline(path: Isa) {
    if !path.available() {
        eprintln!(
            "skipped the {} check: this CPU lacks {} (the baseline path is checked by fullband_check)",
            path.name(),
            path.features()
        );
        return;
    }
    let x = record(N as usize);
    for (di, d) in designs().iter().enumerate() {
        for p in [LanePrecision::F64, LanePrecision::F32] {
            let bits = |path| fast_bits(d, N, &BINS, &x, p, path).expect("stable");
            let (base, wide) = (bits(Isa::Scalar), bits(path));
            assert_eq!(
                first_difference(&base, &wide),
                None,
                "{} design {di} {}: (bin index, stream, sample) where the paths part",
                path.name(),
                p.name()
            );
            // Off-grid chunks on one path, whole record on the other: anchors and blocks
            // fall differently, the sums must not move.
            let (sb, sw) = (
                sums(d, p, Isa::Scalar, &x, 777),
                sums(d, p, path, &x, x.len()),
            );
            let first = sb.iter().zip(&sw).position(|(a, b)| a != b);
            assert_eq!(
                first,
                None,
                "{} design {di} {}: sum index",
                path.name(),
                p.name()
            );
            // The streams are real ΣΔ streams, not all one sign.
            assert!(base[3][0].iter().any(|&b| b) && base[3][0].iter().any(|&b| !b));
        }
    }
}

/// `path`'s f64 sums equal the naive scalar reference's (`Modulator::run` per stream).
fn equals_the_naive_reference(path: Isa) {
    if !path.available() {
        eprintln!("skipped: this CPU lacks {}", path.features());
        return;
    }
    let x = record(N as usize);
    for (di, d) in designs().iter().enumerate() {
        let m = compare(d, N, &BINS, &BINS, &x, 1000, path).expect("stable");
        assert_eq!(
            m,
            None,
            "{} design {di}: {}",
            path.name(),
            m.as_ref().map(|m| m.to_string()).unwrap_or_default()
        );
    }
}

#[test]
fn avx2_and_baseline_give_the_same_bits_and_sums() {
    same_as_baseline(Isa::Avx2);
}

#[test]
fn avx512_and_baseline_give_the_same_bits_and_sums() {
    same_as_baseline(Isa::Avx512);
}

#[test]
fn avx2_path_equals_the_naive_scalar_reference() {
    equals_the_naive_reference(Isa::Avx2);
}

#[test]
fn avx512_path_equals_the_naive_scalar_reference() {
    equals_the_naive_reference(Isa::Avx512);
}

/// The paths group 4, 8 and 16 f64 lanes (16, 32, 32 f32): the widths the two tests above
/// rely on exercising, and `auto` picks the widest this CPU runs.
#[test]
fn each_path_has_its_width_and_auto_is_the_widest() {
    let f64_lanes = Isa::ALL.map(|p| LanePrecision::F64.lanes_on(p));
    let f32_lanes = Isa::ALL.map(|p| LanePrecision::F32.lanes_on(p));
    assert_eq!((f64_lanes, f32_lanes), ([4, 8, 16], [16, 32, 32]));
    assert_eq!(Isa::current(), *Isa::supported().last().unwrap());
}

/// The check can fail: probing bin 100 where the other side probes 101 parts the streams
/// at once, and `first_difference` names the bin index and an early sample.
#[test]
fn a_wrong_bin_fails_the_path_check() {
    let d = &designs()[0];
    let x = record(4096);
    let path = Isa::current();
    let mut wrong = BINS;
    wrong[10] = 100;
    let a = fast_bits(d, N, &BINS, &x, LanePrecision::F64, path).unwrap();
    let b = fast_bits(d, N, &wrong, &x, LanePrecision::F64, Isa::Scalar).unwrap();
    let (i, _, n) = first_difference(&a, &b).expect("must differ");
    assert_eq!(i, 10);
    assert!(n < 1000, "{n}");
    // A path this CPU lacks is refused, not run.
    for p in Isa::ALL.into_iter().filter(|p| !p.available()) {
        let e = fast_bits(d, N, &BINS, &x, LanePrecision::F64, p).unwrap_err();
        assert!(e.to_string().contains(p.name()), "{e}");
    }
}
