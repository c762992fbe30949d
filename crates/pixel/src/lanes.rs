//! The lane driver (issue 28): up to [`LANES`] pixels of an array folded at once.
//!
//! One pixel's folded driver ([`crate::fold`]) is bound by its prefilter, a serial chain
//! from pulse to pulse. The pixels of an array are independent and read the same ROM
//! address for the same pulse (pulse n reads n mod L in every pixel), so [`FoldLanes`] runs
//! [`LANES`] pixels side by side: the front-end state of each pixel in a lane of
//! `[i64; LANES]` arrays, the phase sums laid out [L_v][LANES] (pulse n adds the lanes'
//! operands into one row), the step written on plain arrays the compiler vectorises (an
//! AVX-512 or AVX2 copy chosen at run time by the workspace's ISA, `tofprobe_io::isa`, the
//! scalar copy elsewhere: the same integer operations, bit-identical). Each lane computes exactly the folded driver's
//! arithmetic ([`crate::datapath::FourierStream`]), so each pixel's readout is the one
//! [`crate::FrameDriver`] gives it alone (crates/pixel/tests/it/lanes.rs checks them
//! against the transaction driver).
//!
//! Priming (nothing accumulates before a pixel's first detection) is per pixel: a run
//! steps the pixels singly (the datapath's own [`Datapath::fourier_pulse`]) up to the
//! latest first detection among its pixels, then runs them in lockstep. A pixel with no
//! detection in the whole run (and not primed before it) keeps its state and contributes
//! nothing: its lane is masked.

use tofprobe_dsp::RomImage;
use tofprobe_io::isa::Isa;

use crate::datapath::{Datapath, StepConsts};
use crate::detections::{Detections, NO_DETECTION};
use crate::error::PixelError;
use crate::fold::{check_fold, fold_registers, virtual_depth};
use crate::params::PixelParams;
use crate::readout::Readout;

/// Pixels per lane group (eight `i64` lanes: one AVX-512 register per state word).
pub const LANES: usize = 8;
/// Pulses per block of the lockstep loop (the lanes' codes are transposed a block at a
/// time into rows of [`LANES`]).
const BLOCK: usize = 64;

/// The front-end state (t, x, u) of the lanes ([`crate::datapath::FourierStream`]'s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct LaneState {
    pub target: [i64; LANES],
    pub x: [i64; LANES],
    pub u: [i64; LANES],
}

/// Up to [`LANES`] folded pixels of the same parameters and ROM, run in lockstep.
#[derive(Debug, Clone)]
pub struct FoldLanes<'rom> {
    params: PixelParams,
    rom: &'rom RomImage,
    dps: Vec<Datapath>,
    /// Row p: the lanes' Σ xₙ over n ≡ p (mod L_v), wrapping.
    phases: Vec<[i64; LANES]>,
    pcount: u64,
}

impl<'rom> FoldLanes<'rom> {
    /// `lanes` pixels (1 ..= [`LANES`]) just out of reset. Fails as
    /// [`crate::FoldModel::new`] does (a Fourier pixel, L ≤ [`crate::fold::MAX_FOLD_DEPTH`],
    /// a ROM that fits), or if `lanes` is out of range.
    pub fn new(
        params: &PixelParams,
        rom: &'rom RomImage,
        lanes: usize,
    ) -> Result<Self, PixelError> {
        let rom = check_fold(params, rom)?;
        if !(1..=LANES).contains(&lanes) {
            return Err(PixelError::mismatch(
                "lane driver's pixels",
                lanes,
                format!("1 ..= {LANES}"),
            ));
        }
        Ok(FoldLanes {
            params: params.clone(),
            rom,
            dps: vec![Datapath::new(params); lanes],
            phases: vec![[0; LANES]; virtual_depth(params.rom_depth)],
            pcount: 0,
        })
    }

    /// The number of pixels.
    pub fn lanes(&self) -> usize {
        self.dps.len()
    }

    /// Pulses run since the last readout (each pixel).
    pub fn pulses_in_frame(&self) -> u64 {
        self.pcount
    }

