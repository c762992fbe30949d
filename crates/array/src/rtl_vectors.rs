//! The array's golden vectors (docs/pixel-contract.md "Array"): the per-pixel detections
//! from the array scene, the ports the array model shows every cycle, the readout stream
//! and per-pixel digests, as the files `testbench/array_harness.cpp` (Verilator) and
//! `testbench/array_tb.v` (Icarus) replay:
//!
//! - `array_params.vh`: `AR_TOP`, `AR_NP` (pixels present: all, or a tile's), `AR_T`,
//!   `AR_B`, `AR_CYCLES`, `AR_PULSES`, and with `[array] superpixel = G > 1` `AR_NS` (the
//!   SPAD inputs, AR_NP·G²), and with a mid-frame reset (`rtl::run_with_reset`)
//!   `AR_RESET_AT` (its cycle: `rst` is high then, and in power-up's two cycles);
//! - `array_stim.hex`: one line per pulse the pixels sample, the P·(T+1)-bit value
//!   {tdc[P·T−1:0], valid[P−1:0]} over the P inputs (pixel i = r·cols + c; with G > 1 the
//!   SPADs, i = sr·(cols·G) + sc over the SPAD grid);
//! - `array_expect.hex`: one line per cycle, `pulse_o ready ro_valid ro_data`;
//! - `readout.txt`: per frame and pixel (readout order) its R + 1 words;
//! - `digests.txt`: per frame and pixel, FNV-1a 64 of its words (little-endian u64s).

use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::PixelParams;

use crate::error::ArrayError;
use crate::rtl::ArrayRun;

/// The file names of a vector set, the params include first.
pub const FILES: [&str; 5] = [
    "array_params.vh",
    "array_stim.hex",
    "array_expect.hex",
    "readout.txt",
    "digests.txt",
];

/// Every input's detections for `frames` frames of the design's scene, `frame_pulses` per
/// frame: row-major over the pixels of `tile` (all when `None`), pixel (r, c)'s own stream
/// (`ResolvedDesign::pixel_source`); with `[array] superpixel = G > 1`, row-major over the
/// tile's SPAD grid, SPAD (r, c)'s own stream (`ResolvedDesign::spad_source`).
pub fn scene_detections(
    design: &ResolvedDesign,
    frame_pulses: u64,
    frames: u64,
    tile: Option<tofprobe_design::readout::ArrayTile>,
) -> Result<Vec<Vec<Option<u32>>>, ArrayError> {
    let a = design
        .array
        .as_ref()
        .ok_or_else(|| ArrayError::Shape("the design has no [array]".into()))?;
    let n = (frame_pulses * frames) as usize;
    let t = tile.unwrap_or(tofprobe_design::readout::ArrayTile::whole(a.rows, a.cols));
    // The SPAD grid of the tile (G = 1: its pixels); SPAD (r, c)'s own stream.
    let g = a.superpixel;
    let mut out = Vec::with_capacity(t.pixels() * g * g);
    for r in t.row0 * g..(t.row0 + t.rows) * g {
        for c in t.col0 * g..(t.col0 + t.cols) * g {
            let mut v = vec![None; n];
            design.spad_source(r, c)?.fill(0, &mut v);
            out.push(v);
        }
    }
    Ok(out)
}

/// Thins the detections of `inputs` (as [`scene_detections`] orders them: the tile's
/// `cols` pixels a row, G × G SPADs each) so the co-simulation reaches what a bright scene
/// never does (issue 42's mutation study: with every SPAD valid on every pulse, a
/// superpixel whose `valid` is the AND of its SPADs, two crossed SPAD codes or a wrong
/// reciprocal entry passed). At pulse n, pixel p keeps k = (n + p) mod (G² + 1) of its G²
/// SPADs' detections — every count from none to all, exactly one among them — the ones at
/// positions n, n + 1, … mod G² within the superpixel (so each SPAD is the only one in
/// turn); with G = 1 a pixel presents its detection on one pulse in two (the hold and the
/// priming between). Deterministic: the same inputs give the same stimulus.
pub fn exercise(inputs: &mut [Vec<Option<u32>>], cols: usize, g: usize) {
    let g2 = g * g;
    if cols == 0 || g == 0 || !inputs.len().is_multiple_of(cols * g2) {
        return;
    }
    let scols = cols * g;
    for (k, stream) in inputs.iter_mut().enumerate() {
        let (sr, sc) = (k / scols, k % scols);
        let pixel = (sr / g) * cols + sc / g;
        let spad = (sr % g) * g + sc % g;
        for (n, x) in stream.iter_mut().enumerate() {
            let keep = (n + pixel) % (g2 + 1);
            // SPAD `spad` is kept when it is among the `keep` positions from n mod G².
            let offset = (spad + g2 - n % g2) % g2;
            if offset >= keep {
                *x = None;
            }
        }
    }
}

