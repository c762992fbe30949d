//! `tofprobe flow` on an `[array]` design: the array co-simulated
//! ([`crate::array::cosim`]) and its report written, one output set.

use std::fmt::Write as _;

use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose};
use tofprobe_io::markdown::Table;

use crate::array::cosim::{ArrayCosimOptions, cosim_array};
use crate::error::FlowError;

/// The report's readout section: the configured frame's figures and the comparison with
/// reading every timestamp out (T bits per pixel per laser pulse).
pub fn readout_section(design: &ResolvedDesign, md: &mut String) -> Result<(), FlowError> {
    let Some(ro) = design.readout()? else {
        return Ok(());
    };
    let f_laser = design.sensor().laser_rate_hz;
    let stamps = ro.pixels() as f64 * f_laser * f64::from(design.pixel.tdc_bits);
    let regs = ro.payload_bits_per_frame() as f64 * ro.frame_rate_hz();
    let _ = writeln!(md, "## Readout (docs/pixel-contract.md \"Array\")\n");
    let _ = writeln!(
        md,
        "At the configured frame (N = {} pulses): {} × {} pixels × {} words × {} beat(s) of {} bits = {} bits per frame ({} payload), read in {} cycles = {:.3e} s at f_clk = {:.3e} Hz (one beat every {} cycle(s), {:.3e} bit/s while streaming); a frame every {} cycles: {:.6} Hz, the pixels see {:.4} % of the laser's pulses{}.\n",
        ro.frame_pulses,
        ro.rows,
        ro.cols,
        ro.words_per_pixel(),
        ro.beats_per_word,
        ro.bits,
        ro.stream_bits_per_frame(),
        ro.payload_bits_per_frame(),
        ro.readout_cycles(),
        ro.readout_seconds(),
        ro.clock_hz,
        ro.beat_cycles,
        ro.port_bits_per_s(),
        ro.frame_cycles(),
        ro.frame_rate_hz(),
        100.0 * ro.duty(),
        if ro.double_buffer {
            ", double-buffered"
        } else {
            ""
        }
    );
    let _ = writeln!(
        md,
        "Reading every timestamp out instead: {} pixels × {:.3e} pulses/s × T = {} bits = {:.3e} bit/s ({:.3e} B per pixel per second); the registers need {:.3e} bit/s on average, {:.1}x less.\n",
        ro.pixels(),
        f_laser,
        design.pixel.tdc_bits,
        stamps,
        f_laser * f64::from(design.pixel.tdc_bits) / 8.0,
        regs,
        stamps / regs
    );
    Ok(())
}

/// The array flow's default frame: one period of a periodic ΣΔ ROM (the default's 20,000
/// pulses), else 4096 pulses (a power of two for Haar), never beyond the design's N.
pub fn array_short_frame(design: &ResolvedDesign) -> u64 {
    let probe = &design.document.probe;
    let n = if design.pixel.mode == tofprobe_pixel::Mode::Fourier
        && probe.rom_mode == tofprobe_dsp::sd::RomMode::Periodic
    {
        probe.rom_depth as u64
    } else {
        4096
    };
    n.min(design.pixel.frame_pulses)
}

/// `tofprobe flow` on an `[array]` design: renders the array, co-simulates it under
/// Verilator at its ports against the array model, and writes `report.md` (verdict, the
/// first mismatch named by pixel, register, cycle and pulse, per-pixel digests, the
/// readout at the configured frame and its comparison with reading every timestamp out);
/// the directory is one output set, as the pixel's flow.
pub fn run_array_flow(
    design: &ResolvedDesign,
    a: &crate::flow::FlowOptions,
) -> Result<crate::flow::FlowOutcome, FlowError> {
    if a.signoff {
        return Err(FlowError::option(
            "signoff",
            "true",
            "the pixel's flow (an array is co-simulated here; its synthesis and timing are `tofprobe size`)",
        ));
    }
    crate::flow::check_frames(a.frames)?;
    crate::flow::refuse_foreign_report(&a.out.join("report.md"))?;
    let created = crate::flowset::open(&a.out)?;
    let r = array_flow_in(design, a);
    if r.is_err() {
        crate::flowset::discard(&a.out, created);
    }
    r
}