    /// Runs the same pulses of every pixel: pixel j reads `streams[j]`, pulse i ROM
    /// address (`first_address` + i) mod L, as [`crate::FoldModel::run`] for each alone.
    /// Fails unless there is one stream per pixel, all of the same length.
    pub fn run<D: Detections + ?Sized>(
        &mut self,
        streams: &[&D],
        first_address: u64,
    ) -> Result<(), PixelError> {
        let lanes = self.dps.len();
        if streams.len() != lanes {
            return Err(PixelError::mismatch(
                "lane driver's streams",
                streams.len(),
                format!("one per pixel, {lanes}"),
            ));
        }
        let n = streams[0].len();
        if let Some(s) = streams.iter().find(|s| s.len() != n) {
            return Err(PixelError::mismatch(
                "lane driver's stream length",
                s.len(),
                format!("the first stream's, {n} pulses"),
            ));
        }
        let depth = self.phases.len();
        let addr0 = (first_address % depth as u64) as usize;
        // Which pixels run in lockstep, and from which pulse on: every pixel primed by then.
        let mut live = [false; LANES];
        let mut start = 0usize;
        for (j, (dp, s)) in self.dps.iter().zip(streams).enumerate() {
            if dp.primed() {
                live[j] = true;
            } else if let Some(f) = (0..n).find(|&i| s.get(i).is_some()) {
                live[j] = true;
                start = start.max(f + 1);
            }
        }
        // Singly up to `start`: the datapath pulse by pulse, each operand into its row.
        for (j, (dp, s)) in self.dps.iter_mut().zip(streams).enumerate() {
            if !live[j] {
                continue;
            }
            let mut addr = addr0;
            for i in 0..start {
                let d = s.get(i);
                if let Some(op) = dp.fourier_pulse(d.is_some(), d.unwrap_or(0), None) {
                    let cell = &mut self.phases[addr][j];
                    *cell = cell.wrapping_add(op);
                }
                addr += 1;
                if addr == depth {
                    addr = 0;
                }
            }
        }
        if start < n && live.contains(&true) {
            self.lockstep(streams, &live, start, (addr0 + start) % depth);
        }
        self.pcount += n as u64;
        Ok(())
    }

    /// Pulses `start ..` of the live pixels in lockstep (all primed), pulse `start` at
    /// phase `addr`.
    fn lockstep<D: Detections + ?Sized>(
        &mut self,
        streams: &[&D],
        live: &[bool; LANES],
        start: usize,
        addr: usize,
    ) {
        let mut st = LaneState::default();
        let mut keep = [0i64; LANES];
        let mut consts = None;
        let mut fronts = Vec::with_capacity(self.dps.len());
        for (j, dp) in self.dps.iter().enumerate() {
            let front = if live[j] { dp.stream() } else { None };
            if let Some(f) = &front {
                (st.target[j], st.x[j], st.u[j]) = f.state();
                keep[j] = -1;
                consts = Some(f.consts());
            }
            fronts.push(front);
        }
        let Some(k) = consts else { return };
        let ctx = Lockstep {
            k,
            keep,
            start,
            addr,
        };
        run_lockstep(&ctx, streams, &mut self.phases, &mut st);
        let n = streams[0].len();
        for (j, (dp, front)) in self.dps.iter_mut().zip(fronts).enumerate() {
            if let Some(mut f) = front {
                let last = streams[j].last_detection(start, n);
                f.set_state((st.target[j], st.x[j], st.u[j]), last);
                dp.end_stream(f);
            }
        }
    }

    /// Reads the frame out: one readout per pixel (registers sign-extended from W bits, no
    /// refusals: the folded pixel never refuses), the registers cleared; the depth tracking
    /// continues across frames, as in the hardware.
    pub fn readout(&mut self) -> Vec<Readout> {
        let out = (0..self.dps.len())
            .map(|j| Readout {
                words: fold_registers(&self.params, self.rom, self.phases.iter().map(|r| r[j])),
                refused: 0,
            })
            .collect();
        self.phases.iter_mut().for_each(|r| *r = [0; LANES]);
        self.pcount = 0;
        out
    }
}

