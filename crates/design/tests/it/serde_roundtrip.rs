//! A resolved design and its probe ROM serialise and deserialise to the same value (issue
//! 33: a worker process receives a design and its ROM instead of running the stability
//! sweep and the ROM build again). Random documents: every example scene with its keys
//! perturbed (mode, bins, window, ROM mode and depth, amplitude, order, jitter,
//! adders "auto", register fraction bits), each resolved and, when it resolves, sent
//! through JSON and compared field for field; a tampered ROM image is refused.

use tofprobe_design::{Document, ProbeCache, ResolvedDesign, resolve_with};
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_testkit::params::Rng;

const SCENES: [&str; 7] = [
    include_str!("../../../../scenes/default.toml"),
    include_str!("../../../../scenes/disk-9-period.toml"),
    include_str!("../../../../scenes/disk-pseudo-random.toml"),
    include_str!("../../../../scenes/fig12-step.toml"),
    include_str!("../../../../scenes/fig3-transients.toml"),
    include_str!("../../../../scenes/square-1khz.toml"),
    include_str!("../../../../scenes/table2-background.toml"),
];

/// `text` with `[section] key = value` set (the table created when missing).
fn set(text: &str, section: &str, key: &str, value: &str) -> String {
    let mut doc: toml::Table = toml::from_str(text).expect("example parses");
    let t = doc
        .entry(section.to_string())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .expect("a table");
    let v: toml::Table = toml::from_str(&format!("v = {value}")).expect("value parses");
    t.insert(key.to_string(), v["v"].clone());
    toml::to_string(&doc).expect("serialises")
}

/// A short frame, so the resolution and the ROM stay cheap whatever was drawn.
fn shorten(text: &str, pulses: u64) -> String {
    let mut doc: toml::Table = toml::from_str(text).expect("parses");
    let acq = doc["acquisition"].as_table_mut().expect("acquisition");
    acq.remove("duration_s");
    acq.insert("pulses".into(), toml::Value::Integer(pulses as i64));
    if let Some(px) = doc.get_mut("pixel").and_then(|p| p.as_table_mut()) {
        px.remove("frame_pulses");
    }
    toml::to_string(&doc).expect("serialises")
}

fn roundtrip(d: &ResolvedDesign) -> ResolvedDesign {
    let json = d.to_json().expect("serialises");
    ResolvedDesign::from_json(&json).expect("deserialises")
}

/// 80 random documents (fixed seed); at least a third must resolve, so the round trip is
/// really exercised (the rest are refused by the resolution, which is not under test here).
#[test]
fn random_documents_roundtrip() {
    let mut rng = Rng(33);
    let (mut resolved, mut roms) = (0, 0);
    let cases = 80;
    for _ in 0..cases {
        let scene = rng.below(SCENES.len() as u64) as usize;
        let pulses = [16_384, 20_000, 40_000, 65_536][rng.below(4) as usize];
        let mut text = shorten(SCENES[scene], pulses);
        for _ in 0..rng.below(5) {
            let draw = rng.below(1000);
            let (section, k, v) = match rng.below(10) {
                0 => (
                    "pixel",
                    "mode",
                    ["\"fourier\"", "\"haar\"", "\"auto\""][draw as usize % 3].to_string(),
                ),
                1 => ("pixel", "bins", format!("{}", 1 + draw % 8)),
                2 => (
                    "probe",
                    "window",
                    ["\"rectangular\"", "\"hann\"", "\"blackman\""][draw as usize % 3].to_string(),
                ),
                3 => (
                    "probe",
                    "rom_mode",
                    ["\"periodic\"", "\"windowed\""][draw as usize % 2].to_string(),
                ),
                4 => (
                    "probe",
                    "rom_depth",
                    format!(
                        "{}",
                        [1000, 2000, 4000, 5000, 10_000, 20_000][draw as usize % 6]
                    ),
                ),
                5 => (
                    "probe",
                    "amplitude",
                    format!("{}", 0.1 + 0.5 * (draw as f64 / 1000.0)),
                ),
                6 => ("probe", "order", format!("{}", 1 + draw % 4)),
                7 => (
                    "sensor",
                    "jitter_ps",
                    format!("{}", 1.0 + draw as f64 * 0.37),
                ),
                8 => ("pixel", "adders", "\"auto\"".to_string()),
                _ => ("pixel", "register_frac_bits", format!("{}", draw % 9)),
            };
            text = set(&text, section, k, &v);
        }
        let Ok(doc) = Document::from_toml_str(&text, "random.toml") else {
            continue;
        };
        let Ok(d) = resolve_with(doc, "random.toml", &mut ProbeCache::default()) else {
            continue;
        };
        resolved += 1;
        let back = roundtrip(&d);
        assert_eq!(back, d, "{text}");
        // The ROM of the design, too (Fourier), and the one built from the received design
        // equals the one built from the original.
        if let Some(rom) = d.probe_rom().expect("a resolved design builds its ROM") {
            roms += 1;
            let json = serde_json::to_string(&rom).expect("rom serialises");
            let rom_back: ProbeRom = serde_json::from_str(&json).expect("rom deserialises");
            assert_eq!(rom_back, rom, "{text}");
            let rebuilt = back.probe_rom().expect("rom");
            assert_eq!(rebuilt.as_ref(), Some(&rom), "{text}");
        }
    }
    eprintln!("serde round trip: {cases} documents, {resolved} resolved, {roms} ROMs");
    assert!(
        resolved * 3 >= cases && roms > 5,
        "{resolved} resolved, {roms} ROMs"
    );
}

/// The examples themselves (their own frames, Haar and Fourier, periodic and windowed)
/// round-trip, and a design read back is the same whatever JSON whitespace it came in.
#[test]
fn every_example_roundtrips() {
    for text in SCENES {
        let doc = Document::from_toml_str(text, "example.toml").unwrap();
        let d = resolve_with(doc, "example.toml", &mut ProbeCache::default()).unwrap();
        assert_eq!(roundtrip(&d), d);
        let pretty = serde_json::to_string_pretty(&d).unwrap();
        assert_eq!(ResolvedDesign::from_json(&pretty).unwrap(), d);
    }
}

/// A ROM image whose words do not fit its size, and a probe design whose amplitude its
/// stability limit refuses, are refused on the way in (a received design is checked, not
/// trusted).
#[test]
fn tampered_designs_and_roms_are_refused() {
    let doc = Document::from_toml_str(&shorten(SCENES[0], 40_000), "t.toml").unwrap();
    let d = resolve_with(doc, "t.toml", &mut ProbeCache::default()).unwrap();
    let rom = d.probe_rom().unwrap().expect("Fourier");
    let mut v = serde_json::to_value(&rom).unwrap();
    let data = v["image"]["data"].as_array_mut().unwrap();
    data.pop();
    let e = serde_json::from_value::<ProbeRom>(v)
        .unwrap_err()
        .to_string();
    assert!(e.contains("words"), "{e}");

    let mut v = serde_json::to_value(&d).unwrap();
    v["probe_design"]["max_stable_amplitude"] = serde_json::json!(0.3);
    let e = ResolvedDesign::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("probe.amplitude"), "{e}");
}
