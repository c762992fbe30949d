//! The array's RTL (`templates/array.v`): R × C instances of the one pixel module, the
//! probe ROM and the reference sequencer at the root, the two-stage broadcast and the
//! readout of docs/pixel-contract.md "Array". The readout's numbers (beats per word, cycles
//! per beat, the slot) come from `tofprobe_design::readout`, which the caller resolves;
//! this module only renders them. [`ArrayFault`] are the array-level mutants.

use askama::Template;
use tofprobe_pixel::{Mode, PixelParams};

use crate::error::RtlError;
use crate::naming::clog2;
use crate::render::{RenderOptions, RtlFile, header, render_set};

/// A deliberate fault of the array, for the mutation tests only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArrayFault {
    /// The row's broadcast (`pulse`, `rom_word`) passes one extra register: a cycle late.
    RowLate {
        /// The late row.
        row: usize,
    },
    /// The pixel's `tdc` input is wired to the next pixel's (row-major, wrapping) and that
    /// one's to this one's: two TDCs crossed.
    NeighbourTdc {
        /// The pixel's row.
        row: usize,
        /// Its column.
        col: usize,
    },
    /// The readout order swaps its first two pixels.
    OrderSwap,
    /// The row's read select, once set, never clears: it stays on the column buses.
    RowStuck {
        /// The stuck row.
        row: usize,
    },
    /// Double-buffered arrays only: the swap strobe passes one extra register, so every
    /// pixel's shadow copy is taken a cycle late (after the first readout has begun and
    /// together with the next frame's first pulse).
    SwapLate,
}

impl ArrayFault {
    /// The name used in headers and reports.
    pub fn name(self) -> &'static str {
        match self {
            ArrayFault::RowLate { .. } => "row_late",
            ArrayFault::NeighbourTdc { .. } => "neighbour_tdc",
            ArrayFault::OrderSwap => "order_swap",
            ArrayFault::RowStuck { .. } => "row_stuck",
            ArrayFault::SwapLate => "swap_late",
        }
    }
}

/// The array's shape and readout as the template needs them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArraySpec {
    /// Rows of pixels.
    pub rows: usize,
    /// Columns of pixels.
    pub cols: usize,
    /// b: bits per beat of the output port.
    pub bits: u32,
    /// k: beats per word.
    pub beats_per_word: usize,
    /// g: cycles per beat.
    pub beat_cycles: u64,
    /// S: cycles between two pixels' readout strobes ((R+1)·k·g).
    pub slot_cycles: u64,
    /// A deliberate fault (mutation tests only).
    pub fault: Option<ArrayFault>,
    /// Render only this tile's pixels, with the whole array's sequencer, broadcast and
    /// readout (`None`: every pixel).
    pub tile: Option<ArrayTile>,
    /// G: each pixel is a superpixel of G × G SPADs (1: one SPAD per pixel). With G > 1
    /// the array's `valid`/`tdc` are per SPAD (row-major over the SPAD grid of the pixels
    /// rendered) and each pixel is fed through one `<prefix>_superpixel` averaging module.
    pub superpixel: u32,
    /// `[array] double_buffer`: each pixel's shadow registers, loaded by a broadcast
    /// `swap` at the frame's end, are what the readout streams while the next frame
    /// accumulates (docs/pixel-contract.md "Double buffer").
    pub double_buffer: bool,
}

/// A rectangle of an array's pixels: the part of an array too large to co-simulate whole
/// that is rendered, the sequencer and readout still walking every pixel's slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArrayTile {
    /// First row.
    pub row0: usize,
    /// First column.
    pub col0: usize,
    /// Rows of the tile.
    pub rows: usize,
    /// Columns of the tile.
    pub cols: usize,
}

impl ArrayTile {
    /// The whole `rows` × `cols` array as a tile.
    pub fn whole(rows: usize, cols: usize) -> ArrayTile {
        ArrayTile {
            row0: 0,
            col0: 0,
            rows,
            cols,
        }
    }

