//! Deterministic test stimulus: per-pulse detections and a probe ROM image from a seed
//! (tofprobe-scene's SplitMix64, so the C++ harness or anyone else can re-derive them from the manifest).

use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_scene::SplitMix64;

/// `pulses` detections: a detection with probability 3/4, its code a random walk over the
/// whole TDC range (so the prefilter sees both small and large steps and negative d).
pub fn random_stimulus(p: &PixelParams, pulses: u64, seed: u64) -> Vec<Option<u32>> {
    let mut rng = SplitMix64::new(seed);
    let top = 1u64 << p.tdc_bits;
    let mut code = rng.next_u64() % top;
    (0..pulses)
        .map(|_| {
            let r = rng.next_u64();
            if r & 3 == 0 {
                None
            } else {
                if (r >> 8).is_multiple_of(8) {
                    code = (r >> 16) % top;
                } else {
                    let step = ((r >> 16) % 7) as i64 - 3;
                    code = (code as i64 + step).clamp(0, top as i64 - 1) as u64;
                }
                Some(code as u32)
            }
        })
        .collect()
}

/// The probe ROM: L addresses × R bits, packed `ceil(R/64)` u64 words per address (bit r =
/// register r; 1 = add). Sign-quantised quadrature probes, bin k at k+1 cycles per L
/// pulses, I = sign(cos), Q = sign(sin). Haar has no ROM (an empty image).
pub fn sign_probe_rom(p: &PixelParams) -> Vec<u64> {
    if p.mode == Mode::Haar {
        return Vec::new();
    }
    let r = p.registers();
    let words = r.div_ceil(64);
    let l = p.rom_depth;
    let mut rom = vec![0u64; l * words];
    for a in 0..l {
        for k in 0..p.bins {
            let ph = 2.0 * std::f64::consts::PI * (k as f64 + 1.0) * a as f64 / l as f64;
            for (q, v) in [(0usize, ph.cos()), (1usize, ph.sin())] {
                let reg = 2 * k + q;
                if v >= 0.0 {
                    rom[a * words + reg / 64] |= 1u64 << (reg % 64);
                }
            }
        }
    }
    rom
}

/// A ROM of independent random bits (for co-simulation: every sign pattern occurs).
pub fn random_rom(p: &PixelParams, seed: u64) -> Vec<u64> {
    if p.mode == Mode::Haar {
        return Vec::new();
    }
    let r = p.registers();
    let words = r.div_ceil(64);
    let mut rng = SplitMix64::new(seed ^ 0x005e_ed0f_0e0b);
    let mut rom = vec![0u64; p.rom_depth * words];
    for (i, w) in rom.iter_mut().enumerate() {
        let bits_here = (r - (i % words) * 64).min(64) as u32;
        *w = rng.next_u64()
            & if bits_here == 64 {
                u64::MAX
            } else {
                (1u64 << bits_here) - 1
            };
    }
    rom
}
