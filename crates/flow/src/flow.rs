//! The main flow (`tofprobe flow`). Scene → bit-true model → RTL → golden vectors →
//! Verilator co-simulation → a short report (spectrum at the bins, register widths,
//! verdict, sizing summary; a Haar pixel's transient analysis and `scalogram.svg`) in the
//! output directory. Installs nothing: a missing tool is
//! named together with scripts/install-tools.sh.
//!
//! The ROM is the configuration's ΣΔ probe ROM (`probe_rom`); its bins come from the scene
//! (`autobins`) for the frame actually simulated. The default short frame is whole periods
//! of a periodic ROM ([`periodic_short_frame`]: the default's 60,000 = 3 × 20,000), and for
//! a windowed ROM is chosen so that the scene's strongest in-band tone sits exactly on a
//! bin (see [`short_frame`]): a windowed readout off a bin loses up to the window's
//! scalloping (≈ 12 % for Blackman at half a bin), which would hide whether the chain
//! reads the right amplitude.

mod steps;

use std::fmt::Write as _;
use std::path::PathBuf;

use tofprobe_design::ResolvedDesign;
use tofprobe_io::markdown::Table;
use tofprobe_pixel::fixed::sign_extend as sext;

use crate::error::FlowError;
use crate::sizing::SizeOptions;
use steps::FlowRun;

/// What the flow runs on a design.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowOptions {
    /// Output directory (RTL, vectors, report.md).
    pub out: PathBuf,
    /// Pulses per frame N (default: a short frame of at most [`SHORT_FRAME`] pulses on
    /// which the scene's strongest tone sits on a bin; the design's own N with
    /// `full_frame`).
    pub frame_pulses: Option<u64>,
    /// Use the design's frame length.
    pub full_frame: bool,
    /// Frames (1..=100).
    pub frames: u64,
    /// Skip the sizing summary.
    pub no_size: bool,
    /// Include the sky130 area-only mapping in the sizing summary.
    pub sky130: bool,
    /// Sign off the co-simulated RTL: synthesis, gate-level replay of the same vectors and
    /// equivalence on every library found ([`crate::signoff`]); short frames only.
    pub signoff: bool,
    /// The options study that chose this design (`flow --recommended`): the report opens
    /// with the recommendation and carries the options table.
    pub options: Option<tofprobe_experiments::options::OptionsReport>,
}

/// What the flow found.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowOutcome {
    /// Whether the co-simulation (and, when asked, every library's sign-off) passed.
    pub pass: bool,
    /// Pulses per frame simulated.
    pub frame_pulses: u64,
    /// Cycles co-simulated.
    pub cycles: u64,
    /// Mismatching cycles.
    pub mismatches: u64,
    /// Wall time of the flow (s).
    pub seconds: f64,
    /// One line on the readout (the strongest bin, or the Haar coefficients).
    pub headline: String,
    /// The sizing summary line (or why it is missing).
    pub size_line: String,
    /// The report written.
    pub report: PathBuf,
    /// The sign-off per library (empty without `signoff`).
    pub signoff: Vec<crate::signoff::SignoffLine>,
}

/// Frames a flow co-simulates (its option `frames`).
pub const FRAMES: std::ops::RangeInclusive<u64> = 1..=100;

/// Refuses a frame count out of [`FRAMES`], naming `frames`.
pub fn check_frames(frames: u64) -> Result<(), FlowError> {
    if FRAMES.contains(&frames) {
        Ok(())
    } else {
        Err(FlowError::option("frames", frames, "1..=100"))
    }
}

/// Longest default short frame of the flow.
pub const SHORT_FRAME: u64 = 65_536;

/// The flow's default frame: the longest N in [SHORT_FRAME/2, SHORT_FRAME] for which the
/// strongest tone below `band_hz` is a whole number of cycles per frame (f·N/f_s an integer,
/// so a windowed ROM of depth N has a bin on it), else SHORT_FRAME. The default's 4.5 kHz
/// at 10 MHz gives N = 60 000, bin 27.
pub fn short_frame(tones: &[(f64, f64)], sample_rate_hz: f64, band_hz: f64) -> u64 {
    let strongest = tones
        .iter()
        .filter(|(f, a)| *f > 0.0 && *f < band_hz && a.is_finite())
        .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()));
    let Some(&(f, _)) = strongest else {
        return SHORT_FRAME;
    };
    (SHORT_FRAME / 2..=SHORT_FRAME)
        .rev()
        .find(|&n| {
            let k = f * n as f64 / sample_rate_hz;
            // Relative tolerance: k is a few hundred at most, f and f_s are exact decimals.
            (k - k.round()).abs() < 1e-9 * k.max(1.0) && k.round() >= 1.0
        })
        .unwrap_or(SHORT_FRAME)
}

