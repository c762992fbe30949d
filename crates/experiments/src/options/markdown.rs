//! The options study as Markdown: the options table (accuracy, width, area per library,
//! timing), the bins-per-pitch table beside the paper's 6 and 13, and the recommendation.

use std::fmt::Write;

use tofprobe_io::markdown::{Align, Table};

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
    let mut t = Table::new([
        ("option", Align::Left),
        ("W", Align::Right),
        ("G", Align::Right),
        ("rounding", Align::Left),
        ("register file", Align::Left),
        ("tone error µm (mean, range)", Align::Left),
    ]);
    for l in &libs {
        t.column(format!("{l} area µm²"), Align::Right)
            .column(format!("{l} fixed + per bin µm²"), Align::Right)
            .column(format!("{l} slack"), Align::Left);
    }
    t.column("front", Align::Left);
    for row in &r.rows {
        let recommended = row.option.name == r.recommendation.option;
        let mark = match (recommended, row.on_front) {
            (true, true) => "**recommended**, on front",
            (true, false) => "**recommended**",
            (false, true) => "on front",
            (false, false) => "",
        };
        let e = &row.tone_error_um;
        let mut cells = vec![
            row.option.name.clone(),
            row.width_bits.to_string(),
            row.register_frac_bits.to_string(),
            row.prefilter_rounding.to_string(),
            row.register_file.to_string(),
            format!("{:.3} ({:.3}–{:.3})", e.mean, e.min, e.max),
        ];
        for l in &row.libraries {
            let slack = l.timing.as_ref().map_or("untimed".to_string(), |t| {
                if t.meets_margin {
                    format!("{:.1} %", t.slack_percent)
                } else {
                    format!("**{:.1} %**", t.slack_percent)
                }
            });
            cells.push(format!("{:.0}", l.total_area_um2));
            cells.push(format!(
                "{:.0} + {:.0}",
                l.model.fixed_um2, l.model.per_bin_um2
            ));
            cells.push(slack);
        }
        cells.push(mark.to_string());
        t.row(cells);
    }
    s += &t.render();

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
    let mut t = Table::left(["option"]);
    for l in &libs {
        for (side, _) in &sides {
            t.column(format!("{l} {side:.0}×{side:.0} µm"), Align::Right);
        }
    }
    let paper = libs.iter().flat_map(|_| {
        sides
            .iter()
            .map(|(_, p)| p.map_or("—".into(), |n| n.to_string()))
    });
    t.row(std::iter::once("paper (40 nm estimate)".to_string()).chain(paper));
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
        t.row(std::iter::once(name).chain(cells));
    }
    s += &t.render();

    if let Some(k) = &r.layout {
        layout_table(&mut s, r, k);
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
    if let Some(line) = recommended_from_layout(r) {
        let _ = writeln!(s, "{line}\n");
    }
    for a in &r.assumptions {
        let _ = writeln!(s, "- {a}");
    }
    s
}

/// The bins-per-pitch table from layout: each option's model times the routed factor k,
/// on the libraries of the layout's technology, beside the synthesis count.
fn layout_table(s: &mut String, r: &OptionsReport, k: &tofprobe_eda::scaling::RoutedFactor) {
    let _ = writeln!(
        s,
        "\n### Bins per pixel pitch from layout (k = {:.3}, the {} macro of {} at density {:.2})\n",
        k.factor, k.technology, k.config, k.density
    );
    let Some(first) = r.rows.first() else {
        return;
    };
    let mut t = Table::left(["option"]);
    for l in first.libraries.iter().filter(|l| l.layout_fits.is_some()) {
        for f in &l.fits {
            t.column(
                format!(
                    "{} {:.0}×{:.0} µm: layout (synthesis)",
                    lib_short(&l.library),
                    f.pixel_side_um,
                    f.pixel_side_um
                ),
                Align::Right,
            );
        }
    }
    for row in &r.rows {
        let mut cells = vec![row.option.name.clone()];
        for l in &row.libraries {
            if let Some(lf) = &l.layout_fits {
                for (a, b) in lf.iter().zip(&l.fits) {
                    cells.push(format!("{} ({})", a.bins, b.bins));
                }
            }
        }
        t.row(cells);
    }
    s.push_str(&t.render());
}

/// The recommended option's bins per pitch from layout, in words (none without a layout).
pub fn recommended_from_layout(r: &OptionsReport) -> Option<String> {
    let k = r.layout.as_ref()?;
    let row = r
        .rows
        .iter()
        .find(|row| row.option.name == r.recommendation.option)?;
    let parts: Vec<String> = row
        .libraries
        .iter()
        .filter_map(|l| {
            let lf = l.layout_fits.as_ref()?;
            Some(
                lf.iter()
                    .map(|f| {
                        format!(
                            "{} bins in {:.0} µm on {} (paper {})",
                            f.bins,
                            f.pixel_side_um,
                            lib_short(&l.library),
                            f.paper_bins.map_or("—".into(), |p| p.to_string())
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
            )
        })
        .collect();
    Some(format!(
        "**The recommended option from layout** (k = {:.3}, {} at {:.0} nm): {}.",
        k.factor,
        k.technology,
        row.libraries
            .first()
            .and_then(|l| l.fits.first())
            .map_or(0.0, |f| f.node_nm),
        parts.join("; ")
    ))
}
