//! `tofprobe reproduce --quick --json` through the binary (the documented smoke test; the
//! full run is the benchmark): every Table 2 noise and amplitude row carries its seeds
//! (≥ 5), the band it is read on (noise rows: the DFT's 1–10 kHz, also for ΣΔ) and its
//! z-scores; every Table 2 row of the DFT, ΣΔ and bit-true columns (noise, "A meas.", SNR)
//! shows the paper's printed value, the probe rows their closed form and the same records'
//! DFT apart, each column on seeds of its own; the run passes. The same run writes the paper's figures (Fig. 2–9, 3, 12) into
//! `--out` as one set: every file is listed under `figures` in the JSON, is an SVG, carries
//! its title, axis labels and the paper's printed values as text, and holds no NaN/inf.

use crate::common;

use common::tofprobe;

#[test]
fn quick_json_rows_carry_seeds_bands_and_z_scores() {
    // The one shared run of this test binary (haar.rs reads it too).
    let (out, dir) = common::reproduce_quick();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    check_figures(dir, &v).unwrap_or_else(|e| panic!("{e}"));
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
    // The figure points are multi-seed too: Fig. 4, the hold's corners (Fig. 6), the probe
    // columns' rows, each with its seeds listed and a seed-to-seed sd.
    for (f, count) in [
        ("Fig. 4", 6),
        ("1NN hold f_3dB", 3),
        ("Table 2 amplitude", 18),
        ("Table 2 SNR", 14),
        ("Table 2 ΣΔ noise", 18),
        ("Table 2 ΣΔ amplitude", 18),
        ("Table 2 ΣΔ SNR", 14),
        ("Table 2 bit-true noise", 18),
        ("Table 2 bit-true amplitude", 14),
        ("Table 2 bit-true SNR", 14),
    ] {
        assert_eq!(family(f).count(), count, "{f}");
        for r in family(f) {
            assert!(r["seeds"].as_array().is_some_and(|s| s.len() >= 5), "{r}");
            assert!(r["seed_sd"].as_f64().is_some_and(|s| s > 0.0), "{r}");
        }
    }
    check_table2_paper_values(rows);
    check_own_seeds(rows);
}

/// Every Table 2 row of every column (DFT, ΣΔ, bit-true; noise, "A meas.", SNR) shows the
/// paper's printed value from crates/experiments/data/paper/table2.tsv — the DFT's for the
/// DFT rows, the ΣΔ's for the probe rows — and the probe rows name the closed form and,
/// apart, the same records' DFT. The ΣΔ rows without a prefilter have no printed value.
fn check_table2_paper_values(rows: &[serde_json::Value]) {
    let printed = tofprobe_experiments::paper::table2::ROWS.clone();
    let mut shown = 0;
    for r in rows.iter().filter(|r| {
        let f = r["family"].as_str().unwrap_or("");
        f.starts_with("Table 2") && !f.ends_with("without prefilter")
    }) {
        let family = r["family"].as_str().unwrap();
        let spec = printed
            .iter()
            .find(|s| s.label() == r["label"].as_str().unwrap())
            .unwrap_or_else(|| panic!("no printed row for {r}"));
        let probe = family.contains("ΣΔ") || family.contains("bit-true");
        let p = &spec.printed;
        let want = if family.ends_with("noise") {
            p.noise_um.of(probe)
        } else if family.ends_with("amplitude") {
            p.amp_um.of(probe)
        } else {
            p.snr_db.expect("an SNR row has a printed SNR").of(probe)
        };
        assert_eq!(r["paper"].as_f64(), Some(want), "{r}");
        if probe {
            assert!(
                r["closed_form"].as_f64().is_some() || spec.amp_um.is_none(),
                "{r}"
            );
            assert!(r["same_record_dft"].as_f64().is_some(), "{r}");
        }
        if family.ends_with("SNR") {
            assert!(
                r["note"].as_str().unwrap().contains("ERRATUM (definition)"),
                "{r}"
            );
        }
        shown += 1;
    }
    // 18 + 18 + 14 DFT rows, 18 + 18 + 14 ΣΔ rows, 18 + 14 + 14 bit-true rows.
    assert_eq!(shown, 146);
}