    /// Whether pixel (r, c) of the array is in the tile.
    pub fn contains(&self, r: usize, c: usize) -> bool {
        (self.row0..self.row0 + self.rows).contains(&r)
            && (self.col0..self.col0 + self.cols).contains(&c)
    }

    /// Pixels of the tile.
    pub fn pixels(&self) -> usize {
        self.rows * self.cols
    }

    /// The tile's index of pixel (r, c) of the array (row-major over the tile), if inside.
    pub fn local(&self, r: usize, c: usize) -> Option<usize> {
        self.contains(r, c)
            .then(|| (r - self.row0) * self.cols + (c - self.col0))
    }
}

/// Largest rows × cols the generator renders (the template writes one instance and one
/// bus term per pixel: 64 × 64 is 4096 instances).
pub const MAX_RENDERED_PIXELS: usize = 64 * 64;

struct RowT {
    row: usize,
    /// Its index in the tile.
    lr: usize,
    late: bool,
    stuck: bool,
}

struct PixelT {
    /// Index in the tile (the ports' and the pixel vectors').
    i: usize,
    row: usize,
    col: usize,
    /// Row index in the tile.
    lr: usize,
    /// The pixel's `valid` input: its port bit (G = 1) or its superpixel's output.
    valid: String,
    /// The pixel's `tdc` input: its port field, or its superpixel's output (the pixel's
    /// own unless NeighbourTdc crosses it).
    tdc: String,
    /// G > 1: the port bits of its G² SPADs, row-major within the superpixel.
    spads: Vec<usize>,
}

struct ColT {
    col: usize,
    /// Its index in the tile.
    lc: usize,
    valid: String,
    index: String,
    data: String,
}

#[derive(Template)]
#[template(path = "array.v", escape = "none")]
struct ArrayT<'a> {
    header: String,
    name: &'a str,
    pixel_name: &'a str,
    rom_name: &'a str,
    fourier: bool,
    mutation: &'a str,
    t: usize,
    w: usize,
    r: usize,
    c: usize,
    n: u64,
    l: usize,
    ib: usize,
    aw: usize,
    pw: usize,
    nw: usize,
    rows: usize,
    cols: usize,
    np: usize,
    trows: usize,
    tcols: usize,
    npt: usize,
    tile: Option<(usize, usize)>,
    qw: usize,
    scw: usize,
    rw: usize,
    cw: usize,
    s: u64,
    b: usize,
    k: usize,
    g: u64,
    kw: usize,
    gw: usize,
    kb: usize,
    dx_ext: String,
    parts: Vec<usize>,
    words: Vec<usize>,
    swap_r0: usize,
    swap_c0: usize,
    swap_r1: usize,
    swap_c1: usize,
    rows_t: Vec<RowT>,
    pixels: Vec<PixelT>,
    columns: Vec<ColT>,
    /// G (1: no superpixel) and its module.
    sp: usize,
    sp_name: String,
    /// Inputs on the ports: the pixels rendered × G².
    nin: usize,
    /// SPAD columns of the rendered grid (tcols · G).
    scols: usize,
    dbuf: bool,
    /// Double-buffered: the hold after the frame's pulses beyond its swap cycle,
    /// max(D − N·C − 1, 0) cycles, and its counter's width.
    idle: u64,
    hw: usize,
}

/// The array module's name for a module prefix.
pub fn array_module_name(prefix: &str) -> String {
    format!("{prefix}_array")
}

