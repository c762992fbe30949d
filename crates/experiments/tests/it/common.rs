//! Designs the tests share: the embedded default, shortened and edited.

use tofprobe_design::{DEFAULT_TOML, Document, ProbeCache, ResolvedDesign, resolve_with};

/// `text` resolved (panics with the refusal: these are the tests' own designs).
pub fn resolved(text: &str) -> ResolvedDesign {
    let doc = Document::from_toml_str(text, "short.toml").expect("parses");
    resolve_with(doc, "short.toml", &mut ProbeCache::default()).expect("resolves")
}

/// The default with a windowed ROM (L = N), `n` pulses, B = 4 bins (C = 4).
pub fn windowed_short(n: u64) -> String {
    let text = DEFAULT_TOML
        .replacen("duration_s = 1.0", &format!("pulses = {n}"), 1)
        .replacen("bins = 16", "bins = 4", 1)
        .replacen("cycles_per_pulse = 16", "cycles_per_pulse = 4", 1)
        .replacen("rom_mode = \"periodic\"", "rom_mode = \"windowed\"", 1);
    assert!(
        text.contains(&format!("pulses = {n}")) && text.contains("\"windowed\""),
        "default changed"
    );
    text
}

/// [`windowed_short`] with its tone made 1 mm and moved onto ROM bin 30 (30·f_s/n).
pub fn short_tone_frame(n: u64) -> ResolvedDesign {
    let f = 30.0 * 10e6 / n as f64;
    resolved(
        &windowed_short(n)
            .replacen("amplitude_mm = 0.1", "amplitude_mm = 1.0", 1)
            .replacen("frequency_hz = 4500.0", &format!("frequency_hz = {f}"), 1),
    )
}
