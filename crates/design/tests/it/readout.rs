//! The array's readout contract (`tofprobe_design::readout`): its closed forms on the
//! default pixel (R = 32, W = 39, C = 16, 10 MHz: f_clk = 160 MHz), the order and the beat
//! decode, the width rule's extension bits, and every refusal naming its key with the
//! value that works.

use tofprobe_design::readout::{FIRST_BEAT_LATENCY, Readout, ReadoutKeys};
use tofprobe_design::{DEFAULT_ORIGIN, DEFAULT_TOML, Document, resolve};
use tofprobe_pixel::PixelParams;

const LASER: f64 = 10e6;

fn pixel(n: u64) -> PixelParams {
    PixelParams::fourier_default(39, n, 20_000)
}

fn keys(bits: Option<u32>, rate: Option<f64>, fr: Option<f64>) -> ReadoutKeys {
    ReadoutKeys {
        readout_bits: bits,
        readout_bits_per_s: rate,
        frame_rate_hz: fr,
        double_buffer: false,
    }
}

/// 64 × 64 default pixels, one 39-bit word per cycle: S = 33, D = 4096·33 + 1 = 135,169
/// cycles (0.845 ms at 160 MHz), 5,271,552 bits per frame, and a 1 s frame (N = 10^7)
/// every 160,135,169 cycles: 0.999156 Hz.
#[test]
fn the_default_64_by_64_readout_in_closed_form() {
    let r = Readout::new(&keys(None, None, None), 64, 64, &pixel(10_000_000), LASER).unwrap();
    assert_eq!((r.bits, r.beats_per_word, r.beat_cycles), (39, 1, 1));
    assert_eq!(r.slot_cycles(), 33);
    assert_eq!(r.readout_cycles(), 135_169);
    assert_eq!(r.stream_bits_per_frame(), 4096 * 33 * 39);
    assert_eq!(r.payload_bits_per_frame(), 5_271_552);
    assert_eq!(r.frame_cycles(), 160_000_000 + 135_169);
    assert!((r.frame_rate_hz() - 160e6 / 160_135_169.0).abs() < 1e-12);
    assert!((r.readout_seconds() - 135_169.0 / 160e6).abs() < 1e-15);
    assert!((r.port_bits_per_s() - 39.0 * 160e6).abs() < 1e-3);
    // Double-buffered, the readout hides under the next frame's 1.6·10^8 cycles.
    let db = Readout {
        double_buffer: true,
        ..r
    };
    assert_eq!(db.frame_cycles(), 160_000_001);
}

/// A 16-bit port carries a 39-bit word in k = 3 beats (48 bits, 9 of them extension), and
/// a 1 Gbit/s link spaces 16-bit beats ceil(2.56 Gbit/s / 1 Gbit/s) = 3 cycles apart.
#[test]
fn narrow_ports_and_slow_links_stretch_the_slot() {
    let r = Readout::new(&keys(Some(16), None, None), 3, 5, &pixel(64), LASER).unwrap();
    assert_eq!((r.beats_per_word, r.slot_cycles()), (3, 99));
    assert_eq!(r.readout_cycles(), 15 * 99 + 1);
    assert_eq!(r.stream_bits_per_frame(), 15 * 33 * 48);
    let r = Readout::new(&keys(Some(16), Some(1e9), None), 3, 5, &pixel(64), LASER).unwrap();
    assert_eq!((r.beat_cycles, r.slot_cycles()), (3, 297));
    assert!((r.port_bits_per_s() - 16.0 * 160e6 / 3.0).abs() < 1e-3);
}

/// The order is row-major; beat i decodes to (pixel, word, part) and its cycle is
/// q·S + (j·k + m)·g + 6 after the readout phase starts.
#[test]
fn the_order_and_the_beat_decode() {
    let r = Readout::new(&keys(Some(16), None, None), 3, 5, &pixel(64), LASER).unwrap();
    let order: Vec<_> = r.order_iter().collect();
    assert_eq!(order.len(), 15);
    assert_eq!(
        (order[0], order[4], order[5], order[14]),
        ((0, 0), (0, 4), (1, 0), (2, 4))
    );
    // Pixel 7 = (1, 2), its status word (j = 32), beat 2: 7·99 + 32·3 + 2.
    let b = r.beat(7 * 99 + 32 * 3 + 2);
    assert_eq!((b.position, b.row, b.col, b.word, b.part), (7, 1, 2, 32, 2));
    assert_eq!(r.beat_offset(7, 32, 2), 7 * 99 + 98 + FIRST_BEAT_LATENCY);
    let last = r.beat(r.beats_per_frame() - 1);
    assert_eq!((last.row, last.col, last.word, last.part), (2, 4, 32, 2));
}