/// Renders the array's files: the pixel and the probe ROM (as [`render`] writes them, so
/// the pixel stays one module from one template) and `<prefix>_array.v`. The pixel's own
/// top (`<prefix>_top.v`) is not part of the array's set.
pub fn render_array(
    p: &PixelParams,
    rom: &[u64],
    o: &RenderOptions,
    a: &ArraySpec,
) -> Result<Vec<RtlFile>, RtlError> {
    let bad = |field: &'static str, value: String, allowed: String| RtlError::Array {
        field,
        value,
        allowed,
    };
    if o.directed.is_some() {
        return Err(bad(
            "sequencer",
            "directed".into(),
            "the array renders the reference sequencer only (the directed one is the \
             pixel's top)"
                .into(),
        ));
    }
    let np = a.rows * a.cols;
    if a.rows == 0 || a.cols == 0 || a.rows > 4096 || a.cols > 4096 {
        return Err(bad(
            "array.rows × array.cols",
            format!("{} × {}", a.rows, a.cols),
            "1..=4096 rows and columns".into(),
        ));
    }
    let w = p.width;
    if a.bits == 0 || a.bits > w || a.beats_per_word != w.div_ceil(a.bits) as usize {
        return Err(bad(
            "array.readout_bits",
            a.bits.to_string(),
            format!("1..={w} with k = ceil(W / b) beats per word"),
        ));
    }
    let words = (p.registers() + 1) as u64;
    if a.beat_cycles == 0 || a.slot_cycles != words * a.beats_per_word as u64 * a.beat_cycles {
        return Err(bad(
            "array slot",
            a.slot_cycles.to_string(),
            format!(
                "(R+1)·k·g = {words} × {} × {}",
                a.beats_per_word, a.beat_cycles
            ),
        ));
    }
    let order = |q: usize| (q / a.cols, q % a.cols);
    let tile = a.tile.unwrap_or(ArrayTile::whole(a.rows, a.cols));
    let npt = tile.pixels();
    if npt == 0 || tile.row0 + tile.rows > a.rows || tile.col0 + tile.cols > a.cols {
        return Err(bad(
            "tile",
            format!(
                "rows {}+{}, cols {}+{}",
                tile.row0, tile.rows, tile.col0, tile.cols
            ),
            format!(
                "a non-empty rectangle inside the {} × {} array",
                a.rows, a.cols
            ),
        ));
    }
    if npt > MAX_RENDERED_PIXELS {
        return Err(bad(
            "array.rows × array.cols",
            format!("{} × {}", tile.rows, tile.cols),
            format!(
                "1..={MAX_RENDERED_PIXELS} pixels rendered (64 × 64); a larger array is \
                 co-simulated as a tile of it (`tofprobe cosim --tile ROW,COL,ROWS,COLS`)"
            ),
        ));
    }
    let g = a.superpixel as usize;
    let sp = (g > 1)
        .then(|| tofprobe_pixel::Superpixel::new(a.superpixel, p.tdc_bits))
        .transpose()
        .map_err(|e| {
            bad(
                "array.superpixel",
                a.superpixel.to_string(),
                format!("1..={} ({e})", tofprobe_pixel::superpixel::MAX_SUPERPIXEL),
            )
        })?;
    if g == 0 {
        return Err(bad(
            "array.superpixel",
            "0".into(),
            format!("1..={}", tofprobe_pixel::superpixel::MAX_SUPERPIXEL),
        ));
    }
    match a.fault {
        Some(ArrayFault::OrderSwap) if np < 2 => {
            return Err(bad(
                "mutation",
                "order_swap".into(),
                "an array of 2 pixels or more".into(),
            ));
        }
        Some(ArrayFault::RowLate { row } | ArrayFault::RowStuck { row })
            if !(tile.row0..tile.row0 + tile.rows).contains(&row) =>
        {
            return Err(bad(
                "mutation row",
                row.to_string(),
                format!("{}..{}", tile.row0, tile.row0 + tile.rows),
            ));
        }
        Some(ArrayFault::SwapLate) if !a.double_buffer => {
            return Err(bad(
                "mutation",
                "swap_late".into(),
                "a double-buffered array (array.double_buffer = true)".into(),
            ));
        }
        Some(ArrayFault::NeighbourTdc { row, col }) if !tile.contains(row, col) || npt < 2 => {
            return Err(bad(
                "mutation pixel",
                format!("({row}, {col})"),
                format!(
                    "inside the rendered {} × {} pixels (2 pixels or more)",
                    tile.rows, tile.cols
                ),
            ));
        }
        _ => {}
    }
    if a.double_buffer && p.cycles_per_pulse <= p.slots() {
        return Err(bad(
            "pixel.cycles_per_pulse",
            p.cycles_per_pulse.to_string(),
            format!(
                "more than the {} slot(s) per pulse with array.double_buffer (the swap edge \
                 must follow the last pulse's last register write)",
                p.slots()
            ),
        ));
    }
    // The pixel and the ROM exactly as the single pixel's set has them (the pixel with its
    // shadow registers when double-buffered).
    let mut files: Vec<RtlFile> = render_set(p, rom, o, a.double_buffer)?
        .into_iter()
        .filter(|f| f.template != "top.v")
        .collect();
    let (pixel_name, rom_name, _) = crate::naming::module_names(&o.module_prefix);
    let name = array_module_name(&o.module_prefix);
    let r = p.registers();
    let ib = p.rd_index_bits();
    let cw = clog2(a.cols as u64);
    let k = a.beats_per_word;
    let kb = k as u32 * a.bits;
    let neighbour = match a.fault {
        Some(ArrayFault::NeighbourTdc { row, col }) => tile.local(row, col),
        _ => None,
    };
    let tb = p.tdc_bits as usize;
    let scols = tile.cols * g;
    let pixels: Vec<PixelT> = (0..npt)
        .map(|i| {
            let src = match neighbour {
                Some(n) if n == i => (i + 1) % npt,
                Some(n) if (n + 1) % npt == i => n,
                _ => i,
            };
            let (lr, lc) = (i / tile.cols, i % tile.cols);
            PixelT {
                i,
                row: tile.row0 + lr,
                col: tile.col0 + lc,
                lr,
                valid: if g > 1 {
                    format!("s_valid[{i}]")
                } else {
                    format!("valid[{i}]")
                },
                tdc: if g > 1 {
                    format!("s_tdc[{} +: {tb}]", src * tb)
                } else {
                    format!("tdc[{} +: {tb}]", src * tb)
                },
                spads: (0..g * g)
                    .filter(|_| g > 1)
                    .map(|s| (lr * g + s / g) * scols + lc * g + s % g)
                    .collect(),
            }
        })
        .collect();
    let columns = (0..tile.cols)
        .map(|lc| {
            let terms =
                |f: &dyn Fn(usize) -> String| (0..tile.rows).map(f).collect::<Vec<_>>().join(" | ");
            ColT {
                col: tile.col0 + lc,
                lc,
                valid: terms(&|lr| format!("(m_row[{lr}] & p_valid[{}])", lr * tile.cols + lc)),
                index: terms(&|lr| {
                    format!(
                        "({{{ib}{{m_row[{lr}]}}}} & p_index[{} +: {ib}])",
                        (lr * tile.cols + lc) * ib as usize
                    )
                }),
                data: terms(&|lr| {
                    format!(
                        "({{{w}{{m_row[{lr}]}}}} & p_data[{} +: {w}])",
                        (lr * tile.cols + lc) * w as usize
                    )
                }),
            }
        })
        .collect();
    let (late, stuck) = match a.fault {
        Some(ArrayFault::RowLate { row }) => (Some(row), None),
        Some(ArrayFault::RowStuck { row }) => (None, Some(row)),
        _ => (None, None),
    };
    let (s0, s1) = (order(0), order(1.min(np - 1)));
    let mut h = header(p, "array.v", o);
    h.push_str(&format!(
        "\n// Array: {} x {} pixels, readout {} bits x {} beat(s) per word, one beat every {} \
         cycle(s), slot {} cycles (docs/pixel-contract.md \"Array\").",
        a.rows, a.cols, a.bits, k, a.beat_cycles, a.slot_cycles
    ));
    if a.tile.is_some() {
        h.push_str(&format!(
            "\n// Tile: rows {}..{}, columns {}..{} of it rendered (the others' slots carry no beat).",
            tile.row0,
            tile.row0 + tile.rows - 1,
            tile.col0,
            tile.col0 + tile.cols - 1
        ));
    }
    if g > 1 {
        h.push_str(&format!(
            "\n// Superpixel: {g} x {g} SPADs per pixel, averaged by `{}` (docs/pixel-contract.md \"Superpixel\").",
            crate::superpixel::module_name(&o.module_prefix)
        ));
    }
    // D = P·S + 1; double-buffered, the frame is max(N·C + 1, D) cycles.
    let d = (np as u64).saturating_mul(a.slot_cycles).saturating_add(1);
    let acc = p.frame_pulses.saturating_mul(p.cycles_per_pulse as u64);
    let idle = d.saturating_sub(acc + 1);
    if a.double_buffer {
        h.push_str(&format!(
            "\n// Double-buffered: the readout streams each pixel's shadow while the next frame \
             accumulates; a frame is max(N·C + 1, D) = {} cycles (docs/pixel-contract.md \"Double buffer\").",
            (acc + 1).max(d)
        ));
    }
    if let Some(f) = a.fault {
        h.push_str(&format!(
            "\n// DELIBERATELY BROKEN ({}: {f:?}) for the array mutation tests.",
            f.name()
        ));
    }
    let t = ArrayT {
        header: h,
        name: &name,
        pixel_name: &pixel_name,
        rom_name: &rom_name,
        fourier: p.mode == Mode::Fourier,
        mutation: a.fault.map(ArrayFault::name).unwrap_or(""),
        t: p.tdc_bits as usize,
        w: w as usize,
        r,
        c: p.cycles_per_pulse,
        n: p.frame_pulses,
        l: p.rom_depth,
        ib: ib as usize,
        aw: clog2(p.rom_depth as u64) as usize,
        pw: clog2(p.cycles_per_pulse as u64) as usize,
        nw: clog2(p.frame_pulses) as usize,
        rows: a.rows,
        cols: a.cols,
        np,
        trows: tile.rows,
        tcols: tile.cols,
        npt,
        tile: a.tile.map(|t| (t.row0, t.col0)),
        qw: clog2(np as u64 + 1) as usize,
        scw: clog2(a.slot_cycles) as usize,
        rw: clog2(a.rows as u64) as usize,
        cw: cw as usize,
        s: a.slot_cycles,
        b: a.bits as usize,
        k,
        g: a.beat_cycles,
        kw: clog2(k as u64) as usize,
        gw: clog2(a.beat_cycles) as usize,
        kb: kb as usize,
        dx_ext: if kb > w {
            format!("{{{{{}{{dsx}}}}, dw}}", kb - w)
        } else {
            "dw".into()
        },
        parts: (0..k).collect(),
        words: (0..=r).collect(),
        swap_r0: s0.0,
        swap_c0: s0.1,
        swap_r1: s1.0,
        swap_c1: s1.1,
        rows_t: (0..tile.rows)
            .map(|lr| RowT {
                row: tile.row0 + lr,
                lr,
                late: late == Some(tile.row0 + lr),
                stuck: stuck == Some(tile.row0 + lr),
            })
            .collect(),
        pixels,
        columns,
        sp: g,
        sp_name: crate::superpixel::module_name(&o.module_prefix),
        nin: npt * g * g,
        scols,
        dbuf: a.double_buffer,
        idle,
        hw: clog2(idle + 1) as usize,
    };
    if let Some(sp) = &sp {
        files.push(crate::superpixel::render_superpixel(p, sp, o)?);
    }
    files.push(RtlFile {
        name: format!("{name}.v"),
        template: "array.v",
        contents: t.render().map_err(|e| RtlError::Render {
            template: "array.v",
            message: e.to_string(),
        })? + "\n",
    });
    Ok(files)
}
