//! The array's register-level model, at the clock edge: docs/pixel-contract.md "Array"
//! register by register, as `templates/array.v` builds it — the root sequencer and probe
//! ROM, the two broadcast stages, R × C of the pixel's one cycle model
//! (`tofprobe_pixel::CycleModel`), the row select onto the column buses, the readout buffer
//! and the port. [`ArrayModel::step`] is one rising edge; [`crate::rtl_driver::run`] drives
//! frames of per-pixel detections through it and records what the array's ports show
//! every cycle (the golden vectors of `tofprobe cosim` on an
//! array). The array's faults ([`ArrayFault`]) are carried exactly, so the cycle where a
//! broken RTL first differs is predicted by the model. Double-buffered (`Readout::
//! double_buffer`), the sequencer overlaps the readout with the next frame's pulses and
//! each pixel's readout streams its [`crate::shadow::Shadow`], loaded by the broadcast swap.

use tofprobe_design::readout::Readout;
use tofprobe_pixel::{
    ChipSequencer, CycleModel, Mode, NO_DETECTION, PinsIn, PixelParams, Superpixel, Walk,
};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::array::ArrayTile;

use crate::error::ArrayError;
use crate::shadow::{Shadow, sample};

/// Cycles recorded after the last frame: its last beat is at most 5 cycles after the
/// frame's end (the slot's last beat is 6 cycles after its strobe, 1 before the next).
pub const TAIL_CYCLES: u64 = 6;

/// The array's outputs during one cycle (before its edge).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ArrayPins {
    /// The pixels sample `valid`/`tdc` this cycle.
    pub pulse_o: bool,
    /// Every pixel's pipeline is free.
    pub ready: bool,
    /// A beat is on `ro_data`.
    pub ro_valid: bool,
    /// The beat (b bits).
    pub ro_data: u64,
}

/// The array's registers, named as in `templates/array.v`.
#[derive(Debug, Clone)]
pub struct ArrayModel {
    ro: Readout,
    fourier: bool,
    words: usize,
    rom: Vec<u64>,
    fault: Option<ArrayFault>,
    /// The pixels that exist (the whole array unless a tile of it is co-simulated).
    tile: ArrayTile,
    /// G > 1: each pixel's G × G SPADs averaged by `templates/superpixel.v`'s rule.
    superpixel: Option<Superpixel>,
    /// Per pixel present, its (valid, tdc) after the superpixel (scratch of `step`).
    combined: Vec<(bool, u32)>,
    /// `[array] double_buffer`: per pixel present, its shadow and the shadow's readout
    /// (empty when single-buffered).
    shadows: Vec<Shadow>,
    /// The root: the chip's one sequencer walking the array (`templates/sequencer.v`).
    seq: ChipSequencer,
    // Broadcast stage 1.
    b_pulse: bool,
    b_ro: bool,
    b_swap: bool,
    b_row: usize,
    b_col: usize,
    b_word: Vec<u64>,
    // Broadcast stage 2.
    o_pulse: bool,
    r_pulse: Vec<bool>,
    r_ro: Vec<bool>,
    r_swap: Vec<bool>,
    late_swap: bool,
    r_col: Vec<usize>,
    r_word: Vec<Vec<u64>>,
    late_pulse: bool,
    late_word: Vec<u64>,
    pixels: Vec<CycleModel>,
    // Read select.
    d_ro: bool,
    d_row: usize,
    d_col: usize,
    e_ro: bool,
    e_row: usize,
    e_col: usize,
    m_row: Vec<bool>,
    m_col: usize,
    // Readout buffer and port.
    rbuf: Vec<u64>,
    dr_act: bool,
    dj: usize,
    dm: usize,
    dg: u64,
    ro_valid: bool,
    ro_data: u64,
}

impl ArrayModel {
    /// The array of `readout`'s shape, every pixel `p`, the probe ROM `rom` (L entries of
    /// ceil(R/64) words; empty in Haar mode), in its reset state.
    pub fn new(
        readout: &Readout,
        p: &PixelParams,
        rom: &[u64],
        fault: Option<ArrayFault>,
    ) -> Result<ArrayModel, ArrayError> {
        Self::tile(readout, p, rom, fault, None)
    }

