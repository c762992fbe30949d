//! The segmented driver (issue 28): one pixel's folded run cut into [`LANES`] time segments
//! that run side by side as the lanes of the lane driver's step ([`crate::lanes`], its
//! AVX-512 copy where the CPU has it), then repaired exactly.
//!
//! The folded driver ([`crate::fold`]) is bound by the front end's loop-carried chain (the
//! prefilter, one pulse after the other). Here a primed run of M pulses is cut into eight
//! segments of m pulses (the < 8·m rest, and runs too short to pay, go through the fold):
//!
//! - Lane 0 starts from the pixel's true front-end state; lane j ≥ 1 from a *guess* (the
//!   target of the last detection shortly before its segment, x on it). All eight run the
//!   lane step in lockstep, each adding its operands into its column of `[L_v][LANES]`
//!   rows. Lane j's pulse i has phase a + j·m + i; it writes row a + i, so column j is
//!   rotated by j·m ≡ j·D (mod L_v): every run of a frame takes m ≡ D, D fixed by the
//!   frame's first segmented run, and the readout adds column j's row r into phase
//!   r + j·D.
//! - The repair, segment after segment: the true state at segment j's start is the true
//!   state at segment j−1's end. The true chain and the guessed chain are stepped again
//!   from there, pulse by pulse (the datapath's own step), each pulse's operand difference
//!   added into its phase sum, until the two states are equal: the front end is a function
//!   of its state and the pulse, so from there on the lane computed the true operands, and
//!   its end state is the true one. A segment whose chains never meet is recomputed whole
//!   (its true end state is the repaired chain's): exact either way, slower.
//!
//! Why they meet: the state is (t, x) (u = t − x); t is the held target, equal in both after
//! the segment's first detection; then x ↦ x + ((t − x) >>> S) is monotone and does not
//! expand distances, and the floor drops a unit of the difference whenever the two x fall
//! on either side of a step of the shift: the difference shrinks by ≈ 2^−S a pulse, then
//! by units, a few hundred pulses at S = 5 ([`SegmentedModel::repaired_pulses`] counts
//! them; [`segments_pay`] leaves slow prefilters, large S, to the fold).
//!
//! All sums are 64-bit wrapping and reduced to W bits at the readout (exact modulo 2^W), so
//! the registers are bit-identical to [`crate::TransactionModel`]'s
//! (crates/pixel/tests/it/segments.rs).

use tofprobe_dsp::RomImage;

use crate::datapath::{STREAM_BLOCK, StepConsts, step};
use crate::detections::{Detections, Window};
use crate::error::PixelError;
use crate::fold::{FoldModel, fold_pays, fold_registers};
use crate::lanes::{LANES, LaneState, Lockstep, run_lockstep};
use crate::params::PixelParams;
use crate::readout::Readout;

/// Shortest segment the driver cuts by default: a segment's repair costs a few hundred
/// pulses of two chains (S = 5), small beside m.
pub const MIN_SEGMENT_PULSES: usize = 4096;
/// Largest prefilter shift S the segmented driver is chosen for: the chains meet after
/// ≈ 2^S·ln(difference) pulses, which at larger S is a large part of a segment.
pub const MAX_SEGMENT_SHIFT: u32 = 8;
/// How far back a lane looks for the detection its guessed target is made of.
const GUESS_LOOKBACK: usize = 64;

/// The front end's loop-carried state (t, x, u) ([`crate::datapath::FourierStream`]'s).
type State = (i64, i64, i64);

/// Whether [`crate::FrameDriver`] runs the segmented driver for `params`: the fold pays
/// ([`fold_pays`]), S ≤ [`MAX_SEGMENT_SHIFT`], and a frame holds at least [`LANES`]
/// segments of [`MIN_SEGMENT_PULSES`].
pub fn segments_pay(params: &PixelParams) -> bool {
    fold_pays(params)
        && params.shift <= MAX_SEGMENT_SHIFT
        && params.frame_pulses >= (LANES * MIN_SEGMENT_PULSES) as u64
}