/// Registers are sign-extended and the status word zero-extended to k·b bits, and the
/// beats give the word back.
#[test]
fn the_width_rule_extends_registers_by_sign_and_the_status_by_zero() {
    let r = Readout::new(&keys(Some(16), None, None), 1, 1, &pixel(64), LASER).unwrap();
    let all = (1u64 << 39) - 1;
    assert_eq!(r.beats_of(0, all), vec![0xFFFF, 0xFFFF, 0xFFFF]);
    assert_eq!(r.beats_of(32, all), vec![0xFFFF, 0xFFFF, 0x7F]);
    assert_eq!(r.beats_of(5, 5), vec![5, 0, 0]);
    // −2^38: bit 38 is bit 6 of beat 2, bits 39..47 the extension.
    assert_eq!(r.beats_of(1, 1 << 38), vec![0, 0, 0xFFC0]);
    for (j, raw) in [(0, all), (32, all), (3, 1 << 38), (3, 0x12_3456_789A)] {
        assert_eq!(r.word_of(&r.beats_of(j, raw)), raw);
    }
    // W = b: one beat, the word itself.
    let r = Readout::new(&keys(None, None, None), 1, 1, &pixel(64), LASER).unwrap();
    assert_eq!(r.beats_of(0, all), vec![all]);
}

/// A width beyond W or zero, a link faster than the port and a frame rate the readout
/// does not allow are refused, naming the key, the allowed range and what works.
#[test]
fn bad_readouts_are_refused_naming_what_works() {
    let e = Readout::new(&keys(Some(40), None, None), 2, 2, &pixel(64), LASER).unwrap_err();
    assert!(
        e.contains("array.readout_bits = 40") && e.contains("allowed 1..=39"),
        "{e}"
    );
    let e = Readout::new(&keys(Some(0), None, None), 2, 2, &pixel(64), LASER).unwrap_err();
    assert!(e.contains("array.readout_bits = 0"), "{e}");
    // 8 bits × 160 MHz = 1.28 Gbit/s; 2 Gbit/s needs ceil(2e9 / 160e6) = 13 bits.
    let e = Readout::new(&keys(Some(8), Some(2e9), None), 2, 2, &pixel(64), LASER).unwrap_err();
    assert!(
        e.contains("array.readout_bits_per_s = 2e9") && e.contains("readout_bits = 13"),
        "{e}"
    );
    // 64 × 64, N = 1000 (16,000 cycles): one word per cycle gives 151,169 cycles per
    // frame, 1058.4 Hz; 2000 Hz (80,000 cycles) cannot be met at any width.
    // A link so slow a frame's readout would pass 2^40 cycles (5e-324 bits/s once wrapped
    // the count past 2^64): refused with the slowest rate that fits.
    let e = Readout::new(&keys(Some(8), Some(5e-324), None), 2, 2, &pixel(64), LASER).unwrap_err();
    assert!(
        e.contains("array.readout_bits_per_s = 5e-324") && e.contains("2^40 cycles"),
        "{e}"
    );
    // 2 × 2 pixels of R + 1 words, each in ceil(39 / 8) = 5 beats of 8 bits at 1.28 Gbit/s.
    let beats = 4 * (pixel(64).registers() as u64 + 1) * 5;
    let slowest = 1.28e9 / ((((1u64 << 40) - 1) / beats) as f64);
    let ok = Readout::new(
        &keys(Some(8), Some(slowest * 1.001), None),
        2,
        2,
        &pixel(64),
        LASER,
    )
    .unwrap();
    assert!(ok.readout_cycles() <= 1 << 40, "{}", ok.readout_cycles());
    let e = Readout::new(&keys(None, None, Some(2000.0)), 64, 64, &pixel(1000), LASER).unwrap_err();
    assert!(
        e.contains("array.frame_rate_hz = 2000")
            && e.contains("1058.41")
            && e.contains("even array.readout_bits = 39"),
        "{e}"
    );
    // 13 bits (k = 3): 421,505 cycles, 379.6 Hz; 1000 Hz needs one beat per word: 39 bits.
    let e = Readout::new(
        &keys(Some(13), None, Some(1000.0)),
        64,
        64,
        &pixel(1000),
        LASER,
    )
    .unwrap_err();
    assert!(
        e.contains("379.5") && e.contains("array.readout_bits >= 39"),
        "{e}"
    );
    // 39 bits on a 1 Gbit/s link (g = 7): 166.29 Hz; 500 Hz (320,000 cycles) needs g <= 2,
    // 39 × 160 MHz / 2 = 3.12 Gbit/s.
    let e = Readout::new(
        &keys(None, Some(1e9), Some(500.0)),
        64,
        64,
        &pixel(1000),
        LASER,
    )
    .unwrap_err();
    assert!(
        e.contains("166.2895") && e.contains("readout_bits_per_s >= 3.120000e9"),
        "{e}"
    );
    // And a rate it allows passes.
    Readout::new(
        &keys(None, Some(1e9), Some(160.0)),
        64,
        64,
        &pixel(1000),
        LASER,
    )
    .unwrap();
}

