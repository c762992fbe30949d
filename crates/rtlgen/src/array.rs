//! The array's RTL (`templates/array.v`): R × C instances of the one pixel module, the
//! probe ROM and the reference sequencer at the root, the two-stage broadcast and the
//! readout of docs/pixel-contract.md "Array". The readout's numbers (beats per word, cycles
//! per beat, the slot) come from `tofprobe_design::readout`, which the caller resolves;
//! this module only renders them. [`ArrayFault`] (`array_fault.rs`) are the array-level mutants.

use askama::Template;
use tofprobe_pixel::{Mode, PixelParams};

pub use crate::array_fault::ArrayFault;
use crate::error::RtlError;
use crate::naming::clog2;
use crate::render::{RenderOptions, RtlFile, header, render_set};

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

#[derive(Template)]
#[template(path = "array.v", escape = "none")]
struct ArrayT<'a> {
    header: String,
    name: &'a str,
    pixel_name: &'a str,
    rom_name: &'a str,
    seq_name: &'a str,
    fourier: bool,
    mutation: &'a str,
    t: usize,
    w: usize,
    r: usize,
    c: usize,
    n: u64,
    ib: usize,
    aw: usize,
    rows: usize,
    cols: usize,
    tile_row0: usize,
    tile_col0: usize,
    trows: usize,
    tcols: usize,
    b: usize,
    g: u64,
    /// N·C: the frame's accumulation cycles (the double buffer's hold is the walk beyond it).
    acc: u64,
    /// The readout buffer's words: the registers and the status word.
    words: Vec<usize>,
    /// The row of a row fault (`row_late`, `row_stuck`).
    fault_row: usize,
    /// `neighbour_tdc`: the tile's index of the pixel whose TDC is crossed with the next's.
    neighbour: Option<usize>,
    /// G (1: no superpixel) and its module.
    sp: usize,
    sp_name: String,
    dbuf: bool,
}

/// `module`'s declaration in `text` as a black box: its ports, no body (yosys keeps it as a
/// `blackbox` cell, Verilator and Icarus see an empty module with the same pins). How the
/// array's own logic is timed, and linted at sizes where elaborating every pixel would cost
/// minutes (the pixel is linted alone by its own gates).
pub fn black_box(text: &str, module: &str) -> Option<String> {
    let start = text.find(&format!("module {module} ("))?;
    let end = start + text[start..].find(");")? + 2;
    Some(format!(
        "/* verilator lint_off UNDRIVEN */\n/* verilator lint_off UNUSEDSIGNAL */\n\
         (* blackbox *)\n{}\nendmodule\n/* verilator lint_on UNUSEDSIGNAL */\n\
         /* verilator lint_on UNDRIVEN */\n",
        text[start..end].replace("output reg ", "output wire ")
    ))
}

/// The array module's name for a module prefix.
pub fn array_module_name(prefix: &str) -> String {
    format!("{prefix}_array")
}