    /// [`Self::new`] with only `tile`'s pixels present (`None`: all): the sequencer and the
    /// readout walk the whole array, the absent pixels' slots carry no beat.
    pub fn tile(
        readout: &Readout,
        p: &PixelParams,
        rom: &[u64],
        fault: Option<ArrayFault>,
        tile: Option<ArrayTile>,
    ) -> Result<ArrayModel, ArrayError> {
        let tile = tile.unwrap_or(ArrayTile::whole(readout.rows, readout.cols));
        if tile.pixels() == 0
            || tile.row0 + tile.rows > readout.rows
            || tile.col0 + tile.cols > readout.cols
        {
            return Err(ArrayError::Shape(format!(
                "tile rows {}+{}, cols {}+{} is not inside the {} × {} array",
                tile.row0, tile.rows, tile.col0, tile.cols, readout.rows, readout.cols
            )));
        }
        if fault == Some(ArrayFault::SwapLate) && !readout.double_buffer {
            return Err(ArrayError::Shape(
                "the swap_late fault needs a double-buffered array (array.double_buffer = true)"
                    .into(),
            ));
        }
        let fourier = p.mode == Mode::Fourier;
        let words = if fourier {
            p.registers().div_ceil(64)
        } else {
            0
        };
        if fourier && rom.len() != p.rom_depth * words {
            return Err(ArrayError::Shape(format!(
                "the array's probe ROM has {} words: its L = {} entries need {}",
                rom.len(),
                p.rom_depth,
                p.rom_depth * words
            )));
        }
        let err = |source| ArrayError::Pixel {
            row: 0,
            col: 0,
            source,
        };
        let pixel = CycleModel::new(p).map_err(err)?;
        let rows = tile.rows;
        Ok(ArrayModel {
            ro: *readout,
            fourier,
            words,
            rom: rom.to_vec(),
            fault,
            tile,
            superpixel: None,
            combined: vec![(false, 0); tile.pixels()],
            shadows: if readout.double_buffer {
                vec![Shadow::new(p.registers(), p.width); tile.pixels()]
            } else {
                Vec::new()
            },
            seq: ChipSequencer::new(
                readout.frame_pulses,
                readout.cycles_per_pulse,
                p.rom_depth as u64,
                Walk {
                    pixels: readout.pixels() as u64,
                    cols: readout.cols as u64,
                    slot: readout.slot_cycles(),
                    double_buffer: readout.double_buffer,
                },
            ),
            b_pulse: false,
            b_ro: false,
            b_swap: false,
            b_row: 0,
            b_col: 0,
            b_word: vec![0; words],
            o_pulse: false,
            r_pulse: vec![false; rows],
            r_ro: vec![false; rows],
            r_swap: vec![false; rows],
            late_swap: false,
            r_col: vec![0; rows],
            r_word: vec![vec![0; words]; rows],
            late_pulse: false,
            late_word: vec![0; words],
            pixels: vec![pixel; tile.pixels()],
            d_ro: false,
            d_row: 0,
            d_col: 0,
            e_ro: false,
            e_row: 0,
            e_col: 0,
            m_row: vec![false; rows],
            m_col: 0,
            rbuf: vec![0; readout.registers + 1],
            dr_act: false,
            dj: 0,
            dm: 0,
            dg: 0,
            ro_valid: false,
            ro_data: 0,
        })
    }

    /// The same array with each pixel a superpixel of `g` × `g` SPADs (`[array]
    /// superpixel`; 1: one SPAD per pixel): [`Self::step`] then takes per-SPAD inputs and
    /// averages each pixel's with `tofprobe_pixel::Superpixel` before its cycle model, as
    /// the array RTL's `<prefix>_superpixel` instances do.
    pub fn with_superpixel(mut self, g: usize, p: &PixelParams) -> Result<Self, ArrayError> {
        let sp = Superpixel::new(g as u32, p.tdc_bits).map_err(|source| ArrayError::Pixel {
            row: 0,
            col: 0,
            source,
        })?;
        self.superpixel = (g > 1).then_some(sp);
        Ok(self)
    }

    /// G (1: one SPAD per pixel).
    pub fn superpixel(&self) -> usize {
        self.superpixel.as_ref().map_or(1, |s| s.side() as usize)
    }

    /// The inputs `step` takes: one per pixel present, or one per SPAD (the pixels × G²).
    pub fn inputs(&self) -> usize {
        self.tile.pixels() * self.superpixel() * self.superpixel()
    }

    /// The readout the array follows.
    pub fn readout(&self) -> &Readout {
        &self.ro
    }

    /// The outputs during the current cycle.
    pub fn outputs(&self) -> ArrayPins {
        ArrayPins {
            pulse_o: self.o_pulse,
            ready: self.pixels.iter().all(|p| p.outputs().ready),
            ro_valid: self.ro_valid,
            ro_data: self.ro_data,
        }
    }

    /// The pixels present.
    pub fn present(&self) -> ArrayTile {
        self.tile
    }