fn array_flow_in(
    design: &ResolvedDesign,
    a: &crate::flow::FlowOptions,
) -> Result<crate::flow::FlowOutcome, FlowError> {
    let t0 = std::time::Instant::now();
    let n = match (a.full_frame, a.frame_pulses) {
        (_, Some(n)) => Some(n),
        (true, None) => None,
        (false, None) => Some(array_short_frame(design)),
    };
    let mut o = ArrayCosimOptions::new(&a.out);
    o.frame_pulses = n;
    o.frames = a.frames;
    o.command = format!(
        "tofprobe flow {} --out {}",
        tofprobe_io::text::sanitize(&design.origin),
        tofprobe_io::text::path_as_typed(&a.out)
    );
    let r = cosim_array(design, &o)?;
    let ro = &r.readout;
    let mut md = String::new();
    let _ = writeln!(md, "{}\n", crate::flow::REPORT_TITLE);
    let _ = writeln!(
        md,
        "Configuration: {}, a {} × {} array of {:?} pixels ({} registers × W = {} bits), N = {} pulses/frame (simulated), {} frame(s), probe ROM: {}.\n",
        tofprobe_io::text::sanitize(&design.origin),
        ro.rows,
        ro.cols,
        design.pixel.mode,
        ro.registers,
        ro.width,
        ro.frame_pulses,
        a.frames,
        Chip::array_of(
            design,
            &RtlOverrides {
                frame_pulses: n,
                rom_depth: None
            },
            RomPurpose::Replayed
        )?
        .rom
        .note
    );
    let _ = writeln!(md, "## Verdict\n");
    let _ = writeln!(
        md,
        "Co-simulation at the array's ports (Verilator vs the array model `tofprobe_array::rtl_model`): **{}**, {} cycles, {} mismatches; build {:.1} s{}, Verilator {:.2} s, model {:.2} s; {} detections over the {}.{}\n",
        if r.pass { "PASS" } else { "FAIL" },
        r.cycles,
        r.mismatches,
        r.build_seconds,
        if r.reused { " (cached)" } else { "" },
        r.sim_seconds,
        r.model_seconds,
        r.detections,
        match design.array.as_ref().map_or(1, |a| a.superpixel) {
            1 => "pixels".to_string(),
            g => format!("SPADs (superpixels of {g} × {g}, each pixel's averaged)"),
        },
        r.first
            .as_ref()
            .map(|f| format!(" First mismatch: {f}."))
            .unwrap_or_default()
    );
    let _ = writeln!(
        md,
        "The simulated readout: {} beats of {} bits per frame, {} cycles per frame ({} accumulating, {} reading); per-pixel digests in `vectors/digests.txt`.\n",
        ro.beats_per_frame(),
        ro.bits,
        ro.frame_cycles(),
        ro.accumulate_cycles(),
        ro.readout_cycles()
    );
    if let Some(words) = r.run.words.first() {
        let mut t = Table::left(["pixel", "register 0", "register 1", "status"]);
        for (q, w) in words.iter().enumerate().take(16) {
            let (row, col) = ro.order(q);
            let signed = |v: u64| tofprobe_pixel::fixed::sign_extend(v, ro.width);
            t.row([
                format!("({row}, {col})"),
                signed(w[0]).to_string(),
                w.get(1).map(|&v| signed(v)).unwrap_or(0).to_string(),
                w[ro.registers].to_string(),
            ]);
        }
        let _ = writeln!(md, "{t}");
    }
    readout_section(design, &mut md)?;
    let size_line =
        "size: the array's area, pitch and timing are `tofprobe size CONFIG`".to_string();
    let seconds = t0.elapsed().as_secs_f64();
    let _ = writeln!(md, "Flow time: {seconds:.1} s.");
    let path = a.out.join("report.md");
    tofprobe_io::write_atomic(&path, md.as_bytes())
        .map_err(|e| FlowError::output(path.clone(), e.to_string()))?;
    crate::flowset::seal(&a.out)?;
    Ok(crate::flow::FlowOutcome {
        pass: r.pass,
        frame_pulses: ro.frame_pulses,
        cycles: r.cycles,
        mismatches: r.mismatches,
        seconds,
        headline: format!(
            "{} × {} array, {} bits per frame read in {} cycles",
            ro.rows,
            ro.cols,
            ro.stream_bits_per_frame(),
            ro.readout_cycles()
        ),
        size_line,
        report: path,
        signoff: Vec::new(),
    })
}
