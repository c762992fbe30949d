//! The array's golden vector files (docs/pixel-contract.md "Array"), beside the pixel's
//! ([`crate::vectors`]): the per-input detections, the ports the array model
//! (`tofprobe_array::rtl_model`, run by the flow and handed here as an [`ArrayTrace`]) shows
//! every cycle, the readout stream and per-pixel digests, as the files
//! `testbench/array_harness.cpp` (Verilator) and `testbench/array_tb.v` (Icarus) replay:
//!
//! - `array_params.vh`: `AR_TOP`, `AR_NP` (pixels present: all, or a tile's), `AR_T`,
//!   `AR_B`, `AR_CYCLES`, `AR_PULSES`, and with `[array] superpixel = G > 1` `AR_NS` (the
//!   SPAD inputs, AR_NP·G²), and with a mid-frame reset (`tofprobe_array::rtl_driver::run_with_reset`)
//!   `AR_RESET_AT` (its cycle: `rst` is high then, and in power-up's two cycles);
//! - `array_stim.hex`: one line per pulse the pixels sample, the P·(T+1)-bit value
//!   {tdc[P·T−1:0], valid[P−1:0]} over the P inputs (pixel i = r·cols + c; with G > 1 the
//!   SPADs, i = sr·(cols·G) + sc over the SPAD grid);
//! - `array_expect.hex`: one line per cycle, `pulse_o ready ro_valid ro_data`;
//! - `readout.txt`: per frame and pixel (readout order) its R + 1 words;
//! - `digests.txt`: per frame and pixel, FNV-1a 64 of its words (little-endian u64s).

/// The file names of a vector set, the params include first.
pub const FILES: [&str; 5] = [
    "array_params.vh",
    "array_stim.hex",
    "array_expect.hex",
    "readout.txt",
    "digests.txt",
];

/// Thins the detections of `inputs` (as `tofprobe_flow::array::vectors::scene_detections`
/// orders them: the tile's `cols` pixels a row, G × G SPADs each) so the co-simulation
/// reaches what a bright scene never does (issue 42's mutation study: with every SPAD valid
/// on every pulse, a superpixel whose `valid` is the AND of its SPADs, two crossed SPAD
/// codes or a wrong reciprocal entry passed). At pulse n, pixel p keeps
/// k = (n + p) mod (G² + 1) of its G² SPADs' detections — every count from none to all,
/// exactly one among them — the ones at positions n, n + 1, … mod G² within the superpixel
/// (so each SPAD is the only one in turn); with G = 1 a pixel presents its detection on one
/// pulse in two (the hold and the priming between). Deterministic: the same inputs give the
/// same stimulus.
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

/// The array's ports in one cycle, as `array_expect.hex` holds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArrayPorts {
    /// The pixels sample `valid`/`tdc` this cycle.
    pub pulse_o: bool,
    /// Every pixel's pipeline is free.
    pub ready: bool,
    /// A beat is on `ro_data`.
    pub ro_valid: bool,
    /// The beat (b bits).
    pub ro_data: u64,
}

/// What the array model showed over a run, as plain data: what its vector files hold.
#[derive(Debug, Clone)]
pub struct ArrayTrace<'a> {
    /// b: bits per beat of the output port.
    pub bits: u32,
    /// G: SPADs per pixel side (the inputs are the pixels' × G²).
    pub superpixel: usize,
    /// The ports of every cycle.
    pub ports: Vec<ArrayPorts>,
    /// Pulses the pixels sampled (`pulse_o` cycles).
    pub pulses: usize,
    /// The pixels present, (row, col) in readout order.
    pub pixels: Vec<(usize, usize)>,
    /// Per frame, per pixel present (as `pixels`), its R + 1 words (raw W bits).
    pub words: &'a [Vec<Vec<u64>>],
    /// The cycle of a one-cycle reset in the middle of the run, if any.
    pub reset_at: Option<u64>,
}

/// The vector files of `run` (driven by `detections`, `tdc_bits`-bit codes), each
/// starting with `header` (a `//` line naming the generator); `top` is the array module.
pub fn vector_files(
    run: &ArrayTrace<'_>,
    detections: &[Vec<Option<u32>>],
    tdc_bits: u32,
    top: &str,
    header: &str,
) -> Vec<(String, String)> {
    // The pixels present (a tile of a large array, or all).
    let np = detections.len();
    let g = run.superpixel;
    let t = tdc_bits as usize;
    let mut params = format!("{header}\n");
    if g > 1 {
        // The SPAD inputs (the harness's and testbench's port widths); absent when G = 1
        // (the inputs are the pixels).
        params.push_str(&format!("`define AR_NS {np}\n"));
    }
    for (k, v) in [
        ("AR_NP", (np / (g * g)).to_string()),
        ("AR_T", t.to_string()),
        ("AR_B", run.bits.to_string()),
        ("AR_CYCLES", run.ports.len().to_string()),
        ("AR_PULSES", run.pulses.max(1).to_string()),
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
    for n in 0..run.pulses.max(1) {
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
    for pin in &run.ports {
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
        for (&(r, c), words) in run.pixels.iter().zip(frame) {
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
