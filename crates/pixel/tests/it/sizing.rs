//! Width sizing and readout size (issue point 6), the paper's memory example included, and
//! the `[pixel]` validation of widths and schedules.

use tofprobe_dsp::RomImage;
use tofprobe_pixel::config::{Choice, PixelContext};
use tofprobe_pixel::sizing::{
    any_sign_range, compression, raw_timestamp_bytes, readout_bytes, required_width,
    rom_sign_counts, twos_complement_bits, unsigned_bits,
};
use tofprobe_pixel::{Mode, PixelConfig, PixelError, PixelParams, TransactionModel};

/// The paper: 10 mm motion, 1 mm TDC LSB, N = 10^7 → "26-bit I/Q". That holds only for
/// depths of ±5 codes counted without a sign bit (|Y| ≤ 5·10^7 < 2^26); in two's complement
/// ±5 codes need 27 bits, and codes 0..10 weighted ±1 reach ±10^8 and need 28 bits.
/// Zooming (centring the depth, Z = 5) brings 0..10 back to ±5 codes: 27 bits.
#[test]
fn paper_memory_example() {
    let n = 10_000_000u64;
    let (lo, hi) = any_sign_range(-5, 5, n);
    assert_eq!((lo, hi), (-50_000_000, 50_000_000));
    assert_eq!(
        unsigned_bits(hi as u128),
        26,
        "the paper's 26 bits: magnitude only"
    );
    assert_eq!(twos_complement_bits(lo, hi), 27);
    let (lo, hi) = any_sign_range(0, 10, n);
    assert_eq!(twos_complement_bits(lo, hi), 28);

    // The same through the pixel's parameters: T = 4 bits codes 0..10, F = 0.
    let mut p = PixelParams::fourier_default(28, n, 1);
    p.bins = 128;
    p.adders = 256;
    p.tdc_bits = 4;
    p.frac_bits = 0;
    assert_eq!(required_width(&p, 0, 10, None), 28);
    p.zoom = 5;
    assert_eq!(required_width(&p, 0, 10, None), 27, "centred by the zoom");

    // Readout: 128 bins × 2 × 26 bits = 832 B against 10^7 × 14-bit timestamps = 17.5 MB:
    // 21,034× (the paper prints ≈ 22,400×).
    assert_eq!(readout_bytes(256, 26, false), 832.0);
    assert_eq!(raw_timestamp_bytes(n, 14), 17.5e6);
    let c = compression(n, 14, 256, 26);
    assert_eq!(c.round(), 21_034.0, "{c}");
    // Haar: 127 coefficients for 100,000 timestamps (787×); 500,000 → 3937×.
    assert_eq!((100_000.0f64 / 127.0).round(), 787.0);
    assert_eq!((500_000.0f64 / 127.0).round(), 3937.0);
}

/// With the ROM known, the exact per-register add/subtract counts tighten the bound: a
/// balanced register (n₊ = n₋ = N/2) on codes 0..10 reaches only N/2·10, one bit less than
/// the any-sign bound; an all-ones register needs the full N·10.
#[test]
fn rom_sign_counts_are_exact_and_tighten_the_width() {
    // Register 0 alternates (balanced), register 1 is all ones, register 2 ones at a < 3.
    let rom = RomImage::from_fn(8, 3, |a, r| match r {
        0 => a % 2 == 0,
        1 => true,
        _ => a < 3,
    });
    // N = 20 = 2 periods + 4: register 2 has 2·3 + 3 ones.
    assert_eq!(
        rom_sign_counts(&rom, 3, 20),
        vec![(10, 10), (20, 0), (9, 11)]
    );
    let mut p = PixelParams::fourier_default(30, 1_000_000, 8);
    p.bins = 1;
    p.adders = 2;
    p.tdc_bits = 4;
    p.frac_bits = 0;
    let balanced = RomImage::from_fn(8, 2, |a, _| a % 2 == 0);
    // Any-sign: 10^7 → 25 bits; balanced: 5·10^6 → 24 bits.
    assert_eq!(required_width(&p, 0, 10, None), 25);
    assert_eq!(required_width(&p, 0, 10, Some(&balanced)), 24);
}

