//! `tofprobe reproduce --quick --json` through the binary (the documented smoke test; the
//! full run is the benchmark): every Table 2 noise and amplitude row carries its seeds
//! (≥ 5), the band it is read on (noise rows: the DFT's 1–10 kHz, also for ΣΔ) and its
//! z-scores; the run passes.

mod common;

use common::tofprobe;

#[test]
fn quick_json_rows_carry_seeds_bands_and_z_scores() {
    let dir = std::env::temp_dir().join(format!("tofprobe-reproduce-{}", std::process::id()));
    let out = tofprobe(&[
        "reproduce",
        "--quick",
        "--json",
        "--out",
        dir.to_str().expect("utf-8 path"),
    ]);
    let _ = std::fs::remove_dir_all(&dir);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    // Every figure finite; nulls only where a row has no reference (docs/reliability.md).
    common::finite::assert_finite("reproduce --quick --json", &v);
    assert!(
        out.status.success(),
        "{}",
        serde_json::to_string_pretty(&v).unwrap_or_default()
    );
    assert_eq!(v["quick"], true);
    let rows = v["rows"].as_array().expect("rows");
    let family = |f: &'static str| rows.iter().filter(move |r| r["family"] == f);
    let noise: Vec<_> = family("Table 2 noise").collect();
    assert_eq!(noise.len(), 18, "one noise row per Table 2 row");
    for r in noise
        .iter()
        .chain(family("Table 2 amplitude").collect::<Vec<_>>().iter())
    {
        let seeds = r["seeds"].as_array().expect("seeds");
        assert!(seeds.len() >= 5, "{r}");
        assert!(r["seed_sd"].as_f64().is_some_and(|s| s > 0.0), "{r}");
        assert!(r["z_closed_form"].as_f64().is_some(), "{r}");
    }
    for r in &noise {
        assert_eq!(r["band_hz"], serde_json::json!([1000.0, 10000.0]), "{r}");
        assert_eq!(r["tolerance"]["kind"], "seeds");
    }
    for r in family("Table 2 ΣΔ noise") {
        assert_eq!(r["band_hz"], serde_json::json!([1000.0, 10000.0]), "{r}");
    }
    assert_eq!(family("Table 2 amplitude").count(), 14);
}
