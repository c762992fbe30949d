//! `read_routed_factor`: what `size --options --layout-report` takes from a layout report
//! — k, the technology, the density and the configuration of a clean macro — and the
//! reports it refuses (a dirty macro, another schema, no area model, k < 1, a file that is
//! not a report), each naming the field.

use std::path::PathBuf;

use serde_json::{Value, json};
use tofprobe_layout::report::{SCHEMA, read_routed_factor};

fn report(k: Value, drc: u64, lvs: bool, schema: &str) -> Value {
    json!({
        "schema": schema,
        "tech": "osu018",
        "config": "two.toml",
        "drc_errors": drc,
        "lvs_match": lvs,
        "attempts": [{"density": 0.6}, {"density": 0.5}],
        "bins_per_pitch": if k.is_null() { Value::Null } else { json!({"routed_factor": k}) },
        "other": "ignored"
    })
}

fn write(name: &str, v: &Value) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-routed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, v.to_string()).unwrap();
    p
}

#[test]
fn a_clean_report_gives_k_and_the_density_that_routed() {
    let p = write("clean.json", &report(json!(1.913), 0, true, SCHEMA));
    let k = read_routed_factor(&p).unwrap();
    assert_eq!(k.factor, 1.913);
    assert_eq!(k.technology, "osu018");
    assert_eq!(k.density, 0.5, "the last attempt is the one that routed");
    assert_eq!(k.config, "two.toml");
    assert!(k.applies_to("osu018_stdcells") && !k.applies_to("sky130_fd_sc_hd__tt_025C_1v80"));
}

#[test]
fn unusable_reports_are_refused_naming_the_field() {
    let cases = [
        (report(json!(1.9), 3, true, SCHEMA), "`drc_errors` = 3"),
        (report(json!(1.9), 0, false, SCHEMA), "`lvs_match` = false"),
        (report(json!(1.9), 0, true, "tofprobe-layout-0"), "schema"),
        (report(Value::Null, 0, true, SCHEMA), "`bins_per_pitch`"),
        (report(json!(0.8), 0, true, SCHEMA), "routed_factor` ≥ 1"),
        (json!({"schema": SCHEMA}), "a layout report"),
    ];
    for (i, (v, part)) in cases.iter().enumerate() {
        let p = write(&format!("bad{i}.json"), v);
        let e = read_routed_factor(&p).unwrap_err().to_string();
        assert!(
            e.contains(part) && e.contains(&format!("bad{i}.json")),
            "{e}"
        );
    }
    let e = read_routed_factor(std::path::Path::new("/nonexistent/layout-report.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/layout-report.json"), "{e}");
}
