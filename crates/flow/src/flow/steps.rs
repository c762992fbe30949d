//! The steps of [`super::run_flow`] (its `run_flow_in`), one function each, over one
//! [`FlowRun`]: the frame, the chip, the co-simulation, then the report's sections in
//! order (verdict, register widths, readout, sizing, sign-off) and the sealed output set.

use std::fmt::Write as _;
use std::time::Instant;

use tofprobe_cosim::{CosimOptions, CosimReport, cosim};
use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose, RtlRom};
use tofprobe_pixel::{Mode, PixelParams};
use tofprobe_rtlgen::write::write_atomic;

use super::{
    FlowOptions, FlowOutcome, REPORT_TITLE, SHORT_FRAME, periodic_short_frame,
    refuse_foreign_report, short_frame, spectrum,
};
use crate::error::FlowError;
use crate::sizing::{SizeOptions, size_report};

/// The pulses per frame the flow simulates: the design's own N with `full_frame` (or the
/// one asked), else a short frame — a Haar frame (a power of two, no bins to align), whole
/// periods of a periodic ROM, or a windowed ROM's frame with the strongest tone on a bin.
pub(super) fn frame_override(design: &ResolvedDesign, a: &FlowOptions) -> Option<u64> {
    let config = &design.document;
    let fs = config.sensor.laser_rate_hz;
    if a.full_frame {
        return a.frame_pulses;
    }
    let band = fs / (2.0 * config.probe.osr);
    let haar = design.pixel.mode == Mode::Haar;
    let probe = &config.probe;
    let periodic = probe.rom_mode == tofprobe_dsp::sd::RomMode::Periodic;
    Some(if haar {
        a.frame_pulses.unwrap_or(SHORT_FRAME)
    } else if periodic {
        // The bins are already on the ROM's grid: whole periods, as many as fit.
        a.frame_pulses
            .unwrap_or_else(|| periodic_short_frame(probe.rom_depth as u64))
    } else {
        a.frame_pulses
            .unwrap_or_else(|| short_frame(design.tones(), fs, band))
    })
}

/// The flow under way: the pixel and ROM simulated, and `report.md` as written so far.
pub(super) struct FlowRun<'a> {
    design: &'a ResolvedDesign,
    a: &'a FlowOptions,
    p: PixelParams,
    rom: RtlRom,
    md: String,
}

impl<'a> FlowRun<'a> {
    /// The chip at the flow's frame; a trace too long for gate level is refused at once,
    /// before the co-simulation.
    pub(super) fn new(design: &'a ResolvedDesign, a: &'a FlowOptions) -> Result<Self, FlowError> {
        let overrides = RtlOverrides {
            frame_pulses: frame_override(design, a),
            rom_depth: None,
        };
        let chip = Chip::of(design, &overrides, RomPurpose::Configured)?;
        let (p, rom) = (chip.pixel, chip.rom);
        if a.signoff {
            crate::signoff::check_length(&p, a.frames)?;
        }
        Ok(FlowRun {
            design,
            a,
            p,
            rom,
            md: String::new(),
        })
    }

    /// Scene → TDC stream → the co-simulation of the rendered RTL (digests and the fast
    /// build beyond 2 M cycles).
    pub(super) fn cosimulate(&self) -> Result<CosimReport, FlowError> {
        let (a, p) = (self.a, &self.p);
        let source = self.design.photon_source()?;
        let mut stim = vec![None; (a.frames * p.frame_pulses) as usize];
        source.fill(0, &mut stim);
        let mut o = CosimOptions::new(&a.out);
        o.frames = a.frames;
        o.seed = self.design.document.acquisition.seed;
        o.stimulus = Some(stim);
        o.rom = Some(self.rom.words.clone());
        if a.frames * p.frame_pulses * p.cycles_per_pulse as u64 > 2_000_000 {
            o.digest_pulses = 1024;
            o.profile = tofprobe_cosim::BuildProfile::Speed;
        }
        Ok(cosim(p, &o)?)
    }

    /// The title, the configuration, the recommendation (`flow --recommended`) and the
    /// co-simulation's verdict.
    pub(super) fn write_verdict(&mut self, r: &CosimReport) {
        let (md, p, a) = (&mut self.md, &self.p, self.a);
        let _ = writeln!(md, "{REPORT_TITLE}\n");
        let _ = writeln!(
            md,
            "Configuration: {} (hash {}), {:?} mode, N = {} pulses/frame, {} frame(s), L = {}.\n\nROM: {}.\n",
            tofprobe_io::text::sanitize(&self.design.origin),
            tofprobe_rtlgen::config_hash(p),
            p.mode,
            p.frame_pulses,
            a.frames,
            p.rom_depth,
            self.rom.note
        );
        if let Some(o) = &a.options {
            let _ = writeln!(
                md,
                "## Recommended architecture\n\nThis pixel is the option `{}` that `tofprobe size --options` recommends (target: tone error ≤ {} µm against the float DFT; the table below).\n",
                o.recommendation.option, o.target_error_um
            );
        }
        let _ = writeln!(md, "## Verdict\n");
        let _ = writeln!(
            md,
            "Co-simulation (Verilator vs the pixel crate's cycle model): **{}**, {} cycles, {} mismatches, Verilator {:.2} s, model {:.2} s (the model {:.1}x Verilator).{}\n",
            if r.pass { "PASS" } else { "FAIL" },
            r.cycles,
            r.outcome.mismatches,
            r.verilator_seconds,
            r.model_seconds,
            r.model_speedup(),
            r.first
                .as_ref()
                .map(|m| format!(
                    " First mismatch: cycle {} pulse {} {} expected {} actual {}.",
                    m.cycle, m.pulse, m.signal, m.expected, m.actual
                ))
                .unwrap_or_default()
        );
    }

