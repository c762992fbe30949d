//! The array section of `tofprobe size` as Markdown (appended to the size report's): the
//! pitch, the probe ROM, the area, the broadcast and readout timing, the double buffer and
//! the superpixel, the readout and the comparison with reading every timestamp out.

use tofprobe_eda::array::options::{DoubleBuffer, SuperpixelSize};
use tofprobe_eda::array::timing::PathTiming;
use tofprobe_io::markdown::Table;

use crate::array::report::ArraySizeReport;

/// The array section as Markdown (appended to the size report's).
pub fn markdown(a: &ArraySizeReport) -> String {
    let mut m = format!(
        "\n## The array: {} × {} = {} pixels\n\n",
        a.rows, a.cols, a.pixels
    );
    let mut t = Table::left([
        "library",
        "pixel cell area (µm²)",
        "utilisation",
        "node (nm)",
        "implied pitch (µm)",
    ]);
    for p in &a.pitch {
        t.row([
            p.library.clone(),
            format!("{:.0}", p.cell_area_um2),
            format!("{:.0} %", p.utilisation * 100.0),
            p.node_nm.to_string(),
            format!("{:.1}", p.pitch_um),
        ]);
    }
    m += &t.render();
    m += &format!(
        "\nConfigured pitch {} µm: {}.\n",
        a.configured_pitch_um,
        if a.pitch_fits {
            "the pixel fits it on at least one library"
        } else {
            "the pixel does not fit it on any library measured"
        }
    );
    if let Some(r) = &a.rom {
        m += &format!(
            "\n### The probe ROM (shared, broadcast)\n\n{} entries × {} bits = {} bits ({:.1} kB).\n\n",
            r.depth,
            r.width_bits,
            r.bits,
            r.bits as f64 / 8000.0
        );
        let mut t = Table::left([
            "technology",
            "µm² per bit",
            "ROM macro area (mm², estimate)",
            "basis",
        ]);
        for e in &r.macro_estimates {
            t.row([
                e.technology.to_string(),
                format!("{:.2}", e.um2_per_bit),
                format!("{:.3}", e.area_um2 / 1e6),
                e.basis.to_string(),
            ]);
        }
        m += &t.render();
        let mut t = Table::left([
            "library",
            "entries synthesised",
            "their area (µm²)",
            "cells",
            "whole ROM as logic (mm², scaled)",
        ]);
        for l in &r.logic {
            t.row([
                l.library.clone(),
                l.synthesised_depth.to_string(),
                format!("{:.0}", l.synthesised_area_um2),
                l.synthesised_cells.to_string(),
                format!("{:.3}", l.area_um2 / 1e6),
            ]);
        }
        m += &format!("\n{t}");
    }
    let mut area = Table::left([
        "library",
        "pixels (mm²)",
        "ROM macro (mm², estimate)",
        "shared logic (mm²)",
        "total (mm²)",
        "pixels' share",
    ]);
    for t in &a.totals {
        area.row([
            t.library.clone(),
            format!("{:.3}", t.pixels_um2 / 1e6),
            format!("{:.3}", t.rom_macro_um2 / 1e6),
            t.shared_logic_um2
                .map_or("–".to_string(), |s| format!("{:.3}", s / 1e6)),
            format!("{:.3}", t.total_um2 / 1e6),
            format!("{:.0} %", t.pixel_share * 100.0),
        ]);
    }
    m += &format!("\n### Array area\n\n{area}");
    if !a.timing.is_empty() {
        m += &format!(
            "\n### Broadcast and readout timing (pixel clock {:.1} MHz, margin 10 %)\n\n\
             Each path's delay is the whole path (the array's part + the pixel's own part, the pixel \
             timed alone from those inputs or to those outputs).\n\n",
            a.timing[0].clock_mhz
        );
        let mut table = Table::left([
            "netlist",
            "library",
            "array logic (µm²)",
            "broadcast delay (ns): array + pixel",
            "slack",
            "readout delay (ns): array + pixel",
            "slack",
        ]);
        for t in &a.timing {
            let [broadcast, broadcast_slack] = path_cells(&t.broadcast);
            let [readout, readout_slack] = path_cells(&t.readout);
            table.row([
                t.netlist.to_string(),
                t.library.clone(),
                format!("{:.0}", t.shared_logic_um2),
                broadcast,
                broadcast_slack,
                readout,
                readout_slack,
            ]);
        }
        m += &table.render();
        m += &format!(
            "\nBroadcast and readout {} the pixel clock with ≥ 10 % slack on every library and corner timed.\n",
            if a.timing_meets_margin {
                "meet"
            } else {
                "do NOT all meet"
            }
        );
        for o in &a.at_corner_options {
            m += &format!(
                "- {} on {}: with the option that meets this corner (A = {}, {:.1} MHz), broadcast slack {:.1} %, readout slack {:.1} %: {}.\n",
                o.netlist,
                o.library,
                o.adders,
                o.clock_mhz,
                o.broadcast_slack_percent,
                o.readout_slack_percent,
                if o.meets_margin {
                    "both meet with ≥ 10 %"
                } else {
                    "**short** of the 10 % margin"
                }
            );
        }
    }
    m += &options(&a.double_buffer, a.superpixel.as_ref());
    let r = &a.readout;
    let mut readout = Table::left(["figure", "value"]);
    readout
        .row([
            "port".to_string(),
            format!(
                "{} bits per beat, one beat every {} cycle(s) at f_clk = {:.1} MHz: {:.3} Gbit/s",
                r.bits_per_beat,
                r.cycles_per_beat,
                r.clock_hz / 1e6,
                r.port_bits_per_s / 1e9
            ),
        ])
        .row([
            "words per pixel".to_string(),
            format!("registers + status, {} beat(s) each", r.beats_per_word),
        ])
        .row([
            "bits per frame".to_string(),
            format!(
                "{} payload, {} on the port",
                r.payload_bits_per_frame, r.stream_bits_per_frame
            ),
        ])
        .row([
            "readout".to_string(),
            format!(
                "{} cycles = {:.3} ms",
                r.readout_cycles,
                r.readout_seconds * 1e3
            ),
        ])
        .row([
            "frame".to_string(),
            format!(
                "{} cycles{}: {:.4} frames/s, pixels see {:.3} % of the pulses",
                r.frame_cycles,
                if r.double_buffer {
                    " (double-buffered: max(N·C + 1, D))"
                } else {
                    " (N·C + D)"
                },
                r.frame_rate_hz,
                r.duty * 100.0
            ),
        ])
        .row([
            "mean output rate".to_string(),
            format!("{:.3} Mbit/s", r.mean_bits_per_s / 1e6),
        ]);
    m += &format!("\n### Readout\n\n{readout}");
    let t = &a.timestamps;
    m += &format!(
        "\n### Against reading every timestamp out\n\n\
         One {}-bit timestamp per pulse at {:.1} MHz is {:.1} MB per pixel per second (the paper's \
         17.5 MB at 14 bits); the array's timestamps: {:.2} Gbit/s ({} the paper's 100 Gbit/s), \
         against {:.3} Mbit/s of registers: {:.0}× less.\n",
        t.timestamp_bits,
        t.laser_rate_hz / 1e6,
        t.bytes_per_pixel_per_s / 1e6,
        t.array_bits_per_s / 1e9,
        if t.exceeds_paper_line {
            "above"
        } else {
            "below"
        },
        t.readout_bits_per_s / 1e6,
        t.reduction
    );
    // The paper's per-pixel figure beside: one source of the numbers (`paper_memory`).
    if let Ok(figs) = tofprobe_eda::paper_memory::section8() {
        m += &format!("\n{}", tofprobe_eda::paper_memory::markdown(&figs));
    }
    m += "\nAssumptions:\n\n";
    for s in &a.assumptions {
        m += &format!("- {s}\n");
    }
    m
}