/// The flow's default frame for a periodic ROM of depth L: the most whole periods that fit
/// in [`SHORT_FRAME`], at least one (the default's L = 20,000 gives 60,000).
pub fn periodic_short_frame(l: u64) -> u64 {
    (SHORT_FRAME / l.max(1)).max(1) * l.max(1)
}

/// `flow --recommended`: the architecture options of `design` measured (accuracy over the
/// default seeds, synthesis and timing on osu018 and the sky130 PDK when found, the
/// synthesis cache of `tofprobe size`), the recommendation for `target_error_um` among
/// `only` (all when empty), and the pixel it recommends — `design` with the option's
/// `[pixel]` keys, `adders = "auto"` decided again for it.
pub fn recommended(
    design: &ResolvedDesign,
    only: Vec<String>,
    target_error_um: f64,
) -> Result<(ResolvedDesign, tofprobe_experiments::options::OptionsReport), FlowError> {
    let size = SizeOptions {
        liberty: None,
        no_sky130: false,
        sky130_pdk: None,
        node_nm: 40.0,
        sweep_bins: None,
        sweep_widths: None,
        cache: None,
        // The study compares options at their own clocks; a missed corner's remedy is
        // `tofprobe size`'s.
        corner_trials: 0,
    };
    let req = crate::sizing::options_request(
        design,
        &size,
        only,
        tofprobe_experiments::options::DEFAULT_SEEDS.to_vec(),
        target_error_um,
    )?;
    let report = tofprobe_experiments::options::run(design, &req)?;
    let chosen = tofprobe_experiments::options::recommended_design(design, &report)?;
    Ok((crate::adders::decide(chosen)?, report))
}

/// Runs the flow on `design` and writes its report into `a.out`, the directory one output
/// set ([`crate::flowset`]): the old report and marker go first, the new marker last, and a
/// failed flow removes the directory if it created it.
pub fn run_flow(design: &ResolvedDesign, a: &FlowOptions) -> Result<FlowOutcome, FlowError> {
    check_frames(a.frames)?;
    // Before minutes of co-simulation, not after: a hand-written report.md stays.
    refuse_foreign_report(&a.out.join("report.md"))?;
    let created = crate::flowset::open(&a.out)?;
    let r = run_flow_in(design, a);
    if r.is_err() {
        crate::flowset::discard(&a.out, created);
    }
    r
}

/// The flow's steps in order; the report's sections are written as their step runs.
fn run_flow_in(design: &ResolvedDesign, a: &FlowOptions) -> Result<FlowOutcome, FlowError> {
    let t_start = std::time::Instant::now();
    let mut run = FlowRun::new(design, a)?;
    let r = run.cosimulate()?;
    run.write_verdict(&r);
    run.write_widths();
    let headline = run.write_readout(&r)?;
    let size_line = run.size_line();
    run.write_sizing(&size_line);
    let signoff = run.sign_off(&r)?;
    run.finish(t_start, &r, headline, size_line, signoff)
}

/// First line of every flow report: a `report.md` that does not start with it was written by
/// someone else and is never replaced.
pub(crate) const REPORT_TITLE: &str = "# tofprobe flow report";

/// Refuses to replace a `report.md` that the flow did not write.
pub(crate) fn refuse_foreign_report(path: &std::path::Path) -> Result<(), FlowError> {
    match std::fs::read(path) {
        Ok(bytes) if !bytes.starts_with(REPORT_TITLE.as_bytes()) => {
            Err(tofprobe_rtlgen::RtlError::Foreign {
                path: path.to_path_buf(),
            }
            .into())
        }
        _ => Ok(()),
    }
}

