//! Golden vector files (format: testbench/README.md): plain hex text that `$readmemh` and
//! the C++ harness read, plus a TOML manifest naming the configuration, seed, counts,
//! widths and a hash of every file.

use crate::error::RtlError;
use crate::golden::{self, Golden, GoldenOptions};
use crate::naming::config_hash;
use crate::render::{HEADER_MARK, rom_entry_hex};
use crate::write::write_generated;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use tofprobe_io::fnv1a64;
use tofprobe_pixel::{DirectedOptions, Mode, PixelParams};

/// Above this many cycles the full trace is replaced by digests only (a full trace of a
/// 1.6·10^8-cycle frame would run to gigabytes).
pub const FULL_TRACE_MAX_CYCLES: u64 = 2_000_000;

/// What to generate.
#[derive(Debug, Clone)]
pub struct VectorOptions {
    pub frames: u64,
    pub seed: u64,
    /// Pulses per digest window.
    pub digest_pulses: u64,
    /// Cycles [lo, hi) recorded in full; `None` = everything if short, nothing if long.
    pub trace_window: Option<(u64, u64)>,
    /// Drive the directed sequencer (`frames` loops of its program) instead of the
    /// reference one; the RTL must be rendered with the same options.
    pub directed: Option<DirectedOptions>,
}

impl Default for VectorOptions {
    fn default() -> Self {
        VectorOptions {
            frames: 2,
            seed: 1,
            digest_pulses: 1,
            trace_window: None,
            directed: None,
        }
    }
}

/// The manifest written as `manifest.toml`.
#[derive(Debug, Clone, Serialize)]
pub struct Manifest {
    pub generator: String,
    pub config_hash: String,
    pub mode: String,
    pub seed: u64,
    pub frames: u64,
    pub pulses: u64,
    pub cycles: u64,
    pub registers: usize,
    pub width: u32,
    pub tdc_bits: u32,
    pub frame_pulses: u64,
    pub cycles_per_pulse: usize,
    pub rom_depth: usize,
    pub digest_pulses: u64,
    pub trace_from: u64,
    pub trace_to: u64,
    pub trace_events: usize,
    pub pin_events: usize,
    pub digest_windows: usize,
    /// The directed sequencer's options, when it drove the run (absent: the reference
    /// sequencer).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub directed: Option<String>,
    /// File name → FNV-1a-64 of its bytes (hex).
    pub files: BTreeMap<String, String>,
}

/// Runs the pixel crate's cycle model (the one model, the judge of the RTL) through the
/// contract's sequence for `stim`/`rom` and returns the golden data plus the effective
/// trace window. Fails when the pixel does not accept the parameters or the ROM.
pub fn golden_run(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    o: &VectorOptions,
) -> Result<(Golden, (u64, u64)), RtlError> {
    let (stim, program) = golden::stimuli_and_program(p, stim, o.frames, o.directed.as_ref())?;
    let image = golden::rom_image(p, rom);
    let seq = golden::sequence_for(p, &stim, image.as_ref(), o.frames, program)?;
    let total = seq.total_cycles();
    let window = o.trace_window.unwrap_or(if total <= FULL_TRACE_MAX_CYCLES {
        (0, total)
    } else {
        (0, 0)
    });
    let g = golden::run(
        p,
        &seq,
        &GoldenOptions {
            frames: o.frames,
            digest_pulses: o.digest_pulses.max(1),
            trace_window: window,
        },
    )?;
    Ok((g, window))
}

fn head(what: &str, p: &PixelParams) -> String {
    format!(
        "{HEADER_MARK} (vectors): {what}. Configuration hash {}. DO NOT EDIT.\n",
        config_hash(p)
    )
}