    /// Pixel (r, c)'s cycle model (`None` outside the tile).
    pub fn pixel(&self, r: usize, c: usize) -> Option<&CycleModel> {
        self.tile.local(r, c).map(|i| &self.pixels[i])
    }

    /// The column buses and the column select: the selected pixel's (rd_valid, rd_index,
    /// rd_data), OR-ed over the selected rows.
    fn mux(&self) -> (bool, usize, u64) {
        let t = self.tile;
        if !(t.col0..t.col0 + t.cols).contains(&self.m_col) {
            return (false, 0, 0);
        }
        let lc = self.m_col - t.col0;
        let mut m = (false, 0usize, 0u64);
        for (lr, _) in self.m_row.iter().enumerate().filter(|(_, s)| **s) {
            let i = lr * t.cols + lc;
            let o = match self.shadows.get(i) {
                Some(sh) => sh.outputs(true),
                None => self.pixels[i].outputs(),
            };
            m = (m.0 | o.rd_valid, m.1 | o.rd_index as usize, m.2 | o.rd_data);
        }
        m
    }

    /// Each pixel's (valid, tdc) from the inputs: its own (G = 1), or its G² SPADs' — the
    /// SPAD grid of the pixels present, row-major, pixel (lr, lc) owning SPADs
    /// (lr·G + i, lc·G + j) — combined by the one averaging rule (no detection: tdc 0, as
    /// the RTL's multiply by the table's default 0 gives).
    fn combine_inputs(&mut self, valid: &[bool], tdc: &[u32]) {
        let t = self.tile;
        let Some(sp) = &self.superpixel else {
            for (i, c) in self.combined.iter_mut().enumerate() {
                *c = (valid[i], tdc[i]);
            }
            return;
        };
        let g = sp.side() as usize;
        let scols = t.cols * g;
        let mask = (1u32 << sp.tdc_bits()) - 1;
        let mut codes = [0u32; 16];
        for (i, c) in self.combined.iter_mut().enumerate() {
            let (lr, lc) = (i / t.cols, i % t.cols);
            for (s, code) in codes.iter_mut().take(g * g).enumerate() {
                let k = (lr * g + s / g) * scols + lc * g + s % g;
                *code = if valid[k] {
                    tdc[k] & mask
                } else {
                    NO_DETECTION
                };
            }
            let m = sp.combine(&codes[..g * g]);
            *c = if m == NO_DETECTION {
                (false, 0)
            } else {
                (true, m)
            };
        }
    }