/// Writes the spectrum table of a Fourier readout `f` (raw W-bit words) into `md`: with the
/// ΣΔ ROM, normalised to µm (`tofprobe_pixel::spectrum::phasors`, the one readout → phasor
/// function); with the sign probe, raw. Returns a
/// one-line headline (the strongest bin).
fn spectrum(
    md: &mut String,
    p: &tofprobe_pixel::PixelParams,
    f: &[u64],
    sd: Option<&tofprobe_dsp::sd::ProbeRom>,
    lsb_mm: f64,
) -> String {
    let Some(rom) = sd else {
        let frac = f64::from(1u32 << p.register_frac_bits());
        let _ = writeln!(
            md,
            "## Spectrum at the bins (frame 0, sign-of-cosine probes: unnormalised)\n"
        );
        let mut t = Table::left(["bin", "I (codes)", "Q (codes)"]);
        for k in 0..p.bins {
            let i = sext(f[2 * k], p.width) as f64 / frac;
            let q = sext(f[2 * k + 1], p.width) as f64 / frac;
            t.row([k.to_string(), i.to_string(), q.to_string()]);
        }
        let _ = writeln!(md, "{t}");
        return "sign-probe ROM: spectrum not normalised".into();
    };
    // The frame's register words (the readout ends with the status word).
    let words: Vec<i64> = f
        .iter()
        .take(2 * p.bins)
        .map(|&w| sext(w, p.width))
        .collect();
    let bins = match tofprobe_pixel::spectrum::phasors(p, rom, &words, p.frame_pulses, lsb_mm) {
        Ok(b) => b,
        Err(e) => {
            let _ = writeln!(
                md,
                "## Spectrum at the bins

not normalised: {e}
"
            );
            return format!("spectrum not normalised: {e}");
        }
    };
    let _ = writeln!(
        md,
        "## Spectrum at the bins (frame 0, ΣΔ ROM)\n\nAmplitude = |I − jQ| · 2/N / (G · A_p · |H_pre(f_k)|) · LSB, with N = {}, G = {:.4} ({} window), A_p = {}, α = 2^-{}, LSB = {:.4} mm. I and Q in TDC codes.\n",
        p.frame_pulses,
        rom.coherent_gain,
        rom.window.name(),
        rom.amplitude,
        p.shift,
        lsb_mm
    );
    let mut t = Table::left([
        "reg pair",
        "k",
        "f (Hz)",
        "I",
        "Q",
        "abs(H_pre)",
        "amplitude (µm)",
        "phase (deg)",
    ]);
    let mut best = (0usize, f64::MIN);
    for (b, r) in bins.iter().enumerate() {
        if r.amplitude_um > best.1 {
            best = (b, r.amplitude_um);
        }
        t.row([
            b.to_string(),
            rom.bin_indices[b].to_string(),
            format!("{:.1}", rom.bins[b]),
            format!("{:.3}", r.i_codes),
            format!("{:.3}", r.q_codes),
            format!("{:.4}", r.prefilter_gain),
            format!("{:.2}", r.amplitude_um),
            format!("{:.1}", r.phase_deg),
        ]);
    }
    let _ = writeln!(md, "{t}");
    // Noise estimate: the median of the other bins (autobins' noise bins keep clear of the
    // tones' main lobes, so they read the floor: photon jitter and ΣΔ noise over N pulses).
    let mut rest: Vec<f64> = bins.iter().skip(1).map(|r| r.amplitude_um).collect();
    rest.sort_by(f64::total_cmp);
    let floor = rest.get(rest.len() / 2).copied().unwrap_or(0.0);
    let _ = writeln!(
        md,
        "Noise estimate (median of bins 1..): {floor:.2} µm; it falls as 1/√N (a short frame reads a 100 µm tone only to ± this).\n"
    );
    match bins.first() {
        Some(r) => format!(
            "bin 0 ({:.1} Hz) reads {:.2} µm, noise estimate {floor:.2} µm; strongest bin {:.1} Hz",
            rom.bins[0], r.amplitude_um, rom.bins[best.0]
        ),
        None => "no bins".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_short_frame_is_whole_periods() {
        assert_eq!(periodic_short_frame(20_000), 60_000);
        assert_eq!(periodic_short_frame(65_536), 65_536);
        assert_eq!(periodic_short_frame(100_000), 100_000);
        assert_eq!(periodic_short_frame(7), 65_534);
    }

    #[test]
    fn short_frame_puts_the_strongest_tone_on_a_bin() {
        // 4.5 kHz at 10 MHz: f·N/f_s = 9N/20000 is an integer iff 20000 | N; the largest
        // such N ≤ 65536 is 60000 (bin 27), whatever the weaker tones are.
        let tones = [(4500.0, 0.1), (7000.0, 0.01)];
        assert_eq!(short_frame(&tones, 10e6, 156_250.0), 60_000);
        // No tone, or the only tone out of band: the plain short frame.
        assert_eq!(short_frame(&[], 10e6, 156_250.0), SHORT_FRAME);
        assert_eq!(short_frame(&[(2e5, 0.1)], 10e6, 156_250.0), SHORT_FRAME);
        // 1 kHz at 10 MHz: 10000 | N, so 60000 again; 2^16 itself when f = f_s/2^10.
        assert_eq!(short_frame(&[(1000.0, 0.1)], 10e6, 156_250.0), 60_000);
        assert_eq!(
            short_frame(&[(10e6 / 1024.0, 0.1)], 10e6, 156_250.0),
            SHORT_FRAME
        );
    }
}
