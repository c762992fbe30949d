//! Issue 8 point 3: the extremes matrix through the simulation `tofprobe simulate --json`
//! prints (`simulation::simulate`: scene Monte Carlo → probe ROM → bit-true pixel →
//! spectrum) on short frames. Every case either runs with finite outputs within its stated
//! tolerance, or is refused at resolution with a clear message naming the key at fault —
//! never a panic or a NaN. (The binary's exit code 2 and `error:` for a refusal, and finite
//! JSON from every command, are the CLI's tests: exit_codes.rs, finite_json.rs.)
//!
//! Base: the default scene shortened to N = 2^14 pulses, B = 4 bins (C = 4), the tone
//! moved onto bin 40 (40·f_s/2^14 = 24.4 kHz: well away from DC, whose 30 mm static depth
//! leaks into bins 1..3 through the Blackman main lobe). N = 2^27 streams the whole record
//! (≈ 3 s in release) with a periodic ROM of depth 2^14 on the same bin grid: a windowed
//! 2^27-entry ROM would be 512 MiB, the periodic one is 2^14 entries.

use tofprobe_design::{DEFAULT_TOML, Document, ProbeCache, resolve_with};
use tofprobe_experiments::simulation::simulate;

const N: u64 = 1 << 14;

fn bin_hz(k: f64) -> f64 {
    k * 10e6 / N as f64
}

/// Resolves the base config with `edits` and simulates it (what `tofprobe simulate --json`
/// prints); Ok(json) or Err(the refusal's message).
fn run(name: &str, edits: &[(&str, String)]) -> Result<serde_json::Value, String> {
    // Short windowed frames (L = N), so the tones sit on k·f_s/N; the 2^27 case switches
    // back to periodic.
    let mut text = DEFAULT_TOML.replacen("rom_mode = \"periodic\"", "rom_mode = \"windowed\"", 1);
    let base = [
        ("duration_s = 1.0", format!("pulses = {N}")),
        ("bins = 16", "bins = 4".to_string()),
        ("cycles_per_pulse = 16", "cycles_per_pulse = 4".to_string()),
        (
            "frequency_hz = 4500.0",
            format!("frequency_hz = {}", bin_hz(40.0)),
        ),
    ];
    for (from, to) in base
        .iter()
        .map(|(f, t)| (*f, t))
        .chain(edits.iter().map(|(f, t)| (*f, t)))
    {
        assert!(text.contains(from), "{name}: default lacks `{from}`");
        text = text.replacen(from, to, 1);
    }
    let origin = format!("{name}.toml");
    let design = Document::from_toml_str(&text, &origin)
        .and_then(|doc| resolve_with(doc, &origin, &mut ProbeCache::default()))
        .map_err(|e| e.to_string())?;
    let sim = simulate(&design, |_| {}).map_err(|e| e.to_string())?;
    let v = serde_json::to_value(&sim).expect("serialises");
    assert_finite(name, &v);
    Ok(v)
}

/// Every number in the output is finite (serde_json writes NaN/inf as null).
fn assert_finite(name: &str, v: &serde_json::Value) {
    match v {
        serde_json::Value::Null => panic!("{name}: null (NaN?) in output"),
        serde_json::Value::Number(n) => assert!(n.as_f64().is_some_and(f64::is_finite)),
        serde_json::Value::Array(a) => a.iter().for_each(|x| assert_finite(name, x)),
        serde_json::Value::Object(o) => {
            o.iter()
                .filter(|(k, _)| k.as_str() != "bit_true" || !o[*k].is_null())
                .for_each(|(_, x)| assert_finite(name, x));
        }
        _ => {}
    }
}

fn tone_um(v: &serde_json::Value) -> f64 {
    v["bit_true"]["bins"][0]["amplitude_um"]
        .as_f64()
        .expect("tone bin")
}

fn noise_um(v: &serde_json::Value) -> f64 {
    v["bit_true"]["noise_estimate_um"].as_f64().expect("noise")
}

/// Noise floor (mean bin amplitude) of σ mm over N pulses with Blackman (N_eff = 0.579 N).
fn floor_um(sigma_mm: f64) -> f64 {
    (std::f64::consts::PI * sigma_mm * sigma_mm / (0.579 * N as f64)).sqrt() * 1000.0
}

fn s(x: impl ToString) -> String {
    x.to_string()
}

