//! The docs' tables that a command prints are that command's output: docs/tradeoff.md's
//! levels table is compared, row by row and column by column, with what `tofprobe
//! tradeoff` prints now (the wall-time column excepted: it is a measurement of the machine,
//! not of the model). A change of the model's numbers (e.g. a new Monte Carlo) fails here
//! until the page is regenerated with the command the page gives.

use crate::common;

/// The rows of the first Markdown table after the line starting with `heading` (or the
/// first table of `text` when `heading` is empty): cells of every body row.
fn table_after(text: &str, heading: &str) -> Vec<Vec<String>> {
    let mut lines = text.lines().skip_while(|l| !l.starts_with(heading));
    let mut rows = Vec::new();
    let mut in_table = false;
    for l in lines.by_ref() {
        if l.starts_with('|') {
            in_table = true;
            let cells: Vec<String> = l
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect();
            if !cells.iter().all(|c| c.chars().all(|ch| ch == '-')) {
                rows.push(cells);
            }
        } else if in_table {
            break;
        }
    }
    rows
}

/// Every cell of `doc` equals `now`'s, but the columns named in `skip`; the first
/// difference is named by row and column.
fn compare(doc: &[Vec<String>], now: &[Vec<String>], skip: &[&str]) -> Result<(), String> {
    let (Some(head), Some(now_head)) = (doc.first(), now.first()) else {
        return Err("a table is missing".into());
    };
    if head != now_head {
        return Err(format!(
            "columns differ: docs {head:?}, command {now_head:?}"
        ));
    }
    if doc.len() != now.len() {
        return Err(format!(
            "{} rows in the docs, {} printed",
            doc.len(),
            now.len()
        ));
    }
    for (d, n) in doc.iter().zip(now).skip(1) {
        for ((col, a), b) in head.iter().zip(d).zip(n) {
            if !skip.contains(&col.as_str()) && a != b {
                return Err(format!(
                    "row `{}`, column `{col}`: docs say {a}, the command prints {b}",
                    d[0]
                ));
            }
        }
    }
    Ok(())
}

/// docs/tradeoff.md's "Levels" table is `tofprobe tradeoff` on the embedded default.
#[test]
fn tradeoff_levels_table_is_the_commands_output() {
    let out = common::tofprobe(&["tradeoff"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let printed = table_after(&String::from_utf8_lossy(&out.stdout), "");
    let doc = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/tradeoff.md"
    ))
    .expect("docs/tradeoff.md");
    let documented = table_after(&doc, "## Levels");
    assert!(documented.len() >= 7, "{documented:?}");
    compare(&documented, &printed, &["wall s per simulated s"]).unwrap_or_else(|e| {
        panic!("docs/tradeoff.md is stale: {e} (regenerate with `tofprobe tradeoff`)")
    });
}

/// The comparison fails on a stale cell (the 0.008 µm the page once lagged by) and on a
/// missing row, and ignores the time column.
#[test]
fn a_stale_docs_table_fails() {
    let now = vec![
        vec!["level".to_string(), "wall s".into(), "amplitude µm".into()],
        vec!["float ΣΔ probing".into(), "1.0e0".into(), "97.335".into()],
    ];
    let mut doc = now.clone();
    doc[1][1] = "8.3e-1".into();
    assert_eq!(compare(&doc, &now, &["wall s"]), Ok(()));
    doc[1][2] = "97.343".into();
    let e = compare(&doc, &now, &["wall s"]).unwrap_err();
    assert!(
        e.contains("float ΣΔ probing") && e.contains("97.343"),
        "{e}"
    );
    assert!(compare(&doc[..1], &now, &["wall s"]).is_err());
    let md = "x\n## Levels\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\nafter\n| c |\n";
    assert_eq!(
        table_after(md, "## Levels"),
        vec![vec!["a", "b"], vec!["1", "2"]]
    );
}