/// The sized width is sufficient and one bit less is not: N = 1000 pulses at the top code
/// 10 with every ROM bit 1 give Y = 999·10 = 9990 (the priming pulse adds nothing), which
/// W = 15 holds and W = 14 (max 8191) wraps to 9990 − 16384.
#[test]
fn sized_width_holds_the_worst_case_and_one_less_wraps() {
    let mut p = PixelParams::fourier_default(15, 1000, 1);
    p.bins = 1;
    p.adders = 2;
    p.tdc_bits = 4;
    p.frac_bits = 0;
    p.shift = 0;
    assert_eq!(required_width(&p, 0, 10, None), 15);
    let stimuli = vec![Some(10u32); 1000];
    let rom = RomImage::from_fn(1, 2, |_, _| true);
    for (w, expected) in [(15, 9990), (14, 9990 - 16384)] {
        p.width = w;
        let mut tm = TransactionModel::new(&p).unwrap();
        let r = tm.run_frames(&stimuli, Some(&rom)).unwrap();
        assert_eq!(r[0].words, vec![expected; 2], "W = {w}");
    }
}

/// The same with F = 4 fraction bits of which the registers keep G = 1: at S = 0 x is the
/// held code times 2^4 = 160, the operand 160 >>> 3 = 20 (10·2^G), so Y = 999·20 = 19980:
/// W = 16 holds it and W = 15 (max 16383) wraps it to 19980 − 32768. Keeping all F bits
/// (G = 4: operands of 160) needs F − G = 3 bits more, 19.
#[test]
fn sizing_follows_the_register_fraction_bits() {
    let mut p = PixelParams::fourier_default(16, 1000, 1);
    p.bins = 1;
    p.adders = 2;
    p.tdc_bits = 4;
    p.frac_bits = 4;
    p.shift = 0;
    assert_eq!(required_width(&p, 0, 10, None), 19);
    p.register_frac_bits = Some(1);
    assert_eq!(required_width(&p, 0, 10, None), 16);
    let stimuli = vec![Some(10u32); 1000];
    let rom = RomImage::from_fn(1, 2, |_, _| true);
    for (w, expected) in [(16, 19980), (15, 19980 - 32768)] {
        p.width = w;
        let mut tm = TransactionModel::new(&p).unwrap();
        let r = tm.run_frames(&stimuli, Some(&rom)).unwrap();
        assert_eq!(r[0].words, vec![expected; 2], "W = {w}");
    }
}

fn default_context() -> PixelContext {
    // The default scene's sensor: 400 ps window / 5 ps LSB = 80 codes, 10 MHz, 1 s.
    PixelContext {
        tdc_codes: 80,
        laser_rate_hz: 10e6,
        pulses: 10_000_000,
        code_range: None,
        tones: Vec::new(),
        osr: 32.0,
    }
}

/// The default `[pixel]` on the default scene: T = 7 bits for 80 codes, W from the sizing:
/// codes 0..79 at F = 8 over 10^7 pulses reach ±10^7·79·256 = ±2.02·10^11 → 39 bits.
#[test]
fn default_config_resolves_on_the_default_scene() {
    let p = PixelConfig::default().resolve(&default_context()).unwrap();
    assert_eq!(
        (p.mode, p.bins, p.adders, p.cycles_per_pulse, p.slots()),
        (Mode::Fourier, 16, 2, 16, 16)
    );
    assert_eq!((p.tdc_bits, p.shift, p.frac_bits), (7, 5, 8));
    assert_eq!(p.width, 39);
    assert_eq!((p.frame_pulses, p.rom_depth), (10_000_000, 10_000_000));
    // The same configuration from TOML, every key spelled out.
    let toml_text = "mode = \"fourier\"\nbins = 16\nadders = 2\ncycles_per_pulse = 16\nshift = 5\nfrac_bits = 8\n";
    let c: PixelConfig = toml::from_str(toml_text).unwrap();
    assert_eq!(c, PixelConfig::default());
    assert!(
        toml::from_str::<PixelConfig>("colour = 1").is_err(),
        "unknown keys rejected"
    );
}