/// Renders the array's files: the pixel and the probe ROM (as [`crate::render()`] writes them, so
/// the pixel stays one module from one template) and `<prefix>_array.v`. The pixel's own
/// top (`<prefix>_top.v`) is not part of the array's set.
pub fn render_array(
    p: &PixelParams,
    rom: &[u64],
    o: &RenderOptions,
    a: &ArraySpec,
) -> Result<Vec<RtlFile>, RtlError> {
    let tile = check_shape(p, o, a)?;
    let sp = check_superpixel(p, a)?;
    check_fault(a, &tile)?;
    check_double_buffer(p, a)?;
    // The pixel and the ROM exactly as the single pixel's set has them (the pixel with its
    // shadow registers when double-buffered; with a pixel fault, in every pixel).
    let pixel_fault = a.fault.and_then(ArrayFault::pixel);
    let with_fault = RenderOptions {
        mutation: pixel_fault.or(o.mutation),
        ..o.clone()
    };
    let o = &with_fault;
    let mut files: Vec<RtlFile> = render_set(p, rom, o, a.double_buffer)?
        .into_iter()
        .filter(|f| f.template != "top.v")
        .collect();
    let (pixel_name, rom_name, _) = crate::naming::module_names(&o.module_prefix);
    let seq_name = crate::naming::sequencer_module_name(&o.module_prefix);
    let name = array_module_name(&o.module_prefix);
    let names = ModuleNames {
        name: &name,
        pixel_name: &pixel_name,
        rom_name: &rom_name,
        seq_name: &seq_name,
    };
    let t = array_template(p, o, a, &tile, names);
    if let Some(sp) = &sp {
        let fault = a.fault.filter(|f| f.in_superpixel());
        files.push(crate::superpixel::render_superpixel_with(p, sp, o, fault)?);
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

/// The refusal of `field`'s `value`, naming what is `allowed`.
fn bad(field: &'static str, value: String, allowed: String) -> RtlError {
    RtlError::Array {
        field,
        value,
        allowed,
    }
}

/// The sequencer, the shape, the readout's beats and slot, and the rendered tile: the tile
/// (the whole array when none is asked for) or the first of them that is refused.
fn check_shape(p: &PixelParams, o: &RenderOptions, a: &ArraySpec) -> Result<ArrayTile, RtlError> {
    if o.directed.is_some() {
        return Err(bad(
            "sequencer",
            "directed".into(),
            "the array renders the reference sequencer only (the directed one is the \
             pixel's top)"
                .into(),
        ));
    }
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
    let tile = a.tile.unwrap_or(ArrayTile::whole(a.rows, a.cols));
    if tile.pixels() == 0 || tile.row0 + tile.rows > a.rows || tile.col0 + tile.cols > a.cols {
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
    Ok(tile)
}

/// The superpixel's front end for G ≥ 2 (none for G = 1), or G refused.
fn check_superpixel(
    p: &PixelParams,
    a: &ArraySpec,
) -> Result<Option<tofprobe_pixel::Superpixel>, RtlError> {
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
    Ok(sp)
}

/// An array mutant refused where it has nothing to break: its row or pixel outside the
/// tile, or the part it breaks (a second pixel, the superpixel, the double buffer) absent.
fn check_fault(a: &ArraySpec, tile: &ArrayTile) -> Result<(), RtlError> {
    let (np, npt) = (a.rows * a.cols, tile.pixels());
    match a.fault {
        Some(ArrayFault::OrderSwap) if np < 2 => Err(bad(
            "mutation",
            "order_swap".into(),
            "an array of 2 pixels or more".into(),
        )),
        Some(ArrayFault::RowLate { row } | ArrayFault::RowStuck { row })
            if !(tile.row0..tile.row0 + tile.rows).contains(&row) =>
        {
            Err(bad(
                "mutation row",
                row.to_string(),
                format!("{}..{}", tile.row0, tile.row0 + tile.rows),
            ))
        }
        Some(f) if f.in_superpixel() && a.superpixel < 2 => Err(bad(
            "mutation",
            f.name().into(),
            "a superpixel array (array.superpixel ≥ 2)".into(),
        )),
        Some(ArrayFault::SwapLate) if !a.double_buffer => Err(bad(
            "mutation",
            "swap_late".into(),
            "a double-buffered array (array.double_buffer = true)".into(),
        )),
        Some(ArrayFault::NeighbourTdc { row, col }) if !tile.contains(row, col) || npt < 2 => {
            Err(bad(
                "mutation pixel",
                format!("({row}, {col})"),
                format!(
                    "inside the rendered {} × {} pixels (2 pixels or more)",
                    tile.rows, tile.cols
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// The double buffer's swap edge needs a cycle after the last pulse's last register write.
fn check_double_buffer(p: &PixelParams, a: &ArraySpec) -> Result<(), RtlError> {
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
    Ok(())
}

/// The modules `array.v` names: its own and those it instantiates.
struct ModuleNames<'a> {
    name: &'a str,
    pixel_name: &'a str,
    rom_name: &'a str,
    seq_name: &'a str,
}

/// `array.v`'s variables for a checked spec (`o` with the pixel fault applied).
fn array_template<'a>(
    p: &PixelParams,
    o: &RenderOptions,
    a: &ArraySpec,
    tile: &ArrayTile,
    names: ModuleNames<'a>,
) -> ArrayT<'a> {
    let r = p.registers();
    let neighbour = match a.fault {
        Some(ArrayFault::NeighbourTdc { row, col }) => tile.local(row, col),
        _ => None,
    };
    let fault_row = match a.fault {
        Some(ArrayFault::RowLate { row } | ArrayFault::RowStuck { row }) => row,
        _ => 0,
    };
    let acc = p.frame_pulses.saturating_mul(p.cycles_per_pulse as u64);
    ArrayT {
        header: array_header(p, o, a, tile, acc),
        name: names.name,
        pixel_name: names.pixel_name,
        rom_name: names.rom_name,
        seq_name: names.seq_name,
        fourier: p.mode == Mode::Fourier,
        mutation: a
            .fault
            .filter(|f| !f.in_superpixel() && f.pixel().is_none())
            .map(ArrayFault::name)
            .unwrap_or(""),
        t: p.tdc_bits as usize,
        w: p.width as usize,
        r,
        c: p.cycles_per_pulse,
        n: p.frame_pulses,
        ib: p.rd_index_bits() as usize,
        aw: clog2(p.rom_depth as u64) as usize,
        rows: a.rows,
        cols: a.cols,
        tile_row0: tile.row0,
        tile_col0: tile.col0,
        trows: tile.rows,
        tcols: tile.cols,
        b: a.bits as usize,
        g: a.beat_cycles,
        acc,
        words: (0..=r).collect(),
        fault_row,
        neighbour,
        sp: a.superpixel as usize,
        sp_name: crate::superpixel::module_name(&o.module_prefix),
        dbuf: a.double_buffer,
    }
}

/// `array.v`'s header: the generator's, then the array's shape, readout, tile, superpixel,
/// double buffer and mutant; `acc` is N·C.
fn array_header(
    p: &PixelParams,
    o: &RenderOptions,
    a: &ArraySpec,
    tile: &ArrayTile,
    acc: u64,
) -> String {
    let g = a.superpixel as usize;
    let mut h = header(p, "array.v", o);
    h.push_str(&format!(
        "\n// Array: {} x {} pixels, readout {} bits x {} beat(s) per word, one beat every {} \
         cycle(s), slot {} cycles (docs/pixel-contract.md \"Array\").",
        a.rows, a.cols, a.bits, a.beats_per_word, a.beat_cycles, a.slot_cycles
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
    let np = a.rows * a.cols;
    let d = (np as u64).saturating_mul(a.slot_cycles).saturating_add(1);
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
    h
}

#[cfg(test)]
mod tests {
    use super::black_box;

    #[test]
    fn a_black_box_keeps_the_ports_only() {
        let v = "// x\nmodule m (\n    input wire a,\n    output reg [3:0] y\n);\n    reg z;\nendmodule\n";
        let b = black_box(v, "m").unwrap();
        assert!(b.contains("(* blackbox *)\nmodule m ("), "{b}");
        assert!(
            b.contains("output wire [3:0] y") && !b.contains("reg z"),
            "{b}"
        );
        assert!(black_box(v, "n").is_none());
    }
}
