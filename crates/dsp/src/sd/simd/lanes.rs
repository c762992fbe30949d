//! The fast bitstream generator: several modulators interleaved in a structure-of-arrays
//! loop ([`LANES`] lanes, one probe stream each) that the compiler vectorises, fed by phase
//! rotation recurrences instead of per-sample sin/cos.
//!
//! Each lane's input is u\[n\] = A · w\[n mod L\] · cos(2π k (n mod L)/L + φ), with φ = 0 for
//! I and −π/2 for Q (cos(θ − π/2) = sin θ). The rotators are re-anchored from exact
//! integer phases (k·n mod L) every [`ANCHOR`] samples, so rounding never accumulates
//! beyond ≈ ANCHOR·1e-16 and the input is an exact function of n mod L: every period of a
//! periodic ROM sees bit-identical input.
//!
//! That is the default [`ProbeConvention::Tofprobe`]. Under
//! [`ProbeConvention::Toolbox`] every sample is evaluated directly, as a toolbox script
//! writes it: u\[n\] = (A · w_sym\[m\]) · trig(θ) with m = n mod L, θ = (2π·(k·m mod L))/L,
//! trig = cos for I and sin for Q (exactly 0 at θ = 0), w_sym numpy's symmetric window
//! ([`Window::symmetric_value`]); still an exact function of n mod L, at the cost of a
//! sin or cos per sample and lane (≈ 20 ns: seconds for a windowed ROM of 10^7 pulses).

use crate::error::DspError;
use crate::sd::STATE_BOUND;
use crate::sd::config::ProbeConvention;
use crate::sd::realize::StateSpace;
use crate::window::Window;
use std::f64::consts::PI;

/// Modulators per interleaved group. Four lanes measured fastest on the x86-64 baseline
/// (SSE2, 16 vector registers): 4 lanes × 3 states fit in registers, 8 lanes spill
/// (2 lanes: 0.09 s, 4: 0.13 s, 8: 0.30 s per group of 10^7 samples).
pub const LANES: usize = 4;
/// Samples between exact re-anchorings of the rotators.
pub const ANCHOR: usize = 1024;

/// One lane's probe: bin index k over period L, phase offset, amplitude (0 = idle lane).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneProbe {
    pub bin: u64,
    pub quadrature: bool,
    pub amplitude: f64,
}

/// A group of up to [`LANES`] modulators with their states.
#[derive(Debug, Clone)]
pub struct LaneGroup {
    probes: [LaneProbe; LANES],
    period: u64,
    window: Window,
    convention: ProbeConvention,
    /// `states[i][lane]`
    pub states: Vec<[f64; LANES]>,
}

impl LaneGroup {
    /// A group at rest. `probes` beyond the first LANES are ignored; missing lanes idle.
    pub fn new(probes: &[LaneProbe], period: u64, window: Window, order: usize) -> Self {
        let idle = LaneProbe {
            bin: 0,
            quadrature: false,
            amplitude: 0.0,
        };
        let mut p = [idle; LANES];
        for (d, s) in p.iter_mut().zip(probes) {
            *d = *s;
        }
        LaneGroup {
            probes: p,
            period,
            window,
            convention: ProbeConvention::Tofprobe,
            states: vec![[0.0; LANES]; order],
        }
    }

    /// The same group writing its probes in `convention` (the default is tofprobe's).
    pub fn with_convention(mut self, convention: ProbeConvention) -> Self {
        self.convention = convention;
        self
    }

    /// Fills `u[t][lane]` for samples n0 .. n0 + u.len() (u.len() ≤ ANCHOR).
    pub(crate) fn inputs(&self, n0: u64, u: &mut [[f64; LANES]]) {
        if self.convention == ProbeConvention::Toolbox {
            return self.toolbox_inputs(n0, u);
        }
        let l = self.period;
        let two_pi_over_l = 2.0 * PI / l as f64;
        let mut c = [0.0; LANES];
        let mut s = [0.0; LANES];
        let mut cd = [0.0; LANES];
        let mut sd = [0.0; LANES];
        let mut amp = [0.0; LANES];
        for (i, p) in self.probes.iter().enumerate() {
            let k = p.bin % l;
            let ph = ((k as u128 * (n0 % l) as u128) % l as u128) as f64 * two_pi_over_l
                - if p.quadrature { 0.5 * PI } else { 0.0 };
            c[i] = ph.cos();
            s[i] = ph.sin();
            let d = k as f64 * two_pi_over_l;
            cd[i] = d.cos();
            sd[i] = d.sin();
            amp[i] = p.amplitude;
        }
        // Window rotator (shared by the lanes): w = a0 − a1 cos φ + a2 cos 2φ.
        let (a0, a1, a2) = match self.window {
            Window::Rectangular => (1.0, 0.0, 0.0),
            Window::Hann => (0.5, 0.5, 0.0),
            Window::Blackman => (0.42, 0.5, 0.08),
        };
        let phw = (n0 % l) as f64 * two_pi_over_l;
        let (mut wc, mut ws) = (phw.cos(), phw.sin());
        let (wcd, wsd) = (two_pi_over_l.cos(), two_pi_over_l.sin());
        for row in u.iter_mut() {
            let w = a0 - a1 * wc + a2 * (2.0 * wc * wc - 1.0);
            for i in 0..LANES {
                row[i] = amp[i] * w * c[i];
                let nc = c[i] * cd[i] - s[i] * sd[i];
                let ns = s[i] * cd[i] + c[i] * sd[i];
                c[i] = nc;
                s[i] = ns;
            }
            let nwc = wc * wcd - ws * wsd;
            ws = ws * wcd + wc * wsd;
            wc = nwc;
        }
    }