fn nearest(e: PixelError) -> (&'static str, String) {
    match e {
        PixelError::Invalid { field, nearest, .. } => (field, nearest),
        other => panic!("unexpected {other}"),
    }
}

/// Impossible configurations are rejected with the field and the nearest valid value.
#[test]
fn impossible_configurations_name_the_nearest_valid_value() {
    let ctx = default_context();
    let with = |f: &dyn Fn(&mut PixelConfig)| {
        let mut c = PixelConfig::default();
        f(&mut c);
        c.resolve(&ctx).map(|_| ()).map_err(nearest)
    };
    // 32 registers on 2 adders need 16 slots: C = 15 is too few.
    assert_eq!(
        with(&|c| c.cycles_per_pulse = 15),
        Err(("cycles_per_pulse", "16".into()))
    );
    // One adder: C ≥ 32.
    assert_eq!(
        with(&|c| {
            c.adders = Choice::Value(1);
        }),
        Err(("cycles_per_pulse", "32".into()))
    );
    assert_eq!(
        with(&|c| c.width = Some(tofprobe_pixel::config::Choice::Value(38))),
        Err(("width", "39".into()))
    );
    assert_eq!(
        with(&|c| c.width = Some(tofprobe_pixel::config::Choice::Value(40))),
        Ok(())
    );
    assert_eq!(
        with(&|c| c.tdc_bits = Some(6)),
        Err(("tdc_bits", "7".into()))
    );
    assert_eq!(with(&|c| c.zoom = 128), Err(("zoom", "127".into())));
    assert_eq!(with(&|c| c.shift = 16), Err(("shift", "15".into())));
    assert_eq!(with(&|c| c.frac_bits = 17), Err(("frac_bits", "16".into())));
    assert_eq!(
        with(&|c| c.adders = Choice::Value(33)),
        Err(("adders", "32".into()))
    );
    assert_eq!(
        with(&|c| c.bins = tofprobe_pixel::config::Choice::Value(0)),
        Err(("bins", "1".into()))
    );
    assert_eq!(
        with(&|c| c.frequencies_hz = vec![1000.0, 2000.0]),
        Err(("frequencies_hz", "bins = 2".into()))
    );
    // Haar needs N a power of two: 10^7 → 2^23 is nearest.
    assert_eq!(
        with(&|c| c.mode = Choice::Value(Mode::Haar)),
        Err(("frame_pulses", "8388608".into()))
    );
    assert_eq!(
        with(&|c| {
            c.mode = Choice::Value(Mode::Haar);
            c.frame_pulses = Some(16);
            c.haar_scales = Some(4);
        }),
        Err(("haar_scales", "3".into()))
    );
    // Haar, N = 2^20, U = 4: 31 registers, W for codes 0..79 over N/2 adds and subtracts.
    let mut c = PixelConfig {
        mode: Choice::Value(Mode::Haar),
        frame_pulses: Some(1 << 20),
        ..PixelConfig::default()
    };
    let p = c.resolve(&ctx).unwrap();
    assert_eq!((p.registers(), p.slots()), (31, 3));
    // Scale 0: ±2^19·79 → 2^19·79 < 2^26 → 27 bits.
    assert_eq!(p.width, 27);
    // A frame too long for 63-bit registers (periodic ROM: a windowed one, L = N, would be
    // refused first for its depth beyond 2^32).
    c.mode = Choice::Value(Mode::Fourier);
    c.frame_pulses = Some(1 << 50);
    c.rom_depth = Some(1 << 16);
    assert_eq!(
        c.resolve(&ctx).map(|_| ()).map_err(nearest),
        Err(("width", "63".into()))
    );
}

