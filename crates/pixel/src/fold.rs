//! The folded driver of the one datapath (issue 28): a Fourier frame with a periodic ROM.
//!
//! Pulse n reads ROM address n mod L, so register r accumulates
//! Y\[r\] = Σₙ s_r\[n mod L\]·xₙ = Σₚ s_r\[p\]·(Σ_{n ≡ p (mod L)} xₙ)  (mod 2^W):
//! each pulse adds its operand xₙ into one of L *phase sums*, and the ±-signed distribution
//! of the phase sums to the 2B registers happens once, when the registers are read. A frame
//! of N pulses costs N phase adds plus L·⌈R/8⌉ table adds at the readout instead of the
//! transaction driver's N·⌈R/8⌉ table adds ([`fold_pays`] picks between them).
//!
//! The per-pulse front end is the transaction driver's, call for call: [`Datapath::pulse`]
//! until the first detection primes the pixel, then the datapath's primed Fourier front end
//! [`crate::datapath::FourierStream`] (zoom, hold, prefilter, the operand x >>> (F − G)).
//! Only the accumulation is regrouped. All sums are
//! 64-bit wrapping and reduced to W bits at the end, which is exact modulo 2^W (W ≤ 63), so
//! the readout is bit-identical to [`crate::TransactionModel`]'s (crates/pixel/tests/it/fold.rs).
//!
//! Any multiple of L is a period too: short ROMs are folded with a *virtual* depth of L·k
//! ≥ [`MIN_SEGMENT`] phases, so the inner loop runs over long stretches of distinct cells
//! (no wrap test per pulse, no store-to-load chain on one cell).

use tofprobe_dsp::RomImage;

use crate::datapath::Datapath;
use crate::detections::Detections;
use crate::error::PixelError;
use crate::params::{Mode, PixelParams};
use crate::readout::Readout;
use crate::transaction::{check_rom, distribute};

/// Largest ROM depth L the fold takes: its phase sums are 8 bytes each (8 MiB here).
pub const MAX_FOLD_DEPTH: usize = 1 << 20;
/// Smallest number of phase sums: a shorter ROM is folded over a multiple of its depth.
pub const MIN_SEGMENT: usize = 256;

/// Whether the folded driver does fewer adds than the transaction driver for a frame of
/// `params` (N = `frame_pulses`, L = `rom_depth`, R = 2B registers): a Fourier pixel with
/// L ≤ [`MAX_FOLD_DEPTH`] and N + L_v·⌈R/8⌉ < N·⌈R/8⌉, L_v the virtual depth (both
/// drivers run the same front end per pulse; the transaction driver adds each operand into
/// ⌈R/8⌉ byte tables, the fold into one phase sum and the phase sums into the byte tables
/// once per frame). Haar has no ROM: never.
pub fn fold_pays(params: &PixelParams) -> bool {
    if params.mode != Mode::Fourier || params.rom_depth == 0 || params.rom_depth > MAX_FOLD_DEPTH {
        return false;
    }
    let n = u128::from(params.frame_pulses);
    let l = virtual_depth(params.rom_depth) as u128;
    let nbytes = params.registers().div_ceil(8) as u128;
    n + l * nbytes < n * nbytes
}

/// Checks what a folded pixel needs (valid parameters, Fourier, L ≤ [`MAX_FOLD_DEPTH`], a
/// ROM that fits) and returns the ROM.
pub(crate) fn check_fold<'rom>(
    params: &PixelParams,
    rom: &'rom RomImage,
) -> Result<&'rom RomImage, PixelError> {
    params.validate()?;
    if params.mode != Mode::Fourier {
        return Err(PixelError::mismatch(
            "folded driver's pixel mode",
            params.mode,
            "fourier (Haar has no periodic ROM: use the transaction driver)",
        ));
    }
    if params.rom_depth > MAX_FOLD_DEPTH {
        return Err(PixelError::mismatch(
            "folded driver's ROM depth",
            params.rom_depth,
            format!("L ≤ {MAX_FOLD_DEPTH} (use the transaction driver)"),
        ));
    }
    check_rom(params, Some(rom))
}

/// The registers (sign-extended from W bits) of phase sums `phases` (phase p reads ROM
/// address p mod L): each sum added into the byte tables of its ROM entry, then
/// distributed with the ± signs of the entry's bits. Shared by the folded and lane drivers.
pub(crate) fn fold_registers(
    params: &PixelParams,
    rom: &RomImage,
    phases: impl Iterator<Item = i64>,
) -> Vec<i64> {
    let r = params.registers();
    let mut tables = vec![[0i64; 256]; r.div_ceil(8)];
    let wpe = rom.words_per_entry();
    let words = rom.words();
    let depth = rom.depth();
    let mut a = 0usize;
    for s in phases {
        if s != 0 {
            let entry = &words[a * wpe..a * wpe + wpe];
            for (j, table) in tables.iter_mut().enumerate() {
                let byte = (entry[j / 8] >> ((j % 8) * 8)) as u8;
                let cell = &mut table[byte as usize];
                *cell = cell.wrapping_add(s);
            }
        }
        a += 1;
        if a == depth {
            a = 0;
        }
    }
    let mut regs = vec![0; r];
    distribute(&mut tables, &mut regs, params.width);
    regs
}