    /// The toolbox's samples, each evaluated directly (see the module docs).
    fn toolbox_inputs(&self, n0: u64, u: &mut [[f64; LANES]]) {
        let l = self.period;
        for (t, row) in u.iter_mut().enumerate() {
            let m = (n0 + t as u64) % l;
            let w = self.window.symmetric_value(m as usize, l as usize);
            for (v, p) in row.iter_mut().zip(&self.probes) {
                let km = ((p.bin % l) as u128 * m as u128 % l as u128) as f64;
                let th = 2.0 * PI * km / l as f64;
                *v = p.amplitude * w * if p.quadrature { th.sin() } else { th.cos() };
            }
        }
    }

    /// Runs samples n0 .. n0 + out.len(), writing one word per sample (bit i = lane i
    /// output +1). Errors if a state leaves [`STATE_BOUND`], naming the lane's amplitude.
    pub fn run(&mut self, ss: &StateSpace, n0: u64, out: &mut [u16]) -> Result<(), DspError> {
        self.dispatch(ss, n0, out, true).map(|_| ())
    }

    /// Runs like [`LaneGroup::run`] but never fails: returns which lanes stayed within
    /// the state bound (an unstable lane's state is frozen so it cannot overflow).
    pub fn run_flagging(&mut self, ss: &StateSpace, n0: u64, out: &mut [u16]) -> [bool; LANES] {
        self.dispatch(ss, n0, out, false).unwrap_or([false; LANES])
    }

    fn dispatch(
        &mut self,
        ss: &StateSpace,
        n0: u64,
        out: &mut [u16],
        strict: bool,
    ) -> Result<[bool; LANES], DspError> {
        match ss.order {
            1 => self.run_n::<1>(ss, n0, out, strict),
            2 => self.run_n::<2>(ss, n0, out, strict),
            3 => self.run_n::<3>(ss, n0, out, strict),
            4 => self.run_n::<4>(ss, n0, out, strict),
            5 => self.run_n::<5>(ss, n0, out, strict),
            _ => self.run_n::<6>(ss, n0, out, strict),
        }
    }

