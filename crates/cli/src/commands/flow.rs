//! `tofprobe flow [CONFIG]`: the main flow. Scene → bit-true model → RTL → golden vectors →
//! Verilator co-simulation → a short report (spectrum at the bins, register widths,
//! verdict) in the output directory. Installs nothing: a missing tool is named together
//! with scripts/install-tools.sh.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_rtlgen::model::sext;
use tofprobe_rtlgen::params::Mode;
use tofprobe_rtlgen::write::write_atomic;

use crate::commands::rtl::rtl_params;
use crate::config::Config;
use crate::error::CliError;

/// Arguments of `tofprobe flow`.
#[derive(Debug, Args)]
pub struct FlowArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Output directory (RTL, vectors, report.md).
    #[arg(long, default_value = "flow-out")]
    pub out: PathBuf,
    /// Pulses per frame N (default: 65536, a short frame; the configuration's own N with
    /// --full-frame).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
    /// Use the configuration's frame length (the default's is 10^7 pulses, ~1 min).
    #[arg(long)]
    pub full_frame: bool,
    /// Frames.
    #[arg(long, default_value_t = 1)]
    pub frames: u64,
}

/// Runs `tofprobe flow`.
pub fn run(a: &FlowArgs) -> Result<(), CliError> {
    if a.frames == 0 || a.frames > 100 {
        return Err(CliError::Option {
            option: "frames".into(),
            value: a.frames.to_string(),
            allowed: "1..=100".into(),
        });
    }
    let loaded = Config::load(a.config.as_deref())?;
    let n_override = if a.full_frame {
        a.frame_pulses
    } else {
        Some(a.frame_pulses.unwrap_or(65_536))
    };
    let p = rtl_params(a.config.as_deref(), n_override, None)?;
    // Scene → TDC stream.
    let source = loaded.config.photon_source().map_err(|e| loaded.error(e))?;
    let mut stim = vec![None; (a.frames * p.frame_pulses) as usize];
    source.fill(0, &mut stim);
    let mut o = CosimOptions::new(&a.out);
    o.frames = a.frames;
    o.seed = loaded.config.acquisition.seed;
    o.stimulus = Some(stim);
    if a.frames * p.frame_pulses * p.cycles_per_pulse as u64 > 2_000_000 {
        o.digest_pulses = 1024;
        o.profile = tofprobe_cosim::BuildProfile::Speed;
    }
    let r = cosim(&p, &o)?;
    let lsb_mm = loaded.config.sensor.tdc_lsb_mm();
    let scale = lsb_mm / f64::from(1u32 << p.effective_frac_bits());
    let mut md = String::new();
    let _ = writeln!(md, "# tofprobe flow report\n");
    let _ = writeln!(
        md,
        "Configuration: {} (hash {}), {:?} mode, N = {} pulses/frame, {} frame(s), L = {}.\n",
        loaded.origin,
        p.config_hash(),
        p.mode,
        p.frame_pulses,
        a.frames,
        p.rom_depth
    );
    let _ = writeln!(md, "## Verdict\n");
    let _ = writeln!(
        md,
        "Co-simulation (Verilator vs reference model): **{}**, {} cycles, {} mismatches, {:.2} s.{}\n",
        if r.pass { "PASS" } else { "FAIL" },
        r.cycles,
        r.outcome.mismatches,
        r.verilator_seconds,
        r.first
            .as_ref()
            .map(|m| format!(
                " First mismatch: cycle {} pulse {} {} expected {} actual {}.",
                m.cycle, m.pulse, m.signal, m.expected, m.actual
            ))
            .unwrap_or_default()
    );
    let _ = writeln!(md, "## Register widths\n");
    let _ = writeln!(
        md,
        "{} registers x W = {} bits ({} bits of readout per frame); operand {} bits (T = {}, F = {}); TDC LSB {:.4} mm.\n",
        p.registers(),
        p.width,
        p.registers() as u64 * u64::from(p.width),
        p.operand_bits(),
        p.tdc_bits,
        p.effective_frac_bits(),
        lsb_mm
    );
    if let Some(f) = r.readouts.first() {
        if p.mode == Mode::Fourier {
            let _ = writeln!(
                md,
                "## Spectrum at the bins (frame 0, sign probes: bin k at (k+1)·f_s/L)\n"
            );
            let _ = writeln!(
                md,
                "| bin | f (Hz) | I | Q | 2/N·abs(Y) (mm) |\n|---|---|---|---|---|"
            );
            let fs = loaded.config.sensor.laser_rate_hz;
            for k in 0..p.bins {
                let i = sext(f[2 * k], p.width) as f64;
                let q = sext(f[2 * k + 1], p.width) as f64;
                let mag = 2.0 / p.frame_pulses as f64 * (i * i + q * q).sqrt() * scale;
                let hz = (k as f64 + 1.0) * fs / p.rom_depth as f64;
                let _ = writeln!(md, "| {k} | {hz:.1} | {i} | {q} | {mag:.6} |");
            }
        } else {
            let _ = writeln!(md, "## Haar coefficients (frame 0)\n");
            let words: Vec<String> = f[..p.registers()]
                .iter()
                .map(|w| sext(*w, p.width).to_string())
                .collect();
            let _ = writeln!(md, "{}", words.join(" "));
        }
    }
    let path = a.out.join("report.md");
    write_atomic(&path, md.as_bytes())?;
    println!(
        "flow {}: {} cycles co-simulated, {} mismatches; report {}",
        if r.pass { "PASS" } else { "FAIL" },
        r.cycles,
        r.outcome.mismatches,
        path.display()
    );
    if r.pass {
        Ok(())
    } else {
        std::process::exit(1)
    }
}