    /// One clock cycle: returns the outputs seen during it, then applies the rising edge
    /// with `rst` and the `valid` and `tdc` inputs ([`Self::inputs`] of them: per pixel
    /// present, row-major, or per SPAD with G > 1, row-major over the SPAD grid).
    pub fn step(&mut self, rst: bool, valid: &[bool], tdc: &[u32]) -> ArrayPins {
        let out = self.outputs();
        let ro = self.ro;
        let t = self.tile;
        let npt = t.pixels();
        let (reg, k, g) = (ro.registers, ro.beats_per_word, ro.beat_cycles);
        // Root, combinational.
        let dbuf = ro.double_buffer;
        let root = self.seq.strobes(rst);
        let (s_pulse, s_swap, s_ro) = (root.pulse, root.swap, root.readout);
        let (s_row, s_col) = match (self.fault, root.q) {
            (Some(ArrayFault::OrderSwap), 0) => ro.order(1),
            (Some(ArrayFault::OrderSwap), 1) => ro.order(0),
            _ => (root.row as usize, root.col as usize),
        };
        let addr = root.addr as usize;
        let rom_word: Vec<u64> = if self.fourier {
            self.rom[addr * self.words..(addr + 1) * self.words].to_vec()
        } else {
            Vec::new()
        };
        let (mv, mi, md) = self.mux();
        // The pixels' edges.
        self.combine_inputs(valid, tdc);
        let neighbour = match self.fault {
            Some(ArrayFault::NeighbourTdc { row, col }) => t.local(row, col),
            _ => None,
        };
        for (i, px) in self.pixels.iter_mut().enumerate() {
            let (r, c) = (i / t.cols, t.col0 + i % t.cols);
            // Two TDCs crossed: the faulty pixel reads the next one's, that one its.
            let src = match neighbour {
                Some(n) if n == i => (i + 1) % npt,
                Some(n) if (n + 1) % npt == i => n,
                _ => i,
            };
            let readout = self.r_ro[r] && self.r_col[r] == c;
            // Double-buffered: the readout is the shadow's; the swap samples the registers
            // before this edge and clears them after its writes.
            let swap = dbuf && self.r_swap[r];
            let sampled = swap.then(|| sample(px));
            px.step(&PinsIn {
                rst,
                pulse: self.r_pulse[r],
                valid: self.combined[i].0,
                tdc: self.combined[src].1,
                rom_word: &self.r_word[r],
                readout: readout && !dbuf,
            });
            if let Some(sh) = self.shadows.get_mut(i) {
                if swap && !rst {
                    px.swap_clear();
                }
                sh.step(rst, readout, sampled.as_ref().map(|(y, f)| (&y[..], *f)));
            }
        }
        // The buffer (no reset) and the port.
        let beat = self.dr_act && (g == 1 || self.dg == 0);
        let step = self.dr_act && (g == 1 || self.dg == g - 1);
        let last = self.dj == reg && (k == 1 || self.dm == k - 1);
        let word = self.rbuf.get(self.dj).copied().unwrap_or(0);
        let data = ro.beats_of(self.dj, word)[self.dm.min(k - 1)];
        if mv && mi <= reg {
            self.rbuf[mi] = md;
        }
        if rst {
            self.reset_registers();
            return out;
        }
        self.ro_valid = beat;
        if beat {
            self.ro_data = data;
        }
        if mv && mi == 0 {
            (self.dr_act, self.dj, self.dm, self.dg) = (true, 0, 0, 0);
        } else if self.dr_act {
            if g > 1 {
                self.dg = if step { 0 } else { self.dg + 1 };
            }
            if step {
                if last {
                    self.dr_act = false;
                } else if k > 1 && self.dm == k - 1 {
                    (self.dm, self.dj) = (0, self.dj + 1);
                } else if k > 1 {
                    self.dm += 1;
                } else {
                    self.dj += 1;
                }
            }
        }
        // Read select (from the old stage values).
        if self.e_ro {
            self.m_col = self.e_col;
            for (lr, m) in self.m_row.iter_mut().enumerate() {
                let r = t.row0 + lr;
                let stuck = self.fault == Some(ArrayFault::RowStuck { row: r });
                *m = (stuck && *m) || self.e_row == r;
            }
        }
        (self.e_ro, self.e_row, self.e_col) = (self.d_ro, self.d_row, self.d_col);
        (self.d_ro, self.d_row, self.d_col) = (self.b_ro, self.b_row, self.b_col);
        // Broadcast stage 2 (from the old stage 1).
        self.o_pulse = self.b_pulse;
        let late_row = match self.fault {
            Some(ArrayFault::RowLate { row }) => Some(row),
            _ => None,
        };
        for lr in 0..t.rows {
            if late_row == Some(t.row0 + lr) {
                self.r_pulse[lr] = self.late_pulse;
                self.r_word[lr].clone_from(&self.late_word);
            } else {
                self.r_pulse[lr] = self.b_pulse;
                self.r_word[lr].clone_from(&self.b_word);
            }
            self.r_ro[lr] = self.b_ro && self.b_row == t.row0 + lr;
            self.r_swap[lr] = if self.fault == Some(ArrayFault::SwapLate) {
                self.late_swap
            } else {
                self.b_swap
            };
            self.r_col[lr] = self.b_col;
        }
        self.late_pulse = self.b_pulse;
        self.late_swap = self.b_swap;
        self.late_word.clone_from(&self.b_word);
        // Stage 1 (from the root).
        (self.b_pulse, self.b_ro, self.b_row, self.b_col) = (s_pulse, s_ro, s_row, s_col);
        self.b_swap = s_swap;
        self.b_word = rom_word;
        self.seq.edge(false);
        out
    }

    /// Every register with a reset (all but the readout buffer) to zero.
    fn reset_registers(&mut self) {
        let words = self.words;
        self.seq.reset();
        (self.b_swap, self.late_swap) = (false, false);
        self.r_swap.fill(false);
        (self.b_pulse, self.b_ro, self.b_row, self.b_col) = (false, false, 0, 0);
        self.b_word = vec![0; words];
        self.o_pulse = false;
        self.r_pulse.fill(false);
        self.r_ro.fill(false);
        self.r_col.fill(0);
        self.r_word.iter_mut().for_each(|w| w.fill(0));
        self.late_pulse = false;
        self.late_word.fill(0);
        (self.d_ro, self.d_row, self.d_col) = (false, 0, 0);
        (self.e_ro, self.e_row, self.e_col) = (false, 0, 0);
        self.m_row.fill(false);
        self.m_col = 0;
        (self.dr_act, self.dj, self.dm, self.dg) = (false, 0, 0, 0);
        (self.ro_valid, self.ro_data) = (false, 0);
    }
}