#[test]
fn extremes_matrix() {
    // A = 10 mm (the largest motion the 60 mm window holds around 30 mm with σ = 7.5 mm
    // tails): measured within 4× the noise floor (4·0.48 mm = 1.9 mm) of 10 mm; the
    // prefilter/window/probe normalisation is what this checks at large amplitude.
    let big = run(
        "a_10mm",
        &[("amplitude_mm = 0.1", s("amplitude_mm = 10.0"))],
    )
    .unwrap();
    let fl = floor_um(7.5);
    assert!(
        (tone_um(&big) - 10_000.0).abs() < 4.0 * fl,
        "A=10mm: {}",
        tone_um(&big)
    );
    // A = 1 µm: far below the floor (0.48 mm): the tone bin reads noise, within 4× floor.
    let small = run(
        "a_1um",
        &[("amplitude_mm = 0.1", s("amplitude_mm = 0.001"))],
    )
    .unwrap();
    assert!(tone_um(&small) < 4.0 * fl, "A=1um: {}", tone_um(&small));
    // σ = 0.1 mm (≈ 0.67 ps): the record is quantised to 0.75 mm codes; the 10 mm tone still
    // reads within 4× the floor of the quantisation noise (LSB/√12 = 0.217 mm) plus 5%
    // for the code-rounding harmonic distortion of a deterministic signal.
    let sharp = run(
        "sigma_0p1mm",
        &[
            ("jitter_ps = 50.0", s("jitter_ps = 0.6667")),
            ("amplitude_mm = 0.1", s("amplitude_mm = 10.0")),
        ],
    )
    .unwrap();
    assert!(
        (tone_um(&sharp) - 10_000.0).abs() < 4.0 * floor_um(0.217) + 500.0,
        "σ=0.1mm: {}",
        tone_um(&sharp)
    );
    // σ = 100 mm: most photons land outside the 60 mm window (P(in) = 0.236); the run is
    // finite and the noise estimate is large but bounded by the window (< 60 mm).
    let wide = run(
        "sigma_100mm",
        &[("jitter_ps = 50.0", s("jitter_ps = 666.7"))],
    )
    .unwrap();
    let det = wide["detection_rate"].as_f64().unwrap();
    assert!((det - 0.236).abs() < 0.02, "σ=100mm detection rate {det}");
    assert!(noise_um(&wide) > fl && noise_um(&wide) < 60_000.0);
    // ρ_s = 10^−3: ~16 detections in 2^14 pulses; the hold keeps the first; finite output
    // (the spectrum of a near-constant held depth is DC leakage plus the hold's steps).
    let sparse = run(
        "rho_s_1e-3",
        &[("signal_rate = 1.0", s("signal_rate = 0.001"))],
    )
    .unwrap();
    let d = sparse["detections"].as_u64().unwrap();
    assert!(
        (4..=32).contains(&d),
        "ρ_s=1e-3 detections {d} (mean 16.4, ±4 SD)"
    );
    // ρ_b = 1: background photons win ≈ 1 − e^{−1/2} = 39% of pulses (signal mid-window);
    // the sizing then covers the whole window; the run is finite.
    let bg = run(
        "rho_b_1",
        &[("background_rate = 0.0", s("background_rate = 1.0"))],
    )
    .unwrap();
    let wins = bg["background_wins"].as_f64().unwrap() / N as f64;
    assert!((wins - 0.393).abs() < 0.03, "ρ_b=1 wins {wins}");
    // ρ_b = 0 and ρ_s = 1 is the base: the tone bin reads 100 µm within 4× the floor.
    let base = run("base", &[]).unwrap();
    assert!(
        (tone_um(&base) - 100.0).abs() < 4.0 * fl,
        "base {}",
        tone_um(&base)
    );
    // Tone between bins (40.5): Blackman scalloping loss is 1.1 dB (−12%) at half a bin;
    // a 10 mm tone reads 8.8 mm ± 4× floor.
    let between = run(
        "between_bins",
        &[
            ("amplitude_mm = 0.1", s("amplitude_mm = 10.0")),
            (
                &*format!("frequency_hz = {}", bin_hz(40.0)),
                format!("frequency_hz = {}", bin_hz(40.5)),
            ),
        ],
    );
    let between = between.unwrap();
    let a = tone_um(&between);
    assert!((a - 8_800.0).abs() < 4.0 * fl + 200.0, "between bins {a}");
    // A tone at DC is not a tone: refused by the scene with the allowed range.
    let dc = run(
        "dc",
        &[(
            &*format!("frequency_hz = {}", bin_hz(40.0)),
            s("frequency_hz = 0.0"),
        )],
    );
    assert!(dc.unwrap_err().contains("frequency_hz = 0 is out of range"));
    // A tone at the band edge f_s/(2·OSR) = 156.25 kHz is outside the ΣΔ band: auto bins
    // leave it out (all 4 bins are noise bins below the edge), the run is finite.
    let edge = run(
        "band_edge",
        &[(
            &*format!("frequency_hz = {}", bin_hz(40.0)),
            s("frequency_hz = 156250.0"),
        )],
    )
    .unwrap();
    for b in edge["bit_true"]["bins"].as_array().unwrap() {
        assert!(b["frequency_hz"].as_f64().unwrap() < 156_250.0);
    }
    // Probe amplitude: 0.69 is within 0.9 × the measured stable maximum (≈ 0.7775 → 0.6998)
    // and runs; 0.75 is above it and is refused naming the limit.
    run(
        "probe_0p69",
        &[("amplitude = 0.5 ", s("amplitude = 0.69 "))],
    )
    .unwrap();
    let e = run(
        "probe_0p75",
        &[("amplitude = 0.5 ", s("amplitude = 0.75 "))],
    )
    .unwrap_err();
    assert!(
        e.contains("probe.amplitude = 0.75") && e.contains("stable up to"),
        "{e}"
    );
    // Depths at the window edges: a motion that crosses an edge is refused with the window
    // that would work; 0.5 mm inside the edges runs (half the pulses' jitter falls outside
    // and is not detected: detection rate ≈ 0.5).
    for (name, depth) in [("depth_0", 0.0), ("depth_60", 60.0)] {
        let e = run(name, &[("depth_mm = 30.0", format!("depth_mm = {depth}"))]).unwrap_err();
        assert!(e.contains("outside the timing window"), "{name}: {e}");
    }
    for (name, depth) in [("depth_lo", 0.5), ("depth_hi", 59.5)] {
        let v = run(name, &[("depth_mm = 30.0", format!("depth_mm = {depth}"))]).unwrap();
        let r = v["detection_rate"].as_f64().unwrap();
        // P(0 < depth + N(0, 7.5) < 60) = Φ(0.5/7.5 ± ...) ≈ 0.527; binomial SE 0.004.
        assert!((r - 0.527).abs() < 0.03, "{name}: detection rate {r}");
    }
    // W at its minimum and one below: codes 0..79 · 2^8 over 2^14 pulses reach
    // ±2^14·79·256 = ±3.3·10^8 < 2^29 = 5.4·10^8 → 29 bits + sign = 30.
    let w = base["bit_true"]["width_bits"].as_u64().unwrap();
    assert_eq!(w, 30);
    run(
        "w_min",
        &[("frac_bits = 8", s("frac_bits = 8\nwidth = 30"))],
    )
    .unwrap();
    let e = run(
        "w_below",
        &[("frac_bits = 8", s("frac_bits = 8\nwidth = 29"))],
    )
    .unwrap_err();
    assert!(
        e.contains("pixel.width = 29") && e.contains("nearest valid value: 30"),
        "{e}"
    );
    // N = 2^10: the shortest frame the base bins fit (bin 40 would be out of band at
    // L = 1024: band 1..15); auto bins adapt, finite.
    let short = run("n_2p10", &[(&*format!("pulses = {N}"), s("pulses = 1024"))]);
    let short = short.unwrap();
    assert_eq!(short["bit_true"]["bins"].as_array().unwrap().len(), 4);
}