/// The segmented pixel: the folded driver (priming, short runs, the rest of a run and the
/// repairs' corrections go into its phase sums) and the lanes' rotated rows.
#[derive(Debug, Clone)]
pub struct SegmentedModel<'rom> {
    fold: FoldModel<'rom>,
    /// Row r, column j: lane j's operands at phase (r + j·D) mod L_v, wrapping.
    rows: Vec<[i64; LANES]>,
    /// D (mod L_v): set by the frame's first segmented run, cleared by the readout.
    stride: Option<usize>,
    min_segment: usize,
    /// Pulses stepped again by the repairs since the pixel was made.
    repaired: u64,
    /// Most pulses a repair steps (the segment: exact). Lowered only by the unit test
    /// that shows a repair stopped early is caught.
    repair_limit: usize,
}

impl<'rom> SegmentedModel<'rom> {
    /// A pixel just out of reset, segments of at least [`MIN_SEGMENT_PULSES`]. Fails as
    /// [`FoldModel::new`] does.
    pub fn new(params: &PixelParams, rom: &'rom RomImage) -> Result<Self, PixelError> {
        Self::with_min_segment(params, rom, MIN_SEGMENT_PULSES)
    }

    /// A pixel that cuts runs into segments of at least `min_segment` pulses (≥ 1; the
    /// tests cut short runs to reach every path). Fails as [`FoldModel::new`] does, or if
    /// `min_segment` is 0.
    pub fn with_min_segment(
        params: &PixelParams,
        rom: &'rom RomImage,
        min_segment: usize,
    ) -> Result<Self, PixelError> {
        let fold = FoldModel::new(params, rom)?;
        if min_segment == 0 {
            return Err(PixelError::mismatch(
                "segmented driver's shortest segment",
                min_segment,
                "≥ 1 pulse",
            ));
        }
        Ok(SegmentedModel {
            rows: vec![[0; LANES]; fold.phases().len()],
            fold,
            stride: None,
            min_segment,
            repaired: 0,
            repair_limit: usize::MAX,
        })
    }

    /// Pulses run since the last readout.
    pub fn pulses_in_frame(&self) -> u64 {
        self.fold.pulses_in_frame()
    }

    /// Pulses the repairs have stepped again (true and guessed chain) since reset.
    pub fn repaired_pulses(&self) -> u64 {
        self.repaired
    }

    /// Runs many pulses: pulse i reads ROM address (`first_address` + i) mod L, as
    /// [`crate::TransactionModel::run`] (same registers at the next readout).
    pub fn run<D: Detections + ?Sized>(&mut self, detections: &D, first_address: u64) {
        let total = detections.len();
        let depth = self.rows.len();
        let addr0 = (first_address % depth as u64) as usize;
        let mut pos = 0;
        if !self.fold.primed() {
            // Up to the first detection nothing accumulates: the fold steps it singly.
            let upto = (0..total)
                .find(|&i| detections.get(i).is_some())
                .map_or(total, |f| f + 1);
            self.fold
                .run(&Window::new(detections, 0..upto), addr0 as u64);
            pos = upto;
        }
        if let Some(m) = self.segment_len(total - pos) {
            self.segments(detections, pos, m, (addr0 + pos) % depth);
            pos += LANES * m;
        }
        if pos < total {
            let addr = ((addr0 + pos) % depth) as u64;
            self.fold.run(&Window::new(detections, pos..total), addr);
        }
    }

    /// The segment length for a primed run of `pulses`: the longest m ≡ D (mod L_v) with
    /// [`LANES`]·m ≤ `pulses` and m ≥ the shortest segment (D set here when unset).
    fn segment_len(&mut self, pulses: usize) -> Option<usize> {
        let depth = self.rows.len();
        let m = pulses / LANES;
        let m = match self.stride {
            None => m,
            Some(d) => {
                let r = m % depth;
                m.checked_sub(if r >= d { r - d } else { r + depth - d })?
            }
        };
        if m < self.min_segment {
            return None;
        }
        self.stride = Some(m % depth);
        Some(m)
    }