/// Writes the vector files for the golden data into `dir` and returns the manifest.
pub fn write_vectors(
    dir: &Path,
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    g: &Golden,
    window: (u64, u64),
    o: &VectorOptions,
) -> Result<Manifest, RtlError> {
    let r = p.registers();
    let mut files: Vec<(String, String)> = Vec::new();

    let mut s = head("per pulse: bit 16 = valid, bits 15..0 = tdc", p);
    s.reserve(stim.len() * 6);
    for d in stim.iter().take(g.pulses as usize) {
        let v = d.map_or(0, |c| (1u32 << 16) | c);
        let _ = writeln!(s, "{v:05x}");
    }
    files.push(("stimulus.hex".into(), s));

    if p.mode == Mode::Fourier {
        let words = r.div_ceil(64);
        let mut s = head("probe ROM, one R-bit word per address", p);
        for a in 0..p.rom_depth {
            s.push_str(&rom_entry_hex(&rom[a * words..(a + 1) * words], r));
            s.push('\n');
        }
        files.push(("rom.hex".into(), s));
    }

    let mut s = head("per frame: R register words then the status word", p);
    for f in &g.readouts {
        for w in f {
            let _ = writeln!(s, "{w:016x}");
        }
    }
    files.push(("readout.hex".into(), s));

    let mut s = head("register writes: cycle(48) register(16) value(64)", p);
    for &(c, reg, v) in &g.trace {
        let _ = writeln!(s, "{c:012x}{reg:04x}{v:016x}");
    }
    files.push(("trace.hex".into(), s));

    let mut s = head(
        "pin changes: cycle(48) flags(4: ready, rd_valid) rd_index(12) rd_data(64)",
        p,
    );
    for (c, o) in &g.pins {
        let flags = u8::from(o.ready) | (u8::from(o.rd_valid) << 1);
        let _ = writeln!(s, "{c:012x}{flags:x}{:03x}{:016x}", o.rd_index, o.rd_data);
    }
    files.push(("pins.hex".into(), s));

    let mut s = head("per digest window: event count(32) digest(64)", p);
    for &(n, h) in &g.digests {
        let _ = writeln!(s, "{n:08x}{h:016x}");
    }
    files.push(("digest.hex".into(), s));

    // Plain key/value facts for the harness and a Verilog include for the testbench.
    let kv = [
        ("registers", r as u64),
        ("width", u64::from(p.width)),
        ("tdc_bits", u64::from(p.tdc_bits)),
        ("rd_index_bits", u64::from(p.rd_index_bits())),
        (
            "readout_words",
            g.readouts.iter().map(|f| f.len() as u64).sum(),
        ),
        ("stimulus_lines", g.pulses.min(stim.len() as u64)),
        ("frames", o.frames),
        ("pulses", g.pulses),
        ("cycles", g.cycles),
        ("digest_pulses", o.digest_pulses.max(1)),
        ("trace_from", window.0),
        ("trace_to", window.1),
        ("trace_events", g.trace.len() as u64),
        ("pin_events", g.pins.len() as u64),
        ("digest_windows", g.digests.len() as u64),
    ];
    let mut cfg = head("harness settings, `key value` per line", p);
    let mut vh = head("testbench settings", p);
    for (k, v) in kv {
        let _ = writeln!(cfg, "{k} {v}");
        let _ = writeln!(vh, "localparam integer TB_{} = {v};", k.to_uppercase());
    }
    files.push(("vectors.cfg".into(), cfg));
    files.push(("tb_params.vh".into(), vh));

    let manifest = Manifest {
        generator: format!("tofprobe-rtlgen {}", env!("CARGO_PKG_VERSION")),
        config_hash: config_hash(p),
        mode: format!("{:?}", p.mode).to_lowercase(),
        seed: o.seed,
        frames: o.frames,
        pulses: g.pulses,
        cycles: g.cycles,
        registers: r,
        width: p.width,
        tdc_bits: p.tdc_bits,
        frame_pulses: p.frame_pulses,
        cycles_per_pulse: p.cycles_per_pulse,
        rom_depth: p.rom_depth,
        digest_pulses: o.digest_pulses.max(1),
        trace_from: window.0,
        trace_to: window.1,
        trace_events: g.trace.len(),
        pin_events: g.pins.len(),
        digest_windows: g.digests.len(),
        directed: o.directed.map(|d| {
            format!(
                "long_frame = {}, lead_misses = {}",
                d.long_frame, d.lead_misses
            )
        }),
        files: files
            .iter()
            .map(|(n, c)| (n.clone(), format!("{:016x}", fnv1a64(c.as_bytes()))))
            .collect(),
    };
    let mut m = format!("#{}", &head("vector manifest", p)[2..]);
    m.push_str(&toml::to_string(&manifest).map_err(|e| RtlError::Render {
        template: "manifest.toml",
        message: e.to_string(),
    })?);
    files.push(("manifest.toml".into(), m));
    write_generated(dir, &files)?;
    Ok(manifest)
}