    fn run_n<const N: usize>(
        &mut self,
        ss: &StateSpace,
        n0: u64,
        out: &mut [u16],
        strict: bool,
    ) -> Result<[bool; LANES], DspError> {
        let mut ok = [true; LANES];
        // CIFB structure (see `StateSpace::from_cifb`): A is tridiagonal with a unit
        // diagonal, and only the last state feeds the quantiser. Exploiting it halves the
        // work of a dense N×N product; the order of the additions equals the dense
        // reference's with its zero terms dropped, so the bits are identical.
        let tridiagonal = |r: usize| (0..N).all(|j| r.abs_diff(j) <= 1 || ss.a[r * N + j] == 0.0);
        debug_assert!((0..N).all(tridiagonal));
        debug_assert!((0..N).all(|r| ss.a[r * N + r] == 1.0));
        let mut sub = [0.0; N];
        let mut sup = [0.0; N];
        let mut b1 = [0.0; N];
        let mut b2 = [0.0; N];
        for r in 0..N {
            if r > 0 {
                sub[r] = ss.a[r * N + r - 1];
            }
            if r + 1 < N {
                sup[r] = ss.a[r * N + r + 1];
            }
            b1[r] = ss.b1[r];
            b2[r] = ss.b2[r];
        }
        let c_last = ss.c[N - 1];
        let d1 = ss.d1;
        let mut x = [[0.0; LANES]; N];
        for (r, row) in x.iter_mut().enumerate() {
            *row = self.states[r];
        }
        let mut u = vec![[0.0; LANES]; ANCHOR];
        let mut done = 0usize;
        while done < out.len() {
            let len = (out.len() - done).min(ANCHOR);
            let n = n0 + done as u64;
            self.inputs(n, &mut u[..len]);
            let mut peak = [0.0f64; LANES];
            for (ut, o) in u[..len].iter().zip(out[done..done + len].iter_mut()) {
                let mut pos = [0u8; LANES];
                let mut p = [false; LANES];
                for l in 0..LANES {
                    let y = d1 * ut[l] + c_last * x[N - 1][l];
                    p[l] = y >= 0.0;
                    pos[l] = p[l] as u8;
                }
                *o = gather_bits(&pos);
                // x'[r] = (A x)[r] + b1·u, then ± b2 (= b2·v, v = ±1, exactly) last: all but
                // the final add is off the quantiser's critical path. Conditions are
                // hoisted out of the lane loops so each lane loop is straight-line SIMD.
                let mut nx = [[0.0; LANES]; N];
                for r in 0..N {
                    let mut acc = x[r];
                    if r > 0 {
                        for l in 0..LANES {
                            acc[l] = sub[r] * x[r - 1][l] + x[r][l];
                        }
                    }
                    if r + 1 < N && sup[r] != 0.0 {
                        for l in 0..LANES {
                            acc[l] += sup[r] * x[r + 1][l];
                        }
                    }
                    for l in 0..LANES {
                        acc[l] += b1[r] * ut[l];
                        nx[r][l] = acc[l] + if p[l] { b2[r] } else { -b2[r] };
                    }
                }
                x = nx;
                for l in 0..LANES {
                    // A plain compare-select (maxpd); NaN is caught at the block end.
                    let a = x[N - 1][l].abs();
                    peak[l] = if a > peak[l] { a } else { peak[l] };
                }
            }
            // The last state is tracked every sample (a run-away drives the quantiser
            // input first); all states are checked at the block end.
            for row in x.iter() {
                for l in 0..LANES {
                    peak[l] = peak[l].max(row[l].abs());
                    if row[l].is_nan() {
                        peak[l] = f64::NAN;
                    }
                }
            }
            for l in 0..LANES {
                // NaN never compares greater: catch it explicitly.
                let bad = peak[l] > STATE_BOUND || peak[l].is_nan();
                if bad && !strict {
                    ok[l] = false;
                    self.probes[l].amplitude = 0.0;
                    for row in x.iter_mut() {
                        row[l] = 0.0;
                    }
                } else if bad {
                    return Err(DspError::Unstable {
                        amplitude: self.probes[l].amplitude,
                        sample: n,
                        state: peak[l],
                        bound: STATE_BOUND,
                        hint: format!(
                            "; bin {} ({}) of a period of {} pulses",
                            self.probes[l].bin,
                            if self.probes[l].quadrature { "Q" } else { "I" },
                            self.period
                        ),
                    });
                }
            }
            done += len;
        }
        for (r, row) in x.iter().enumerate() {
            self.states[r] = *row;
        }
        Ok(ok)
    }
}

