//! Random valid pixel parameters: the one generator, every knob of [`PixelParams`] drawn
//! here once, on the workspace's one SplitMix64 (`tofprobe_scene`). Both modes, A > 1,
//! K < C, odd and tight widths (so the registers wrap often), any zoom, short frames,
//! registers keeping G ≤ F fraction bits, either rounding, every register file. Its
//! [`Ranges`] are the tests' ([`Ranges::TESTS`], through `tofprobe_testkit::params`) or
//! `tofprobe cosim --random`'s ([`Ranges::VERILATOR`], kept small: every configuration is a
//! Verilator build). The draws before the latest knobs are unchanged, so a seed keeps its
//! case when a knob is added: draw new knobs last.

use tofprobe_scene::SplitMix64;

use crate::params::{Mode, PixelParams, RegisterFile, Rounding};

/// The Fourier frames N drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FourierFrames {
    /// 1 ..= n.
    UpTo(u64),
    /// 2^lo ..= 2^hi.
    PowersOfTwo(u32, u32),
}

/// How far each knob ranges, and how often the later knobs leave their defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ranges {
    /// Percent of Haar configurations.
    pub haar_percent: u64,
    /// T: 1 ..= this.
    pub tdc_bits_max: u32,
    /// Haar frames N = 2^l, l in lo ..= hi.
    pub haar_levels: (u32, u32),
    /// U: 0 ..= min(l − 1, this).
    pub haar_scales_max: u32,
    /// B: 1 ..= this (Fourier).
    pub bins_max: u64,
    pub fourier_frames: FourierFrames,
    /// S: 0 ..= this.
    pub shift_max: u64,
    /// F: 0 ..= this.
    pub frac_bits_max: u64,
    /// L: 1 ..= this.
    pub rom_depth_max: u64,
    /// A: 1 ..= min(P, this).
    pub adders_max: u64,
    /// W: one operand plus 0 ..= this bits (at most 63).
    pub width_extra_max: u64,
    /// Percent of draws that move a later knob off its default (G < F, nearest rounding,
    /// clock gates, latches).
    pub knob_percent: u64,
}

impl Ranges {
    /// The tests': tiny frames and ROMs, many Haar scales, every A.
    pub const TESTS: Ranges = Ranges {
        haar_percent: 35,
        tdc_bits_max: 8,
        haar_levels: (1, 4),
        haar_scales_max: u32::MAX,
        bins_max: 5,
        fourier_frames: FourierFrames::UpTo(12),
        shift_max: 6,
        frac_bits_max: 6,
        rom_depth_max: 7,
        adders_max: u64::MAX,
        width_extra_max: 9,
        knob_percent: 30,
    };

    /// `tofprobe cosim --random`'s: R ≤ 15 and N ≤ 64, since every configuration is a
    /// Verilator build.
    pub const VERILATOR: Ranges = Ranges {
        haar_percent: 50,
        tdc_bits_max: 9,
        haar_levels: (4, 6),
        haar_scales_max: 2,
        bins_max: 7,
        fourier_frames: FourierFrames::PowersOfTwo(4, 6),
        shift_max: 8,
        frac_bits_max: 5,
        rom_depth_max: 48,
        adders_max: 4,
        width_extra_max: 11,
        knob_percent: 50,
    };
}

/// Uniform in `lo ..= hi`.
fn between(rng: &mut SplitMix64, lo: u64, hi: u64) -> u64 {
    lo + rng.below(hi - lo + 1)
}