    /// Pulses `pos .. pos + LANES·m` (primed) as eight segments in lockstep, repaired;
    /// pulse `pos` at phase `addr`.
    fn segments<D: Detections + ?Sized>(
        &mut self,
        detections: &D,
        pos: usize,
        m: usize,
        addr: usize,
    ) {
        let depth = self.rows.len();
        let mut front = self
            .fold
            .datapath_mut()
            .stream()
            .expect("a primed Fourier pixel streams");
        let k = front.consts();
        let mut st = LaneState::default();
        for j in 0..LANES {
            let (t, x, u) = if j == 0 {
                front.state()
            } else {
                let start = pos + j * m;
                let from = start.saturating_sub(GUESS_LOOKBACK).max(pos);
                detections
                    .last_detection(from, start)
                    .map_or(front.state(), |c| guess(c, &k))
            };
            (st.target[j], st.x[j], st.u[j]) = (t, x, u);
        }
        let guesses = st;
        let windows: [Window<'_, D>; LANES] =
            std::array::from_fn(|j| Window::new(detections, pos + j * m..pos + (j + 1) * m));
        let streams: [&Window<'_, D>; LANES] = std::array::from_fn(|j| &windows[j]);
        let ctx = Lockstep {
            k,
            keep: [-1; LANES],
            start: 0,
            addr,
        };
        run_lockstep(&ctx, &streams, &mut self.rows, &mut st);
        // Lane 0 started true: its end is true. Each next segment starts from it.
        let mut truth = (st.target[0], st.x[0], st.u[0]);
        for (j, segment) in windows.iter().enumerate().skip(1) {
            let guessed = (guesses.target[j], guesses.x[j], guesses.u[j]);
            let phase = (addr + j * m) % depth;
            truth = self.repair(segment, phase, truth, guessed, &k).unwrap_or((
                st.target[j],
                st.x[j],
                st.u[j],
            ));
        }
        front.set_state(truth, detections.last_detection(pos, pos + LANES * m));
        self.fold.datapath_mut().end_stream(front);
        self.fold.count_pulses((LANES * m) as u64);
    }

    /// Steps a segment's true chain (from `truth`) and its lane's guessed chain (from
    /// `guessed`) side by side, adding each pulse's operand difference into its phase sum
    /// (the segment's first pulse at `phase`), until the two states are equal: then `None`
    /// (the lane's end state is true). `Some(true end state)` if they never meet.
    fn repair<D: Detections + ?Sized>(
        &mut self,
        segment: &Window<'_, D>,
        phase: usize,
        mut truth: State,
        mut guessed: State,
        k: &StepConsts,
    ) -> Option<State> {
        let phases = self.fold.phases_mut();
        let depth = phases.len();
        let m = segment.len();
        let mut p = phase;
        let mut buf = [0u32; STREAM_BLOCK];
        let mut i = 0;
        while i < m {
            let n = (m - i).min(STREAM_BLOCK);
            for &c in segment.codes(i, n, &mut buf) {
                if truth == guessed || i == self.repair_limit {
                    self.repaired += i as u64;
                    return None;
                }
                let d = one_step(&mut truth, c, k).wrapping_sub(one_step(&mut guessed, c, k));
                phases[p] = phases[p].wrapping_add(d);
                p += 1;
                if p == depth {
                    p = 0;
                }
                i += 1;
            }
        }
        self.repaired += m as u64;
        Some(truth)
    }

    /// The phase sums: the fold's plus each lane's column, unrotated.
    fn merged_phases(&self) -> Vec<i64> {
        let mut phases = self.fold.phases().to_vec();
        if let Some(d) = self.stride {
            add_columns(&mut phases, &self.rows, d);
        }
        phases
    }

    /// The register file as it stands (each value sign-extended from W bits).
    pub fn registers(&self) -> Vec<i64> {
        fold_registers(
            self.fold.params(),
            self.fold.rom(),
            self.merged_phases().into_iter(),
        )
    }

    /// Reads the frame out and clears the registers and the frame counters (the depth
    /// tracking continues across frames, as in the hardware).
    pub fn readout(&mut self) -> Readout {
        if let Some(d) = self.stride.take() {
            add_columns(self.fold.phases_mut(), &self.rows, d);
            self.rows.iter_mut().for_each(|r| *r = [0; LANES]);
        }
        self.fold.readout()
    }
}

/// Adds column j of `rows` (rotated by j·`stride` phases) into `phases`, wrapping.
fn add_columns(phases: &mut [i64], rows: &[[i64; LANES]], stride: usize) {
    let depth = phases.len();
    for j in 0..LANES {
        let off = j * stride % depth;
        for (r, row) in rows.iter().enumerate() {
            let p = if r + off >= depth {
                r + off - depth
            } else {
                r + off
            };
            phases[p] = phases[p].wrapping_add(row[j]);
        }
    }
}

/// A guessed primed state from detection code `c`: its target, x on it.
fn guess(c: u32, k: &StepConsts) -> State {
    let t = (i64::from(c & k.mask) << k.frac_bits) + k.offset;
    (t, t, 0)
}

/// One pulse of the datapath's stream step ([`crate::datapath::FourierStream`]'s, the
/// same function): the state advanced, the pulse's operand returned.
#[inline(always)]
fn one_step(state: &mut State, c: u32, k: &StepConsts) -> i64 {
    let mut cell = [0i64];
    if k.register_shift == 0 {
        step::<false>(&[c], &mut cell, k, state);
    } else {
        step::<true>(&[c], &mut cell, k, state);
    }
    cell[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TransactionModel;
    use crate::detections::NO_DETECTION;

    fn codes(n: usize, seed: u64) -> Vec<u32> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                if s.is_multiple_of(7) {
                    NO_DETECTION
                } else {
                    ((s >> 8) % 200) as u32
                }
            })
            .collect()
    }

