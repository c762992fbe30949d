//! `tofprobe bench sd --json --svg FILE --rom-dir DIR`, as a user runs it: the documented
//! figures are there and right where a closed form exists, and the files are written.

use std::process::Command;

/// Eq. 4 of the paper (the ideal L-th order one-bit modulator's in-band SNR), written out
/// independently of `tofprobe_dsp::sd::quality::eq4_snr_db`:
/// 6.02 + 1.76 − 10·log10(π^(2L)/(2L+1)) + (2L+1)·10·log10(OSR) + 20·log10(A).
fn eq4(order: f64, osr: f64, amplitude: f64) -> f64 {
    let pi2l = std::f64::consts::PI.powf(2.0 * order);
    6.02 + 1.76 - 10.0 * (pi2l / (2.0 * order + 1.0)).log10()
        + (2.0 * order + 1.0) * 10.0 * osr.log10()
        + 20.0 * amplitude.log10()
}

#[test]
fn bench_sd_reports_the_snr_table_and_writes_its_files() {
    let tmp = tempfile::tempdir().unwrap();
    let svg = tmp.path().join("probe.svg");
    let rom = tmp.path().join("rom");
    let o = Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(["bench", "sd", "--json", "--svg"])
        .arg(&svg)
        .arg("--rom-dir")
        .arg(&rom)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let table = r["snr_table"].as_array().unwrap();
    assert_eq!(table.len(), 20, "orders 1–4 × OSR 8–128");
    for order in 1..=4u64 {
        let rows: Vec<_> = table.iter().filter(|x| x["order"] == order).collect();
        let mut last = f64::NEG_INFINITY;
        for row in rows {
            let osr = row["osr"].as_f64().unwrap();
            let e = row["eq4_snr_db"].as_f64().unwrap();
            // The same closed form; the paper prints its constants rounded (9.94 for
            // 20·log10 π, 3.01 for 10·log10 2): at most 0.012 + 0.019 dB apart up to L = 4,
            // OSR 128.
            assert!((e - eq4(order as f64, osr, 0.5)).abs() < 0.05, "{row}");
            let m = row["measured_snr_db"].as_f64().unwrap();
            // A real modulator never beats the ideal one by more than the estimate's
            // spread (2 dB: 2^17 samples, a few hundred in-band bins)…
            assert!(m <= e + 2.0, "{row}");
            // …and noise shaping: doubling the OSR buys SNR at every order.
            assert!(m > last + 3.0, "{row} after {last}");
            last = m;
        }
    }
    // First order at OSR 8 is close to ideal (no H_inf limit bites): within 3 dB.
    let first = &table[0];
    let (m, e) = (
        first["measured_snr_db"].as_f64().unwrap(),
        first["eq4_snr_db"].as_f64().unwrap(),
    );
    assert!((m - e).abs() < 3.0, "{first}");
    // The paper's 297 kHz reads 12 bits as SNR_dB/6.02 at full scale.
    let paper = r["band_hz_12_bits_eq4_full_scale_paper_enob"]
        .as_f64()
        .unwrap();
    assert!((paper - 297e3).abs() < 1e3, "{paper}");
    assert_eq!(r["periodic_rom_depth"], 20_000);
    assert!(r["threads"].as_u64().unwrap() >= 1);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg"), "an SVG document");
    assert_eq!(r["svg"].as_str().unwrap(), svg.to_str().unwrap());
    let written: Vec<_> = std::fs::read_dir(&rom).unwrap().collect();
    assert!(!written.is_empty(), "the 16-bin ROM is written");
}