    /// The registers, the operand and the TDC's LSB.
    pub(super) fn write_widths(&mut self) {
        let (md, p) = (&mut self.md, &self.p);
        let _ = writeln!(md, "## Register widths\n");
        let _ = writeln!(
            md,
            "{} registers x W = {} bits ({} bits of readout per frame); operand {} bits (T = {}, F = {}{}); TDC LSB {:.4} mm.\n",
            p.registers(),
            p.width,
            p.registers() as u64 * u64::from(p.width),
            p.operand_bits(),
            p.tdc_bits,
            p.effective_frac_bits(),
            // G only where it differs from F, so the default's report reads as before.
            if p.register_frac_bits() < p.effective_frac_bits() {
                format!(", G = {}", p.register_frac_bits())
            } else {
                String::new()
            },
            self.design.document.sensor.tdc_lsb_mm()
        );
    }

    /// The first frame's readout: the spectrum at the bins (Fourier) or the transients
    /// and the scalogram (Haar); returns its headline (empty without a frame).
    pub(super) fn write_readout(&mut self, r: &CosimReport) -> Result<String, FlowError> {
        let (p, a) = (&self.p, self.a);
        let lsb_mm = self.design.document.sensor.tdc_lsb_mm();
        let mut headline = String::new();
        if let Some(f) = r.readouts.first() {
            let md = &mut self.md;
            if p.mode == Mode::Fourier {
                headline = spectrum(md, p, f, self.rom.sd.as_ref(), lsb_mm);
            } else {
                headline =
                    tofprobe_experiments::transients::flow_section(md, self.design, p, f, &a.out)?;
            }
        }
        Ok(headline)
    }

    /// The sizing summary of the configured point, or why it is missing (non-fatal: the
    /// flow's verdict is the co-simulation).
    pub(super) fn size_line(&self) -> String {
        let (a, p) = (self.a, &self.p);
        if a.no_size {
            return "sizing skipped (--no-size)".to_string();
        }
        let sa = SizeOptions {
            liberty: None,
            no_sky130: !a.sky130,
            sky130_pdk: None,
            node_nm: 40.0,
            // The configured point only: the B/W sweeps are `tofprobe size`'s job.
            sweep_bins: Some(vec![p.bins as u64]),
            sweep_widths: Some(vec![p.width]),
            cache: None,
            // The flow reports the corners; the search for the adders that meet a missed
            // one is `tofprobe size`'s (minutes of synthesis).
            corner_trials: 0,
        };
        match size_report(self.design, &sa) {
            Ok(s) => tofprobe_eda::markdown::summary(&s),
            Err(e) => format!(
                "sizing not available ({e}); run scripts/install-tools.sh, or pass --no-size"
            ),
        }
    }

    /// The sizing section, then the options table of `flow --recommended`.
    pub(super) fn write_sizing(&mut self, size_line: &str) {
        let (md, a) = (&mut self.md, self.a);
        let _ = writeln!(
            md,
            "## Sizing\n\n{size_line}{}\n",
            if a.sky130 {
                ""
            } else {
                " (sky130 skipped; --sky130 includes it)"
            }
        );
        if let Some(o) = &a.options {
            *md += &tofprobe_experiments::options::markdown::render(o);
            *md += "\n";
        }
    }

    /// With `signoff`, every library's sign-off of the co-simulated RTL (not run when the
    /// co-simulation failed) and its section.
    pub(super) fn sign_off(
        &mut self,
        r: &CosimReport,
    ) -> Result<Vec<crate::signoff::SignoffLine>, FlowError> {
        let (md, a) = (&mut self.md, self.a);
        let mut signoff = Vec::new();
        if a.signoff {
            let _ = writeln!(md, "## Sign-off\n");
            if r.pass {
                signoff = crate::signoff::sign_off_all(
                    &self.p,
                    self.design.document.sensor.laser_rate_hz,
                    &r.rtl_dir,
                    &r.vectors_dir,
                    &a.out.join("signoff"),
                )?;
                for l in &signoff {
                    let _ = writeln!(md, "- {}", l.text);
                }
                let _ = writeln!(md);
            } else {
                let _ = writeln!(md, "Not run: the co-simulation failed.\n");
            }
        }
        Ok(signoff)
    }

    /// The flow's time, `report.md` written (never over a foreign one) and the output set
    /// sealed.
    pub(super) fn finish(
        mut self,
        t_start: Instant,
        r: &CosimReport,
        headline: String,
        size_line: String,
        signoff: Vec<crate::signoff::SignoffLine>,
    ) -> Result<FlowOutcome, FlowError> {
        let a = self.a;
        let seconds = t_start.elapsed().as_secs_f64();
        let _ = writeln!(self.md, "Flow time: {seconds:.1} s.");
        let path = a.out.join("report.md");
        refuse_foreign_report(&path)?;
        write_atomic(&path, self.md.as_bytes())?;
        crate::flowset::seal(&a.out)?;
        Ok(FlowOutcome {
            pass: r.pass && signoff.iter().all(|l| l.pass()),
            frame_pulses: self.p.frame_pulses,
            cycles: r.cycles,
            mismatches: r.outcome.mismatches,
            seconds,
            headline,
            size_line,
            report: path,
            signoff,
        })
    }
}