/// N = 2^27 (13.4 s of sensor time), streamed: the periodic ROM (L = 2^14, rectangular)
/// puts the tone on bin 40 of the same grid as the base. W is sized to 43 bits
/// (2^27 · 79 · 2^8 < 2^42, plus sign); the tone reads 100 µm within 4× the
/// rectangular-window noise floor sqrt(π σ_s² / N) = 1.15 µm (σ_s² = 7.5² + 0.75²/12 mm²);
/// the periodic ROM's own error is below 0.2 µm (docs/tradeoff.md), inside that margin.
#[test]
fn n_2p27_streams_with_a_periodic_rom() {
    let v = run(
        "n_2p27",
        &[
            (
                &*format!("pulses = {N}"),
                s(format!("pulses = {}", 1u64 << 27)),
            ),
            ("rom_mode = \"windowed\"", s("rom_mode = \"periodic\"")),
            ("rom_depth = 20000", s(format!("rom_depth = {N}"))),
        ],
    )
    .unwrap();
    assert_eq!(v["bit_true"]["frame_pulses"].as_u64(), Some(1 << 27));
    assert_eq!(v["bit_true"]["width_bits"].as_u64(), Some(43));
    let floor = (std::f64::consts::PI * (7.5f64.powi(2) + 0.75f64.powi(2) / 12.0)
        / (1u64 << 27) as f64)
        .sqrt()
        * 1000.0;
    let tone = tone_um(&v);
    assert!(
        (tone - 100.0).abs() < 4.0 * floor,
        "N=2^27: tone {tone} µm, floor {floor} µm"
    );
}
