//! The array's RTL (`templates/array.v`): R × C instances of the one pixel module, the
//! probe ROM and the reference sequencer at the root, the two-stage broadcast and the
//! readout of docs/pixel-contract.md "Array". The readout's numbers (beats per word, cycles
//! per beat, the slot) come from `tofprobe_design::readout`, which the caller resolves;
//! this module only renders them. [`ArrayFault`] are the array-level mutants.

use askama::Template;
use tofprobe_pixel::{Mode, PixelParams};

use crate::error::RtlError;
use crate::naming::clog2;
use crate::render::{RenderOptions, RtlFile, header, render};

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
}

impl ArrayFault {
    /// The name used in headers and reports.
    pub fn name(self) -> &'static str {
        match self {
            ArrayFault::RowLate { .. } => "row_late",
            ArrayFault::NeighbourTdc { .. } => "neighbour_tdc",
            ArrayFault::OrderSwap => "order_swap",
            ArrayFault::RowStuck { .. } => "row_stuck",
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
}

/// Largest rows × cols the generator renders (the template writes one instance and one
/// bus term per pixel: 64 × 64 is 4096 instances).
pub const MAX_RENDERED_PIXELS: usize = 64 * 64;

struct RowT {
    row: usize,
    late: bool,
    stuck: bool,
}

struct PixelT {
    i: usize,
    row: usize,
    col: usize,
    /// The pixel whose TDC field this one reads (itself unless NeighbourTdc).
    tdc: usize,
}

struct ColT {
    col: usize,
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
    if a.rows == 0 || a.cols == 0 || np > MAX_RENDERED_PIXELS {
        return Err(bad(
            "array.rows × array.cols",
            format!("{} × {}", a.rows, a.cols),
            format!(
                "1..={MAX_RENDERED_PIXELS} pixels rendered whole (64 × 64); a larger array is \
                 built and timed from a tile or a row slice"
            ),
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
    match a.fault {
        Some(ArrayFault::OrderSwap) if np < 2 => {
            return Err(bad(
                "mutation",
                "order_swap".into(),
                "an array of 2 pixels or more".into(),
            ));
        }
        Some(ArrayFault::RowLate { row } | ArrayFault::RowStuck { row }) if row >= a.rows => {
            return Err(bad(
                "mutation row",
                row.to_string(),
                format!("0..{}", a.rows),
            ));
        }
        Some(ArrayFault::NeighbourTdc { row, col }) if row >= a.rows || col >= a.cols || np < 2 => {
            return Err(bad(
                "mutation pixel",
                format!("({row}, {col})"),
                format!(
                    "inside the {} × {} array (2 pixels or more)",
                    a.rows, a.cols
                ),
            ));
        }
        _ => {}
    }
    // The pixel and the ROM exactly as the single pixel's set has them.
    let mut files: Vec<RtlFile> = render(p, rom, o)?
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
        Some(ArrayFault::NeighbourTdc { row, col }) => Some(row * a.cols + col),
        _ => None,
    };
    let pixels: Vec<PixelT> = (0..np)
        .map(|i| PixelT {
            i,
            row: i / a.cols,
            col: i % a.cols,
            tdc: match neighbour {
                Some(n) if n == i => (i + 1) % np,
                Some(n) if (n + 1) % np == i => n,
                _ => i,
            },
        })
        .collect();
    let columns = (0..a.cols)
        .map(|c| {
            let terms =
                |f: &dyn Fn(usize) -> String| (0..a.rows).map(f).collect::<Vec<_>>().join(" | ");
            ColT {
                col: c,
                valid: terms(&|row| format!("(m_row[{row}] & p_valid[{}])", row * a.cols + c)),
                index: terms(&|row| {
                    format!(
                        "({{{ib}{{m_row[{row}]}}}} & p_index[{} +: {ib}])",
                        (row * a.cols + c) * ib as usize
                    )
                }),
                data: terms(&|row| {
                    format!(
                        "({{{w}{{m_row[{row}]}}}} & p_data[{} +: {w}])",
                        (row * a.cols + c) * w as usize
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
        rows_t: (0..a.rows)
            .map(|row| RowT {
                row,
                late: late == Some(row),
                stuck: stuck == Some(row),
            })
            .collect(),
        pixels,
        columns,
    };
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