/// The keys are `[array]` keys of the document: the resolution refuses a bad one naming
/// it and the file, and `ResolvedDesign::readout` resolves a good one.
#[test]
fn the_document_resolution_checks_the_readout() {
    let text = DEFAULT_TOML.replace("duration_s = 1.0", "pulses = 20000");
    let array = "\n[array]\nrows = 4\ncols = 4\npitch_um = 30.0\nmm_per_pixel = 1.0\n";
    let doc =
        Document::from_toml_str(&format!("{text}{array}readout_bits = 13\n"), "a.toml").unwrap();
    let d = resolve(doc, "a.toml").unwrap();
    let r = d.readout().unwrap().unwrap();
    assert_eq!((r.rows, r.cols, r.bits, r.beats_per_word), (4, 4, 13, 3));
    let doc =
        Document::from_toml_str(&format!("{text}{array}readout_bits = 99\n"), "a.toml").unwrap();
    let e = resolve(doc, "a.toml").unwrap_err().to_string();
    assert!(
        e.contains("a.toml") && e.contains("array.readout_bits = 99"),
        "{e}"
    );
    let doc = Document::from_toml_str(&format!("{text}{array}readout_lanes = 2\n"), "a.toml");
    assert!(doc.is_err(), "an unknown key is refused");
    let single = resolve(Document::from_toml_str(&text, "s.toml").unwrap(), "s.toml").unwrap();
    assert!(single.readout().unwrap().is_none());
    let _ = DEFAULT_ORIGIN;
}

/// Double-buffered, the swap edge must come after the last pulse's last register write:
/// a pixel at C = K is refused naming both
/// keys and the C that works; C = K + 1 is accepted.
#[test]
fn a_double_buffer_needs_more_cycles_than_slots() {
    let mut p = pixel(64);
    let k = p.slots();
    p.cycles_per_pulse = k;
    p.validate().unwrap();
    let db = ReadoutKeys {
        double_buffer: true,
        ..keys(None, None, None)
    };
    let e = Readout::new(&db, 2, 2, &p, LASER).unwrap_err();
    assert!(
        e.contains("array.double_buffer = true")
            && e.contains(&format!("pixel.cycles_per_pulse > {k}"))
            && e.contains(&format!("cycles_per_pulse = {} works", k + 1)),
        "{e}"
    );
    // Single-buffered the same pixel is fine; C = K + 1 is fine double-buffered.
    assert!(Readout::new(&keys(None, None, None), 2, 2, &p, LASER).is_ok());
    p.cycles_per_pulse = k + 1;
    assert!(Readout::new(&db, 2, 2, &p, LASER).unwrap().double_buffer);
}