/// A path's two cells of the timing table: its delay (array + pixel) and its slack, marked
/// **short** below the margin.
fn path_cells(p: &PathTiming) -> [String; 2] {
    [
        format!(
            "{:.3}: {:.3} + {:.3}",
            p.delay_ns, p.array_part_ns, p.pixel_part_ns
        ),
        format!(
            "{:.3} ns ({:.1} %){}",
            p.slack_ns,
            p.slack_percent,
            if p.meets_margin { "" } else { " **short**" }
        ),
    ]
}

/// The two options as Markdown (a part of the array section).
fn options(db: &DoubleBuffer, sp: Option<&SuperpixelSize>) -> String {
    let mut m = format!(
        "\n### Double buffer ({}): a shadow copy of the registers\n\n\
         {} shadow bits per pixel ((R+1)·W: the registers and the status word). Area: {}.\n\n",
        if db.enabled { "on" } else { "off" },
        db.shadow_bits_per_pixel,
        db.basis
    );
    let mut t = Table::left([
        "library",
        "register file (µm², flops)",
        "shadow (µm², estimate)",
        "bare flops (µm²)",
        "pixel without → with (µm²)",
        "array without → with (mm²)",
    ]);
    for a in &db.areas {
        t.row([
            a.library.clone(),
            format!("{:.0} ({})", a.register_file_um2, a.register_file_flops),
            format!("{:.0}", a.shadow_um2),
            a.shadow_flops_only_um2
                .map_or("–".to_string(), |v| format!("{v:.0}")),
            format!("{:.0} → {:.0}", a.pixel_um2, a.pixel_with_um2),
            format!(
                "{:.3} → {:.3}",
                a.array_total_um2 / 1e6,
                a.array_total_with_um2 / 1e6
            ),
        ]);
    }
    m += &t.render();
    if let Some(s) = sp {
        m += &format!(
            "\n### Superpixel {g} × {g}: {n} SPADs share one pixel\n\n\
             The front end (templates/superpixel.v) averages the valid SPADs' codes: a table of \
             {n} words of {tb} bits (⌈2^{k}/n⌉), a multiply and a shift by {k}; combinational. \
             SPAD pitch {pitch} µm (a pixel: {g} × that).\n\n",
            g = s.side,
            n = s.spads_per_pixel,
            tb = s.table_bits,
            k = s.shift,
            pitch = s.spad_pitch_um,
        );
        let mut t = Table::left(["per SPAD", "plain pixel", "superpixel"]);
        t.row([
            "register bits".to_string(),
            s.plain_bits_per_spad.to_string(),
            format!(
                "{:.1} ({} / {})",
                s.bits_per_spad, s.plain_bits_per_spad, s.spads_per_pixel
            ),
        ]);
        for a in &s.area {
            t.row([
                format!("area on {} (µm²)", a.library),
                format!("{:.0}", a.plain_per_spad_um2),
                format!(
                    "{:.0} (({:.0} + front end {:.0}, {} cells) / {})",
                    a.per_spad_um2,
                    a.pixel_um2,
                    a.front_end_um2,
                    a.front_end_cells,
                    s.spads_per_pixel
                ),
            ]);
        }
        m += &t.render();
    }
    m
}
