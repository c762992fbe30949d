//! The one resolution: deterministic, the probe-design cache changes nothing but the
//! time, every refusal names the key, and the chip ROM policy starts from the resolved
//! pixel.

use proptest::prelude::*;
use tofprobe_design::rom_policy::{RtlOverrides, rtl_params};
use tofprobe_design::{DEFAULT_ORIGIN, DEFAULT_TOML, Document, ProbeCache, resolve, resolve_with};

fn default_doc() -> Document {
    Document::from_toml_str(DEFAULT_TOML, DEFAULT_ORIGIN).expect("default")
}

/// A short default (4096 pulses would break the periodic 20,000-entry ROM, so the frame is
/// one ROM period).
fn short() -> Document {
    let mut d = default_doc();
    d.acquisition.pulses = Some(20_000);
    d.acquisition.duration_s = None;
    d
}

/// The cached resolution equals the plain one and reuses the design when only F changes
/// (F touches neither `[probe]` nor the bins).
#[test]
fn cached_resolution_equals_the_plain_one_and_reuses_the_design() {
    let mut c = short();
    let mut cache = ProbeCache::default();
    let a = resolve_with(c.clone(), "t", &mut cache).expect("resolves");
    let plain = resolve(c.clone(), "t").expect("resolves");
    assert_eq!(a.pixel, plain.pixel);
    assert_eq!(a.bins, plain.bins);
    assert_eq!(a.probe_rom().expect("rom"), plain.probe_rom().expect("rom"));
    c.pixel.frac_bits = 4;
    let b = resolve_with(c, "t", &mut cache).expect("resolves");
    assert_eq!(cache.len(), 1);
    assert_eq!(b.probe_rom().expect("rom"), a.probe_rom().expect("rom"));
}

/// The default resolves to the committed chip: W = 39, L = 20,000, bins k = 9 (4.5 kHz on
/// the 500 Hz grid) first; the RTL parameters are the same pixel.
#[test]
fn default_resolves_to_the_committed_chip() {
    let d = resolve(default_doc(), DEFAULT_ORIGIN).expect("resolves");
    assert_eq!((d.pixel.width, d.pixel.rom_depth), (39, 20_000));
    assert_eq!(d.bins[0], 9);
    let p = rtl_params(&d, &RtlOverrides::default()).expect("params");
    assert_eq!(p, d.pixel);
}

/// A `pixel.rom_depth` other than the `[probe]` ROM's is refused naming the key, the value
/// and the depth that works; an explicit width below the sizing names the minimum.
#[test]
fn refusals_name_the_key_the_value_and_a_fix() {
    let mut c = short();
    c.pixel.rom_depth = Some(1);
    let e = resolve(c, "t.toml").unwrap_err().to_string();
    assert!(
        e.contains("t.toml")
            && e.contains("pixel.rom_depth = 1")
            && e.contains("nearest valid value: 20000"),
        "{e}"
    );
    let mut c = short();
    c.pixel.width = Some(tofprobe_pixel::config::Choice::Value(20));
    let e = resolve(c, "t.toml").unwrap_err().to_string();
    assert!(e.contains("pixel.width = 20"), "{e}");
    // Control: the same document without the bad key resolves.
    assert!(resolve(short(), "t.toml").is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    /// Random documents resolve (or are refused) the same way twice, with or without a
    /// shared cache; an accepted one's pixel reads the `[probe]` ROM's depth and holds B
    /// bins inside the ΣΔ band.
    #[test]
    fn resolution_is_deterministic(
        periods in 1u64..4,
        width in prop::option::of(prop_oneof![Just(None), (30u32..48).prop_map(Some)]),
        bins in 1usize..20,
        rom_depth in prop::option::of(prop::sample::select(vec![1usize, 2048, 20_000])),
    ) {
        let mut c = default_doc();
        c.acquisition.pulses = Some(20_000 * periods);
        c.acquisition.duration_s = None;
        c.pixel.bins = tofprobe_pixel::config::Choice::Value(bins);
        c.pixel.cycles_per_pulse = 32;
        c.pixel.width = width.map(|w| match w {
            None => tofprobe_pixel::config::Choice::AUTO,
            Some(w) => tofprobe_pixel::config::Choice::Value(w),
        });
        c.pixel.rom_depth = rom_depth;
        let a = resolve(c.clone(), "p");
        let mut cache = ProbeCache::default();
        let b = resolve_with(c.clone(), "p", &mut cache);
        match (&a, &b) {
            (Ok(a), Ok(b)) => {
                prop_assert_eq!(&a.pixel, &b.pixel);
                prop_assert_eq!(&a.bins, &b.bins);
                prop_assert_eq!(a.pixel.rom_depth, c.probe.depth(a.pixel.frame_pulses));
                prop_assert_eq!(a.bins.len(), a.pixel.bins);
                let edge = a.pixel.rom_depth as f64 / (2.0 * c.probe.osr);
                prop_assert!(a.bins.iter().all(|&k| k >= 1 && (k as f64) < edge));
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            _ => prop_assert!(false, "one resolution accepted, the other refused"),
        }
    }
}

/// `[probe] convention`: "toolbox" resolves into the design and changes its ROM's bits
/// (docs/probe.md) but not its bins or readout normalisation; the
/// default is "tofprobe", written or not; a bad value or type names the key, the value
/// and the allowed values.
#[test]
fn probe_convention_is_resolved_and_a_bad_one_is_named() {
    use tofprobe_dsp::sd::ProbeConvention;
    let with = |line: &str| DEFAULT_TOML.replace("convention = \"tofprobe\"", line);
    assert!(
        DEFAULT_TOML.contains("convention = \"tofprobe\""),
        "the default documents the key"
    );
    let plain = resolve(short(), "t").expect("resolves");
    let doc = |text: &str| {
        let mut d = Document::from_toml_str(text, "t").expect("parses");
        d.acquisition.pulses = Some(20_000);
        d.acquisition.duration_s = None;
        d
    };
    let explicit = resolve(doc(&with("convention = \"tofprobe\"")), "t").expect("resolves");
    assert_eq!(
        explicit.probe_rom().expect("rom").expect("a Fourier ROM"),
        plain.probe_rom().expect("rom").expect("a Fourier ROM")
    );
    let toolbox = resolve(doc(&with("convention = \"toolbox\"")), "t").expect("resolves");
    let design = toolbox.probe_design.as_ref().expect("Fourier design");
    assert_eq!(design.config.convention, ProbeConvention::Toolbox);
    let (a, b) = (
        toolbox.probe_rom().expect("rom").expect("a Fourier ROM"),
        plain.probe_rom().expect("rom").expect("a Fourier ROM"),
    );
    assert_eq!(a.convention, ProbeConvention::Toolbox);
    assert_eq!(
        (a.coherent_gain, a.bin_indices.clone()),
        (b.coherent_gain, b.bin_indices.clone())
    );
    // The default is periodic (rectangular window): the sine's rounding alone parts the
    // streams, and the wrap search then keeps other cuts.
    assert_ne!(a.image, b.image);
    let e = Document::from_toml_str(&with("convention = \"numpy\""), "t")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("probe.convention = \"numpy\"")
            && e.contains("\"tofprobe\" (the default) or \"toolbox\""),
        "{e}"
    );
    let e = Document::from_toml_str(&with("convention = 3"), "t")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`probe.convention` = 3") && e.contains("a string"),
        "{e}"
    );
}