/// The DFT, ΣΔ and bit-true rows of one Table 2 row run on seeds of their own.
fn check_own_seeds(rows: &[serde_json::Value]) {
    let mut by_label: std::collections::BTreeMap<&str, Vec<(&str, Vec<u64>)>> = Default::default();
    for r in rows.iter().filter(|r| {
        r["family"]
            .as_str()
            .is_some_and(|f| f.starts_with("Table 2") && f.ends_with("noise"))
    }) {
        let seeds = r["seeds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_u64().unwrap())
            .collect();
        by_label
            .entry(r["label"].as_str().unwrap())
            .or_default()
            .push((r["family"].as_str().unwrap(), seeds));
    }
    assert_eq!(by_label.len(), 18);
    for (label, cols) in by_label {
        assert_eq!(cols.len(), 3, "{label}: {cols:?}");
        let all: std::collections::BTreeSet<u64> =
            cols.iter().flat_map(|c| c.1.iter().copied()).collect();
        assert_eq!(
            all.len(),
            cols.iter().map(|c| c.1.len()).sum::<usize>(),
            "{label}"
        );
    }
}

/// (file, figure, texts it must hold): title, axis labels, the paper's printed values.
const FIGURES: &[(&str, &str, &[&str])] = &[
    (
        "fig2_probe_spectrum.svg",
        "Fig. 2",
        &["frequency (Hz)", "power per bin", "156.25 kHz", "297 kHz"],
    ),
    (
        "fig4_noise_vs_sigma_i.svg",
        "Fig. 4",
        &[
            "σ_I (ps)",
            "noise floor (µm)",
            "0.53 / 5.3 / 53 µm",
            "0.7 / 6.98 / 69.8 µm",
            "mean ± sd",
        ],
    ),
    (
        "fig5_amplitude_vs_rho_b.svg",
        "Fig. 5",
        &[
            "ρ_b",
            "amplitude / A",
            "e^(−ρ_b/2)",
            "99.63 / 95.71 / 92.61 / 88.75 / 98.31 / 55.14 µm",
        ],
    ),
    (
        "fig6_hold_bandwidth.svg",
        "Fig. 6",
        &[
            "ρ_s",
            "f_3dB (kHz)",
            "paper 168.4",
            "paper 15.8",
            "paper 1.69",
            "corrected 167.8",
        ],
    ),
    (
        "fig7_dft_spectrum.svg",
        "Fig. 7",
        &[
            "frequency (Hz)",
            "|Y| (µm)",
            "σ_s = 3 mm, ρ_s = 1, ρ_b = 0, no tone",
            "prints an average noise of 2.5 µm",
            "gives 2.25 µm (DFT)",
        ],
    ),
    (
        "fig8_sd_spectrum.svg",
        "Fig. 8",
        &[
            "frequency (Hz)",
            "|Y| (µm)",
            "ΣΔ probing",
            "amplitude 102.3 µm, noise floor 5.52 µm",
        ],
    ),
    (
        "fig9_rho_sweep.svg",
        "Fig. 9",
        &[
            "ρ_s",
            "µm",
            "131.34 / 114.76 / 102.22 / 102.3 µm",
            "44.42 / 23.57 / 13.11 / 5.52 µm",
        ],
    ),
    (
        "fig3_scalogram.svg",
        "Fig. 3",
        &["time (ms)", "scale (wavelet duration)"],
    ),
    (
        "fig12_scalogram.svg",
        "Fig. 12",
        &["time (ms)", "scale (wavelet duration)"],
    ),
];

/// A NaN or infinity spelled as a token ("H_inf" is a name, not a number).
fn non_finite_token(text: &str) -> Option<&str> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .find(|t| matches!(t.to_ascii_lowercase().as_str(), "nan" | "inf" | "infinity"))
}

/// One figure file's checks: a whole SVG document with its texts and only finite numbers.
fn check_svg(name: &str, svg: &str, title: &str, texts: &[&str]) -> Result<(), String> {
    let head = svg.trim_start();
    if !(head.starts_with("<svg") || head.starts_with("<?xml")) {
        return Err(format!("{name}: does not start as an SVG document"));
    }
    if !svg.trim_end().ends_with("</svg>") {
        return Err(format!("{name}: does not close </svg>"));
    }
    for t in std::iter::once(&title).chain(texts) {
        if !svg.contains(t) {
            return Err(format!("{name}: no text `{t}`"));
        }
    }
    if let Some(t) = non_finite_token(svg) {
        return Err(format!("{name}: holds `{t}`"));
    }
    // Readable as drawn: texts ≥ 8 px, no legend over a data marker.
    if let Some(p) = tofprobe_experiments::paper::svg_check::problems(svg).first() {
        return Err(format!("{name}: {p}"));
    }
    Ok(())
}