fn hex_of_bits(bits: &[bool]) -> String {
    let digits = bits.len().div_ceil(4).max(1);
    (0..digits)
        .rev()
        .map(|d| {
            let nib = (0..4).fold(0u32, |a, b| {
                a | (u32::from(*bits.get(d * 4 + b).unwrap_or(&false)) << b)
            });
            char::from_digit(nib, 16).unwrap_or('0')
        })
        .collect()
}

/// FNV-1a 64 of a pixel's words (each as 8 little-endian bytes).
pub fn digest(words: &[u64]) -> u64 {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    tofprobe_io::fnv1a64(&bytes)
}

/// The vector files of `run` (driven by `detections`, pixel `p`), each starting with
/// `header` (a `//` line naming the generator); `top` is the array module.
pub fn vector_files(
    run: &ArrayRun,
    detections: &[Vec<Option<u32>>],
    p: &PixelParams,
    top: &str,
    header: &str,
) -> Vec<(String, String)> {
    let ro = &run.readout;
    // The pixels present (a tile of a large array, or all).
    let np = detections.len();
    let g = run.superpixel;
    let t = p.tdc_bits as usize;
    let mut params = format!("{header}\n");
    if g > 1 {
        // The SPAD inputs (the harness's and testbench's port widths); absent when G = 1
        // (the inputs are the pixels).
        params.push_str(&format!("`define AR_NS {np}\n"));
    }
    for (k, v) in [
        ("AR_NP", (np / (g * g)).to_string()),
        ("AR_T", t.to_string()),
        ("AR_B", ro.bits.to_string()),
        ("AR_CYCLES", run.cycles().to_string()),
        ("AR_PULSES", run.pulse_cycles.len().max(1).to_string()),
        ("AR_TOP", top.to_string()),
    ] {
        params.push_str(&format!("`define {k} {v}\n"));
    }
    if let Some(c) = run.reset_at {
        // One cycle of `rst` in the middle of the first frame (the testbenches' second
        // reset; absent, power-up's alone).
        params.push_str(&format!("`define AR_RESET_AT {c}\n"));
    }
    let mut stim = format!("{header}\n");
    for n in 0..run.pulse_cycles.len().max(1) {
        let mut bits = vec![false; np * (t + 1)];
        for (i, d) in detections.iter().enumerate() {
            if let Some(Some(code)) = d.get(n) {
                bits[i] = true;
                for b in 0..t {
                    bits[np + i * t + b] = (code >> b) & 1 == 1;
                }
            }
        }
        stim.push_str(&hex_of_bits(&bits));
        stim.push('\n');
    }
    let mut expect = format!("{header}\n");
    for pin in &run.pins {
        expect.push_str(&format!(
            "{} {} {} {:x}\n",
            u8::from(pin.pulse_o),
            u8::from(pin.ready),
            u8::from(pin.ro_valid),
            pin.ro_data
        ));
    }
    let mut readout =
        format!("{header}\n# frame row col: words 0..R-1 then the status word (hex, W bits)\n");
    let mut digests = format!("{header}\n# frame row col fnv1a64(words)\n");
    for (f, frame) in run.words.iter().enumerate() {
        for (&q, words) in run.positions.iter().zip(frame) {
            let (r, c) = ro.order(q);
            let list: Vec<String> = words.iter().map(|w| format!("{w:x}")).collect();
            readout.push_str(&format!("{f} {r} {c}: {}\n", list.join(" ")));
            digests.push_str(&format!("{f} {r} {c} {:016x}\n", digest(words)));
        }
    }
    FILES
        .iter()
        .map(|s| s.to_string())
        .zip([params, stim, expect, readout, digests])
        .collect()
}