/// The smallest multiple of `depth` that is at least [`MIN_SEGMENT`] (`depth` ≥ 1).
pub(crate) fn virtual_depth(depth: usize) -> usize {
    depth * MIN_SEGMENT.div_ceil(depth).max(1)
}

/// The folded pixel: the one datapath's front end and L_v phase sums. A Fourier pixel
/// only; it borrows the probe ROM, which the readout needs to distribute the sums.
#[derive(Debug, Clone)]
pub struct FoldModel<'rom> {
    params: PixelParams,
    rom: &'rom RomImage,
    dp: Datapath,
    /// Σ xₙ over the pulses of the frame with n ≡ p (mod L_v), wrapping.
    phases: Vec<i64>,
    pcount: u64,
    refused: u64,
}

impl<'rom> FoldModel<'rom> {
    /// A pixel just out of reset. Fails if the parameters do not validate, if the mode is
    /// not Fourier, if L exceeds [`MAX_FOLD_DEPTH`] or if `rom` does not fit the parameters.
    pub fn new(params: &PixelParams, rom: &'rom RomImage) -> Result<Self, PixelError> {
        let rom = check_fold(params, rom)?;
        Ok(FoldModel {
            params: params.clone(),
            rom,
            dp: Datapath::new(params),
            phases: vec![0; virtual_depth(params.rom_depth)],
            pcount: 0,
            refused: 0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PixelParams {
        &self.params
    }

    /// The held depth (last valid d = tdc − Z; 0 before the first detection).
    pub fn held(&self) -> i64 {
        self.dp.held()
    }

    /// The prefilter state x in units of 2^−F codes.
    pub fn prefilter_state(&self) -> i64 {
        self.dp.prefilter_state()
    }

    /// Whether a first valid detection has been seen since reset.
    pub fn primed(&self) -> bool {
        self.dp.primed()
    }

    /// Pulses run since the last readout.
    pub fn pulses_in_frame(&self) -> u64 {
        self.pcount
    }

    /// Counts a refused pulse strobe (the hardware's saturating counter), as
    /// [`crate::TransactionModel::refuse`].
    pub fn refuse(&mut self) {
        self.refused = (self.refused + 1).min(self.params.refused_max());
    }

    /// Runs many pulses: pulse i reads ROM address (`first_address` + i) mod L, as
    /// [`crate::TransactionModel::run`] (same registers at the next readout).
    pub fn run<D: Detections + ?Sized>(&mut self, detections: &D, first_address: u64) {
        let depth = self.phases.len();
        let total = detections.len();
        // L_v is a multiple of L: address mod L_v names the same ROM entry.
        let mut addr = (first_address % depth as u64) as usize;
        // Until the first detection nothing accumulates (the priming rule): step singly.
        let mut pos = 0usize;
        while !self.dp.primed() && pos < total {
            let det = detections.get(pos);
            self.dp.pulse(det.is_some(), det.unwrap_or(0), None);
            pos += 1;
            addr += 1;
            if addr == depth {
                addr = 0;
            }
        }
        let Some(mut stream) = self.dp.stream() else {
            // Every pulse went into priming and none primed.
            self.pcount += total as u64;
            return;
        };
        while pos < total {
            let len = (depth - addr).min(total - pos);
            // Primed: every pulse adds its operand into its phase sum, in phase order.
            stream.accumulate(detections, pos, &mut self.phases[addr..addr + len]);
            pos += len;
            addr += len;
            if addr == depth {
                addr = 0;
            }
        }
        self.dp.end_stream(stream);
        self.pcount += total as u64;
    }

    /// The datapath (the segmented driver, [`crate::segments`], steps its primed front end
    /// itself and hands the state back).
    pub(crate) fn datapath_mut(&mut self) -> &mut Datapath {
        &mut self.dp
    }

    /// The phase sums (L_v of them, phase p reading ROM address p mod L).
    pub(crate) fn phases(&self) -> &[i64] {
        &self.phases
    }

    /// The phase sums, for the segmented driver's repairs and its lanes' sums.
    pub(crate) fn phases_mut(&mut self) -> &mut [i64] {
        &mut self.phases
    }

    /// Counts `n` pulses the segmented driver ran past this driver's own `run`.
    pub(crate) fn count_pulses(&mut self, n: u64) {
        self.pcount += n;
    }

    /// The ROM the readout distributes the phase sums with.
    pub(crate) fn rom(&self) -> &'rom RomImage {
        self.rom
    }

    /// The register file as it stands (each value sign-extended from W bits): the phase
    /// sums distributed, without reading out.
    pub fn registers(&self) -> Vec<i64> {
        fold_registers(&self.params, self.rom, self.phases.iter().copied())
    }

    /// Reads the frame out and clears the registers and the frame counters. The depth
    /// tracking (`primed`, held, x) continues across frames, as in the hardware.
    pub fn readout(&mut self) -> Readout {
        let words = self.registers();
        self.phases.iter_mut().for_each(|s| *s = 0);
        self.pcount = 0;
        Readout {
            words,
            refused: std::mem::take(&mut self.refused),
        }
    }
}