/// Random valid parameters within `r` (see the module documentation).
pub fn random_params(rng: &mut SplitMix64, r: &Ranges) -> PixelParams {
    let haar = rng.chance(r.haar_percent);
    let tdc_bits = between(rng, 1, u64::from(r.tdc_bits_max)) as u32;
    let zoom = rng.below(1 << tdc_bits) as u32;
    let (mode, bins, haar_scales, frame_pulses) = if haar {
        let l = between(rng, u64::from(r.haar_levels.0), u64::from(r.haar_levels.1)) as u32;
        let scales = rng.below(u64::from(l.min(r.haar_scales_max.saturating_add(1)))) as u32;
        (Mode::Haar, 1, scales, 1u64 << l)
    } else {
        let bins = between(rng, 1, r.bins_max) as usize;
        let n = match r.fourier_frames {
            FourierFrames::UpTo(n) => between(rng, 1, n),
            FourierFrames::PowersOfTwo(lo, hi) => 1 << between(rng, lo.into(), hi.into()),
        };
        (Mode::Fourier, bins, 0, n)
    };
    let mut p = PixelParams {
        mode,
        bins,
        haar_scales,
        adders: 1,
        cycles_per_pulse: 1,
        tdc_bits,
        zoom,
        shift: rng.below(r.shift_max + 1) as u32,
        frac_bits: rng.below(r.frac_bits_max + 1) as u32,
        width: 1,
        frame_pulses,
        rom_depth: between(rng, 1, r.rom_depth_max) as usize,
        prefilter_rounding: Rounding::Floor,
        register_frac_bits: None,
        register_file: RegisterFile::default(),
    };
    let ops = p.ops_per_pulse() as u64;
    p.adders = between(rng, 1, ops.min(r.adders_max)) as usize;
    p.cycles_per_pulse = p.slots() + rng.below(3) as usize;
    // Registers keeping G ≤ F fraction bits (G = F half the time), before the width so
    // the tight widths are tight for the narrower operand too.
    if mode == Mode::Fourier && rng.chance(50) {
        p.register_frac_bits = Some(rng.below(u64::from(p.frac_bits) + 1) as u32);
    }
    p.width = (p.operand_bits() + rng.below(r.width_extra_max + 1) as u32).min(63);
    // Knobs added later, drawn last.
    if mode == Mode::Fourier && rng.chance(r.knob_percent) {
        p.prefilter_rounding = Rounding::Nearest;
    }
    if rng.chance(r.knob_percent) {
        p.register_file = RegisterFile::ClockGated;
    }
    // Latches after that, only over flops: a case's other fields stay what they were.
    if rng.chance(r.knob_percent) && p.register_file == RegisterFile::Flops {
        p.register_file = RegisterFile::Latch;
    }
    p.validate()
        .expect("random parameters are valid by construction");
    p
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::*;

    /// The generator covers every knob's values within a few hundred draws, in both
    /// ranges. `PixelParams` is destructured without `..`: a new field does not compile
    /// here until it is listed, and the test fails until the generator draws it.
    #[test]
    fn every_knob_is_drawn() {
        for r in [&Ranges::TESTS, &Ranges::VERILATOR] {
            let mut rng = SplitMix64::new(7);
            let ps: Vec<PixelParams> = (0..400).map(|_| random_params(&mut rng, r)).collect();
            let mut seen: Vec<(&str, BTreeSet<String>)> = Vec::new();
            for p in &ps {
                let PixelParams {
                    mode,
                    bins,
                    haar_scales,
                    adders,
                    cycles_per_pulse,
                    tdc_bits,
                    zoom,
                    shift,
                    frac_bits,
                    width,
                    frame_pulses,
                    rom_depth,
                    prefilter_rounding,
                    register_frac_bits,
                    register_file,
                } = p;
                let values = [
                    ("mode", format!("{mode:?}")),
                    ("bins", bins.to_string()),
                    ("haar_scales", haar_scales.to_string()),
                    ("adders", adders.to_string()),
                    (
                        "cycles_per_pulse",
                        (cycles_per_pulse - p.slots()).to_string(),
                    ),
                    ("tdc_bits", tdc_bits.to_string()),
                    ("zoom", zoom.to_string()),
                    ("shift", shift.to_string()),
                    ("frac_bits", frac_bits.to_string()),
                    ("width", (width - p.operand_bits()).to_string()),
                    ("frame_pulses", frame_pulses.to_string()),
                    ("rom_depth", rom_depth.to_string()),
                    ("prefilter_rounding", format!("{prefilter_rounding:?}")),
                    ("register_frac_bits", format!("{register_frac_bits:?}")),
                    ("register_file", format!("{register_file:?}")),
                ];
                if seen.is_empty() {
                    seen = values.iter().map(|(k, _)| (*k, BTreeSet::new())).collect();
                }
                for ((_, s), (_, v)) in seen.iter_mut().zip(values) {
                    s.insert(v);
                }
            }
            for (name, values) in &seen {
                assert!(
                    values.len() >= 2,
                    "{name} is never drawn: {values:?} ({r:?})"
                );
            }
            let any = |f: &dyn Fn(&PixelParams) -> bool| ps.iter().any(f);
            assert!(any(&|p| p.mode == Mode::Haar && p.haar_scales > 0));
            assert!(any(&|p| p.prefilter_rounding == Rounding::Nearest));
            assert!(any(&|p| p.register_file == RegisterFile::ClockGated));
            assert!(any(&|p| p.register_file == RegisterFile::Latch));
            assert!(any(&|p| p
                .register_frac_bits
                .is_some_and(|g| g < p.frac_bits)));
            assert!(any(&|p| p.adders > 1 && p.cycles_per_pulse > p.slots()));
        }
    }
}