/// The constants of one lockstep run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lockstep {
    pub k: StepConsts,
    /// −1 for a live lane, 0 for a masked one (its operands are not added).
    pub keep: [i64; LANES],
    pub start: usize,
    pub addr: usize,
}

/// The lockstep loop on the workspace's ISA ([`Isa::current`]). Also the segmented
/// driver's ([`crate::segments`]: the lanes are segments of one pixel's run).
pub(crate) fn run_lockstep<D: Detections + ?Sized>(
    ctx: &Lockstep,
    streams: &[&D],
    phases: &mut [[i64; LANES]],
    st: &mut LaneState,
) {
    run_lockstep_on(Isa::current(), ctx, streams, phases, st);
}

/// The lockstep loop on `isa`: the AVX-512 or AVX2 copy where asked for and the CPU has
/// it (the same integer operations on the same arrays: bit-identical), the scalar copy
/// otherwise.
pub(crate) fn run_lockstep_on<D: Detections + ?Sized>(
    isa: Isa,
    ctx: &Lockstep,
    streams: &[&D],
    phases: &mut [[i64; LANES]],
    st: &mut LaneState,
) {
    #[cfg(target_arch = "x86_64")]
    if isa != Isa::Scalar && isa.available() {
        // SAFETY: the CPU has the path's features (`available`, checked above), the one
        // requirement of `lockstep_avx512` / `lockstep_avx2`.
        #[allow(unsafe_code)]
        unsafe {
            return match isa {
                Isa::Avx512 => lockstep_avx512(ctx, streams, phases, st),
                _ => lockstep_avx2(ctx, streams, phases, st),
            };
        }
    }
    let _ = isa;
    lockstep_body(ctx, streams, phases, st);
}

/// [`lockstep_body`] compiled for AVX-512 (the eight lanes of a state word in one
/// register, 64-bit arithmetic shifts in vectors).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
fn lockstep_avx512<D: Detections + ?Sized>(
    ctx: &Lockstep,
    streams: &[&D],
    phases: &mut [[i64; LANES]],
    st: &mut LaneState,
) {
    lockstep_body(ctx, streams, phases, st);
}

/// [`lockstep_body`] compiled for AVX2 (a state word in two registers; the 64-bit
/// arithmetic shift, which AVX2 lacks, is a logical shift and a sign fix: exact).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn lockstep_avx2<D: Detections + ?Sized>(
    ctx: &Lockstep,
    streams: &[&D],
    phases: &mut [[i64; LANES]],
    st: &mut LaneState,
) {
    lockstep_body(ctx, streams, phases, st);
}

#[inline(always)]
pub(crate) fn lockstep_body<D: Detections + ?Sized>(
    ctx: &Lockstep,
    streams: &[&D],
    phases: &mut [[i64; LANES]],
    st: &mut LaneState,
) {
    let depth = phases.len();
    let n = streams[0].len();
    let (mut pos, mut addr) = (ctx.start, ctx.addr);
    // Masked lanes read "no detection" throughout.
    static DARK: [u32; BLOCK] = [NO_DETECTION; BLOCK];
    let mut rows = [[NO_DETECTION; LANES]; BLOCK];
    let mut bufs = [[0u32; BLOCK]; LANES];
    while pos < n {
        let len = (depth - addr).min(n - pos);
        for (b, cells) in phases[addr..addr + len].chunks_mut(BLOCK).enumerate() {
            let first = pos + b * BLOCK;
            let m = cells.len();
            let mut cols: [&[u32]; LANES] = [&DARK[..m]; LANES];
            for (j, (s, buf)) in streams.iter().zip(bufs.iter_mut()).enumerate() {
                if ctx.keep[j] != 0 {
                    cols[j] = s.codes(first, m, buf);
                }
            }
            transpose(&cols, &mut rows[..m]);
            if ctx.k.register_shift == 0 {
                step::<false>(&rows[..m], cells, &ctx.k, &ctx.keep, st);
            } else {
                step::<true>(&rows[..m], cells, &ctx.k, &ctx.keep, st);
            }
        }
        pos += len;
        addr += len;
        if addr == depth {
            addr = 0;
        }
    }
}