/// The shipped default scene's `[pixel]` (scenes/default.toml) resolves against its own
/// `[sensor]` and acquisition (1 s at 10 MHz): the explicit keys there equal the defaults,
/// and the sized W = 39 holds every final value of codes 0..79 over the 10^7-pulse frame.
#[test]
fn shipped_default_scene_pixel_section_resolves() {
    let text = include_str!("../../../../scenes/default.toml");
    let doc: toml::Table = toml::from_str(text).unwrap();
    let pixel: PixelConfig = doc["pixel"].clone().try_into().unwrap();
    assert_eq!(pixel, PixelConfig::default());
    let sensor: tofprobe_scene::SensorConfig = doc["sensor"].clone().try_into().unwrap();
    let ctx = PixelContext::from_sensor(&sensor, 10_000_000);
    let p = pixel.resolve(&ctx).unwrap();
    assert_eq!((p.tdc_bits, p.width, p.registers()), (7, 39, 32));
    // Margin: the worst case 10^7·79·256 = 2.02·10^11 is 0.74 of 2^38.
    let worst = 10_000_000f64 * 79.0 * 256.0;
    assert!(worst < 2f64.powi(38) && worst > 2f64.powi(37));
}

/// Per-register widths, the scene's code range and the summary report.
#[test]
fn sizing_report_for_a_scene() {
    use tofprobe_pixel::sizing::{SizingReport, register_widths, scene_code_range};
    // 30 mm ± 0.1 mm, σ = 7.5 mm, ±4σ, 0.75 mm codes from 0 mm, 80 codes: codes
    // floor((29.9 − 30)/0.75) = −1 → 0 and floor((30.1 + 30)/0.75) = 80 → 79.
    assert_eq!(
        scene_code_range(29.9, 30.1, 7.5, 4.0, 0.0, 0.75, 80, false),
        (0, 79)
    );
    // σ = 0.75 mm: codes floor(26.9/0.75) = 35 to floor(33.1/0.75) = 44.
    assert_eq!(
        scene_code_range(29.9, 30.1, 0.75, 4.0, 0.0, 0.75, 80, false),
        (35, 44)
    );
    // Background photons reach the whole window.
    assert_eq!(
        scene_code_range(29.9, 30.1, 0.75, 4.0, 0.0, 0.75, 80, true),
        (0, 79)
    );
    // Balanced register 0 and all-ones register 1, codes 35..44, N = 10^6, F = 0, zoom 0:
    // register 0 reaches ±(N/2)·44 − (N/2)·35 → [−4.5e6, 4.5e6] → 24 bits; register 1
    // reaches 44·10^6 → 27 bits.
    let mut p = PixelParams::fourier_default(30, 1_000_000, 2);
    p.bins = 1;
    p.frac_bits = 0;
    let rom = RomImage::from_fn(2, 2, |a, r| r == 1 || a == 0);
    assert_eq!(register_widths(&p, 35, 44, Some(&rom)), vec![24, 27]);
    // Zoom to the centre (Z = 40: codes −5..4) brings the all-ones register to
    // [−5·10^6, 4·10^6] → 24 bits: centring the depth is what shrinks the DC term.
    p.zoom = 40;
    assert_eq!(register_widths(&p, 35, 44, Some(&rom)), vec![24, 24]);
    let r = SizingReport::new(&p, 35, 44, Some(&rom), 14);
    assert_eq!(r.width, 24);
    // 2 words × 24 bits = 6 bytes against 10^6 × 14 bits = 1.75 MB.
    assert_eq!((r.readout_bytes, r.raw_bytes), (6.0, 1.75e6));
    assert!((r.compression - 1.75e6 / 6.0).abs() < 1e-6);
}
