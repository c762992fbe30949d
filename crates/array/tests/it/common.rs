//! Small array designs for the tests: the plate-mode example shrunk (fewer pixels, a frame
//! of 10 ROM periods), with the scene's motions and `[array]` replaced.

use std::ops::Range;

use tofprobe_design::{Document, ProbeCache, ResolvedDesign, resolve_with};

/// The example's sensor, pixel and probe (periodic L = 20,000, 500 Hz bins, B = 4) with
/// `motions` (TOML `[[scene.motion]]` tables), `pulses` per pixel and `array` (the body of
/// the `[array]` table).
pub fn design(motions: &str, pulses: u64, array: &str) -> ResolvedDesign {
    parse(&text(motions, pulses, array))
}

/// The same as a Haar pixel with U = 4 (31 registers; no `[probe]`).
pub fn haar_design(motions: &str, pulses: u64, array: &str) -> ResolvedDesign {
    let t = text(motions, pulses, array);
    let head = t.split("[probe]").next().unwrap();
    let tail = &t[t.find("[array]").unwrap()..];
    let t = format!("{head}{tail}").replacen(
        "mode = \"fourier\"",
        "mode = \"haar\"\nhaar_scales = 4",
        1,
    );
    parse(&t)
}

/// The document's text.
pub fn text(motions: &str, pulses: u64, array: &str) -> String {
    let text = include_str!("../../../../scenes/plate-mode.toml");
    let head = text.split("[[scene.motion]]").next().unwrap();
    let tail = &text[text.find("[acquisition]").unwrap()..];
    let tail = tail.split("[array]").next().unwrap();
    let tail = tail.replacen("pulses = 1000000", &format!("pulses = {pulses}"), 1);
    format!("{head}{motions}\n{tail}\n[array]\n{array}\n")
}

fn parse(doc: &str) -> ResolvedDesign {
    let d = Document::from_toml_str(doc, "test.toml").unwrap_or_else(|e| panic!("{e}\n{doc}"));
    resolve_with(d, "test.toml", &mut ProbeCache::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The (m, n) mode of a 80 × 80 mm plate, 1 mm at 1.5 kHz.
pub fn plate(m: u32, n: u32) -> String {
    format!(
        "[[scene.motion]]\nkind = \"plate_mode\"\nm = {m}\nn = {n}\nlength_x_mm = 80.0\n\
         length_y_mm = 80.0\namplitude_mm = 1.0\nfrequency_hz = 1500.0\n"
    )
}

/// Tiles of `d`'s array, each `(rows, cols, threads)` run on a pool of that many threads,
/// merge into the whole frame (run on 2 threads) byte for byte: per-pixel seeds make a
/// pixel's registers independent of the tiling and the pool.
pub fn assert_tiles_merge(d: &ResolvedDesign, tiles: &[(Range<usize>, Range<usize>, usize)]) {
    let rom = d.probe_rom().unwrap().unwrap();
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let whole = pool(2)
        .install(|| tofprobe_array::model::run_array(d, Some(&rom.image)))
        .unwrap();
    let parts: Vec<_> = tiles
        .iter()
        .map(|(rows, cols, n)| {
            pool(*n)
                .install(|| {
                    tofprobe_array::run_tile(d, Some(&rom.image), rows.clone(), cols.clone())
                })
                .unwrap()
        })
        .collect();
    let a = d.array.as_ref().unwrap();
    assert_eq!(
        tofprobe_array::model::merge(a.rows, a.cols, &parts).unwrap(),
        whole
    );
}