/// `rows[i][j] = cols[j][i]`: the lanes' codes, one row per pulse. Whole 8 × 8 tiles
/// (the compiler makes them register shuffles; lane by lane it scatters), the rest singly.
#[inline(always)]
fn transpose(cols: &[&[u32]; LANES], rows: &mut [[u32; LANES]]) {
    let done = rows.len() / 8 * 8;
    let mut tiles = rows.chunks_exact_mut(8);
    for (t, tile) in (&mut tiles).enumerate() {
        let src: [[u32; 8]; LANES] =
            std::array::from_fn(|j| cols[j][8 * t..8 * t + 8].try_into().expect("8 codes"));
        for (i, row) in tile.iter_mut().enumerate() {
            *row = std::array::from_fn(|j| src[j][i]);
        }
    }
    for (i, row) in tiles.into_remainder().iter_mut().enumerate() {
        let i = done + i;
        *row = std::array::from_fn(|j| cols[j][i]);
    }
}

/// [`crate::datapath::FourierStream`]'s step in every lane: per pulse the prefilter steps
/// towards the held target, the hold takes the pulse's code, the operand goes into the
/// pulse's row (masked lanes add 0).
#[inline(always)]
fn step<const SHIFTS: bool>(
    rows: &[[u32; LANES]],
    cells: &mut [[i64; LANES]],
    k: &StepConsts,
    keep: &[i64; LANES],
    st: &mut LaneState,
) {
    let LaneState {
        mut target,
        mut x,
        mut u,
    } = *st;
    for (cell, c) in cells.iter_mut().zip(rows) {
        for j in 0..LANES {
            let t = (i64::from(c[j] & k.mask) << k.frac_bits) + k.offset;
            let next = if c[j] != NO_DETECTION { t } else { target[j] };
            let s = u[j] >> k.shift;
            let v = u[j] + (next - target[j]);
            u[j] = v - s;
            x[j] = (next - v) + s;
            let op = if SHIFTS {
                x[j] >> k.register_shift
            } else {
                x[j]
            };
            cell[j] = cell[j].wrapping_add(op & keep[j]);
            target[j] = next;
        }
    }
    *st = LaneState { target, x, u };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every copy the CPU runs (AVX2, AVX-512) and the scalar copy give the same phase sums and states, bit for bit, with and without the operand shift, one
    /// lane masked (a reordered or widened operation would move some sums).
    #[test]
    fn every_copy_of_the_lockstep_is_bit_identical() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let n = 3000;
        let streams: Vec<Vec<u32>> = (0..LANES)
            .map(|_| {
                (0..n)
                    .map(|_| match next() % 10 {
                        0 => NO_DETECTION,
                        r => (r * 977 % 300) as u32,
                    })
                    .collect()
            })
            .collect();
        let refs: Vec<&[u32]> = streams.iter().map(Vec::as_slice).collect();
        for register_shift in [0, 3] {
            let mut keep = [-1i64; LANES];
            keep[5] = 0;
            let ctx = Lockstep {
                k: StepConsts {
                    mask: 0xff,
                    frac_bits: 6,
                    offset: 16 - (40 << 6),
                    shift: 5,
                    register_shift,
                },
                keep,
                start: 7,
                addr: 250,
            };
            let start = LaneState {
                target: std::array::from_fn(|j| (j as i64) << 9),
                x: std::array::from_fn(|j| -(j as i64) * 77),
                u: std::array::from_fn(|j| (j as i64) * 31 - 100),
            };
            let mut b = vec![[0i64; LANES]; 1024];
            let mut sb = start;
            run_lockstep_on(Isa::Scalar, &ctx, &refs, &mut b, &mut sb);
            let mut a = b.clone();
            for isa in Isa::vector_paths_to_test() {
                a = vec![[0i64; LANES]; 1024];
                let mut sa = start;
                run_lockstep_on(isa, &ctx, &refs, &mut a, &mut sa);
                assert_eq!(a, b, "{}", isa.name());
                assert_eq!((sa.target, sa.x, sa.u), (sb.target, sb.x, sb.u));
            }
            assert!(a.iter().all(|r| r[5] == 0) && a.iter().any(|r| r[0] != 0));
        }
    }
}
