//! The options study as Markdown: the options table (accuracy, width, area per library,
//! timing), the bins-per-pitch table beside the paper's 6 and 13, and the recommendation.

use std::fmt::Write;

use super::OptionsReport;

fn lib_short(name: &str) -> String {
    if name.contains("sky130") {
        "sky130".into()
    } else if name.contains("osu018") {
        "osu018".into()
    } else {
        name.to_string()
    }
}

/// The section `tofprobe size --options` appends to the size report.
pub fn render(r: &OptionsReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n## Architecture options: area against accuracy (B = {}, clock {:.1} MHz)\n",
        r.bins, r.clock_mhz
    );
    let libs: Vec<String> = r.rows.first().map_or(Vec::new(), |row| {
        row.libraries
            .iter()
            .map(|l| lib_short(&l.library))
            .collect()
    });
    let mut head =
        "| option | W | G | rounding | register file | tone error µm (mean, range) |".to_string();
    let mut rule = "|---|---:|---:|---|---|---|".to_string();
    for l in &libs {
        let _ = write!(
            head,
            " {l} area µm² | {l} fixed + per bin µm² | {l} slack |"
        );
        rule += "---:|---:|---|";
    }
    head += " front |";
    rule += "---|";
    let _ = writeln!(s, "{head}\n{rule}");
    for row in &r.rows {
        let recommended = row.option.name == r.recommendation.option;
        let mark = match (recommended, row.on_front) {
            (true, true) => "**recommended**, on front",
            (true, false) => "**recommended**",
            (false, true) => "on front",
            (false, false) => "",
        };
        let e = &row.tone_error_um;
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {} | {:.3} ({:.3}–{:.3}) |",
            row.option.name,
            row.width_bits,
            row.register_frac_bits,
            row.prefilter_rounding,
            row.register_file,
            e.mean,
            e.min,
            e.max
        );
        for l in &row.libraries {
            let slack = l.timing.as_ref().map_or("untimed".to_string(), |t| {
                if t.meets_margin {
                    format!("{:.1} %", t.slack_percent)
                } else {
                    format!("**{:.1} %**", t.slack_percent)
                }
            });
            let _ = write!(
                s,
                " {:.0} | {:.0} + {:.0} | {slack} |",
                l.total_area_um2, l.model.fixed_um2, l.model.per_bin_um2
            );
        }
        let _ = writeln!(s, " {mark} |");
    }

    let _ = writeln!(
        s,
        "\n### Bins per pixel pitch at {} nm\n",
        r.rows
            .first()
            .and_then(|row| row.libraries.first())
            .and_then(|l| l.fits.first())
            .map_or(0.0, |f| f.node_nm)
    );
    let sides: Vec<(f64, Option<u64>)> = r
        .rows
        .first()
        .and_then(|row| row.libraries.first())
        .map_or(Vec::new(), |l| {
            l.fits
                .iter()
                .map(|f| (f.pixel_side_um, f.paper_bins))
                .collect()
        });
    let mut head = "| option |".to_string();
    let mut rule = "|---|".to_string();
    for l in &libs {
        for (side, _) in &sides {
            let _ = write!(head, " {l} {side:.0}×{side:.0} µm |");
            rule += "---:|";
        }
    }
    let _ = writeln!(s, "{head}\n{rule}");
    let paper: Vec<String> = libs
        .iter()
        .flat_map(|_| {
            sides
                .iter()
                .map(|(_, p)| p.map_or("—".into(), |n| n.to_string()))
        })
        .collect();
    let _ = writeln!(s, "| paper (40 nm estimate) | {} |", paper.join(" | "));
    for row in &r.rows {
        let cells: Vec<String> = row
            .libraries
            .iter()
            .flat_map(|l| l.fits.iter().map(|f| f.bins.to_string()))
            .collect();
        let name = if row.option.name == r.recommendation.option {
            format!("**{}** (recommended)", row.option.name)
        } else {
            row.option.name.clone()
        };
        let _ = writeln!(s, "| {name} | {} |", cells.join(" | "));
    }

    let rec = &r.recommendation;
    let saving = rec
        .baseline_area_um2
        .filter(|b| *b > 0.0)
        .map_or(String::new(), |b| {
            format!(
                ", {:+.1} % against the baseline",
                (rec.total_area_um2 / b - 1.0) * 100.0
            )
        });
    let _ = writeln!(
        s,
        "\n**Recommended:** `{}` — {:.0} µm² on {}{saving}; worst-seed tone error {:.3} µm ≤ {} µm; {}. Set in `[pixel]`: {}. `tofprobe flow --recommended` builds, co-simulates and reports it.\n",
        rec.option,
        rec.total_area_um2,
        lib_short(&rec.library),
        rec.tone_error_um,
        rec.target_error_um,
        rec.min_slack_percent
            .map_or("untimed".into(), |m| format!("smallest slack {m:.1} %")),
        if rec.overrides.is_empty() {
            "nothing (the configuration as it is)".to_string()
        } else {
            rec.overrides
                .iter()
                .map(|(k, v)| format!("`{} = {v}`", k.trim_start_matches("pixel.")))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    for a in &r.assumptions {
        let _ = writeln!(s, "- {a}");
    }
    s
}