/// The figure renders in librsvg (what GNOME's viewers and many converters use) without an
/// error: a malformed element fails here even where the text checks pass.
fn render(path: &std::path::Path) -> Result<(), String> {
    if !tofprobe_testkit::tools::have(&["rsvg-convert"], "reproduce figures render") {
        return Ok(());
    }
    // PNG to stdout (rsvg-convert refuses a non-regular --output such as /dev/null).
    let out = std::process::Command::new("rsvg-convert")
        .args(["--format", "png"])
        .arg(path)
        .output()
        .map_err(|e| format!("rsvg-convert: {e}"))?;
    if !out.status.success() || !out.stdout.starts_with(b"\x89PNG") {
        return Err(format!(
            "{}: rsvg-convert failed: {}",
            path.display(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(())
}

/// Every figure of [`FIGURES`] is in the JSON's `figures` (figure → path inside `dir`) and
/// passes [`check_svg`].
fn check_figures(dir: &std::path::Path, v: &serde_json::Value) -> Result<(), String> {
    let listed = v["figures"].as_object().ok_or("no `figures` object")?;
    for (file, figure, texts) in FIGURES {
        let path = dir.join(file);
        let named = listed.get(*figure).and_then(|p| p.as_str());
        if named != Some(path.to_str().unwrap_or_default()) {
            return Err(format!(
                "`figures` lists {figure} as {named:?}, not {}",
                path.display()
            ));
        }
        let svg = std::fs::read_to_string(&path).map_err(|e| format!("{file}: {e}"))?;
        check_svg(file, &svg, &format!("{figure}:"), texts)?;
        render(&path)?;
    }
    // The set is whole: no stage directory or temporary left beside it.
    for e in std::fs::read_dir(dir).map_err(|e| e.to_string())? {
        let name = e.map_err(|e| e.to_string())?.file_name();
        if name.to_string_lossy().starts_with('.') {
            return Err(format!("left over in --out: {name:?}"));
        }
    }
    Ok(())
}

/// The checks can fail: a truncated file, a missing paper value and a NaN are each caught.
#[test]
fn figure_checks_catch_broken_files() {
    let good =
        "<svg x=\"1\"><text>Fig. 5: a</text><text>99.6 µm</text><text>H_inf 1.5</text></svg>\n";
    assert_eq!(check_svg("f", good, "Fig. 5:", &["99.6 µm"]), Ok(()));
    let truncated = &good[..good.len() - 8];
    assert!(
        check_svg("f", truncated, "Fig. 5:", &[])
            .unwrap_err()
            .contains("</svg>")
    );
    assert!(
        check_svg("f", good, "Fig. 5:", &["55.1 µm"])
            .unwrap_err()
            .contains("55.1")
    );
    let nan = good.replace("x=\"1\"", "x=\"NaN\"");
    assert!(
        check_svg("f", &nan, "Fig. 5:", &[])
            .unwrap_err()
            .contains("NaN")
    );
    let inf = good.replace("x=\"1\"", "x=\"-inf\"");
    assert!(check_svg("f", &inf, "Fig. 5:", &[]).is_err());
    assert!(check_svg("f", "<html></html>", "Fig. 5:", &[]).is_err());
}

/// `--out` that cannot be a directory (a regular file) fails at once with status 2, names
/// the path, and leaves the file as it was: the output set is begun before the simulation.
#[test]
fn unusable_out_fails_before_simulating() {
    let file = std::env::temp_dir().join(format!("tofprobe-reproduce-file-{}", std::process::id()));
    std::fs::write(&file, b"not a directory").expect("write");
    let t = std::time::Instant::now();
    let out = tofprobe(&[
        "reproduce",
        "--quick",
        "--out",
        file.to_str().expect("utf-8 path"),
    ]);
    let secs = t.elapsed().as_secs_f64();
    let kept = std::fs::read(&file).expect("read");
    let _ = std::fs::remove_file(&file);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(file.to_str().unwrap_or_default()), "{err}");
    assert_eq!(kept, b"not a directory");
    // The quick run simulates for ≈ 30 s; failing first takes well under that.
    assert!(secs < 10.0, "{secs} s");
}