/// Packs the lanes' 0/1 bytes into a word (bit l = lane l), eight at a time: the multiply
/// moves byte i's bit to bit 56 + i of the product (no carries: each byte is 0 or 1).
#[inline]
fn gather_bits(pos: &[u8; LANES]) -> u16 {
    let mut out = 0u16;
    for (c, chunk) in pos.chunks(8).enumerate() {
        let mut b = [0u8; 8];
        b[..chunk.len()].copy_from_slice(chunk);
        let m = u64::from_le_bytes(b).wrapping_mul(0x0102_0408_1020_4080) >> 56;
        out |= (m as u16) << (8 * c);
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn gather_bits_puts_lane_l_at_bit_l() {
        for l in 0..LANES {
            let mut pos = [0u8; LANES];
            pos[l] = 1;
            assert_eq!(gather_bits(&pos), 1 << l);
        }
        assert_eq!(gather_bits(&[1; LANES]) as u32, (1u32 << LANES) - 1);
    }

    use super::*;
    use crate::sd::modulator::Modulator;

    /// The rotator inputs must equal directly computed A·w·cos/sin: re-anchoring every
    /// ANCHOR samples keeps the recurrence's rounding to ≈ ANCHOR·ε ≈ 1e-13.
    #[test]
    fn rotator_inputs_match_direct_trig() {
        let len = 5000usize;
        let probes = [
            LaneProbe {
                bin: 17,
                quadrature: false,
                amplitude: 0.5,
            },
            LaneProbe {
                bin: 17,
                quadrature: true,
                amplitude: 0.5,
            },
            LaneProbe {
                bin: 2400,
                quadrature: true,
                amplitude: 0.7,
            },
        ];
        let g = LaneGroup::new(&probes, len as u64, Window::Blackman, 3);
        let mut u = vec![[0.0; LANES]; ANCHOR];
        for n0 in (0..len).step_by(ANCHOR) {
            let m = (len - n0).min(ANCHOR);
            g.inputs(n0 as u64, &mut u[..m]);
            for (t, row) in u[..m].iter().enumerate() {
                let n = n0 + t;
                for (i, p) in probes.iter().enumerate() {
                    let th = 2.0 * PI * p.bin as f64 * n as f64 / len as f64;
                    let c = if p.quadrature { th.sin() } else { th.cos() };
                    let want = p.amplitude * Window::Blackman.value(n, len) * c;
                    assert!((row[i] - want).abs() < 1e-11, "n {n} lane {i}");
                }
                assert_eq!(row[LANES - 1], 0.0);
            }
        }
    }

    /// Under the toolbox convention the samples are the toolbox's formula, written here
    /// independently: A·w[n]·cos/sin(2π·(kn mod N)/N) with the textbook symmetric
    /// Blackman 0.42 − 0.5cos(2πn/(N−1)) + 0.08cos(4πn/(N−1)). The generator evaluates
    /// numpy's centred form of the same window, so the two agree to the window's few ulps
    /// (≤ 1.5e-15, see `window::tests`) × A ≤ 0.7, not bit for bit; sin(0) is exactly 0,
    /// so Q starts at exactly 0, where tofprobe's cos(−π/2) leaves ≈ −4e-34.
    #[test]
    fn toolbox_inputs_are_the_toolbox_formula() {
        let len = 3000usize;
        let probes = [
            LaneProbe {
                bin: 17,
                quadrature: false,
                amplitude: 0.5,
            },
            LaneProbe {
                bin: 17,
                quadrature: true,
                amplitude: 0.5,
            },
            LaneProbe {
                bin: 1499,
                quadrature: true,
                amplitude: 0.7,
            },
        ];
        let g = LaneGroup::new(&probes, len as u64, Window::Blackman, 3)
            .with_convention(ProbeConvention::Toolbox);
        let mut u = vec![[0.0; LANES]; ANCHOR];
        let d = (len - 1) as f64;
        for n0 in (0..len).step_by(ANCHOR) {
            let m = (len - n0).min(ANCHOR);
            g.inputs(n0 as u64, &mut u[..m]);
            for (t, row) in u[..m].iter().enumerate() {
                let n = n0 + t;
                let x = 2.0 * PI * n as f64 / d;
                let w = 0.42 - 0.5 * x.cos() + 0.08 * (2.0 * x).cos();
                for (i, p) in probes.iter().enumerate() {
                    let th = 2.0 * PI * ((p.bin * n as u64) % len as u64) as f64 / len as f64;
                    let c = if p.quadrature { th.sin() } else { th.cos() };
                    let want = p.amplitude * w * c;
                    assert!(
                        (row[i] - want).abs() < 1.1e-15,
                        "n {n} lane {i}: {} vs {want}",
                        row[i]
                    );
                }
            }
        }
        g.inputs(0, &mut u[..1]);
        assert_eq!(u[0][1], 0.0, "toolbox Q starts at exactly 0");
        // tofprobe's convention: the periodic window and cos(θ − π/2), ≈ −4e-34 at n = 0.
        let ours = LaneGroup::new(&probes, len as u64, Window::Blackman, 3);
        ours.inputs(0, &mut u[..1]);
        assert!(u[0][1] != 0.0 && u[0][1].abs() < 1e-33, "{}", u[0][1]);
    }

    /// The interleaved loop must produce exactly the scalar reference modulator's bits
    /// when both see the same input (same arithmetic order, so no rounding difference).
    #[test]
    fn interleaved_matches_scalar_reference() {
        let m = Modulator::design(4, 16.0, true, 1.5).unwrap();
        let len = 20_000usize;
        let probes: Vec<LaneProbe> = (0..LANES)
            .map(|i| LaneProbe {
                bin: 3 + 41 * (i as u64 / 2),
                quadrature: i % 2 == 1,
                amplitude: 0.45,
            })
            .collect();
        let mut g = LaneGroup::new(&probes, len as u64, Window::Hann, 4);
        let mut out = vec![0u16; len];
        g.run(&m.ss, 0, &mut out).unwrap();
        let mut u = vec![[0.0; LANES]; len];
        for n0 in (0..len).step_by(ANCHOR) {
            let e = (n0 + ANCHOR).min(len);
            g.inputs(n0 as u64, &mut u[n0..e]);
        }
        for i in 0..LANES {
            let ui: Vec<f64> = u.iter().map(|r| r[i]).collect();
            let mut v = vec![0.0; len];
            m.run(&ui, &mut m.zero_state(), &mut v, 0.45, 0).unwrap();
            for n in 0..len {
                assert_eq!((out[n] >> i) & 1 == 1, v[n] > 0.0, "lane {i} sample {n}");
            }
        }
    }
}