    /// A repair stopped after two pulses (before the chains meet) moves the registers:
    /// the comparison with the transaction driver catches it, and names the first
    /// register that differs. The exact repair on the same pulses reads out equal.
    #[test]
    fn a_repair_stopped_early_is_caught() {
        let params = PixelParams::fourier_default(30, 40_000, 1000);
        let rom = RomImage::from_fn(1000, params.registers(), |a, r| (a * 7 + r) % 3 == 0);
        let pulses = codes(40_000, 0x1234_5678_9ABC_DEF1);
        let mut tm = TransactionModel::new(&params).unwrap();
        tm.run(&pulses[..], Some(&rom), 0).unwrap();
        let want = tm.readout();
        for (limit, equal) in [(usize::MAX, true), (2, false)] {
            let mut sm = SegmentedModel::with_min_segment(&params, &rom, 1000).unwrap();
            sm.repair_limit = limit;
            sm.run(&pulses[..], 0);
            assert!(sm.repaired_pulses() > 0, "the segments were repaired");
            let got = sm.readout();
            let first = got.words.iter().zip(&want.words).position(|(a, b)| a != b);
            assert_eq!(
                first.is_none(),
                equal,
                "limit {limit}: first differing register {first:?}"
            );
        }
    }

    /// The rotation of the lanes' columns: column j's row r is phase r + j·D.
    #[test]
    fn the_columns_are_unrotated() {
        let mut rows = vec![[0i64; LANES]; 5];
        rows[4][2] = 7;
        rows[0][1] = 3;
        let mut phases = vec![0i64; 5];
        add_columns(&mut phases, &rows, 3);
        // Column 2: 4 + 6 = 10 ≡ 0; column 1: 0 + 3 = 3.
        assert_eq!(phases, [7, 0, 0, 3, 0]);
    }
}
