//! The array at the clock edge (`tofprobe_array::rtl_model`, driven by `tofprobe_array::rtl_driver`) against the contract: every pixel's
//! words in the stream are the words its own pixel model reads out under the pixel's
//! reference sequence (a naive per-pixel drive, no array logic), the beats sit exactly at
//! the cycles of the contract's formula, no pulse is refused, and each array fault changes
//! the stream.

use tofprobe_array::rtl_driver::run;
use tofprobe_array::rtl_model::ArrayModel;
use tofprobe_design::readout::{Readout, ReadoutKeys};
use tofprobe_pixel::{CycleModel, Mode, PinsIn, PixelParams};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::array::ArrayTile;
use tofprobe_scene::SplitMix64;

pub fn fourier(n: u64) -> PixelParams {
    let mut p = PixelParams::fourier_default(24, n, 8);
    p.bins = 3;
    p.adders = 2;
    p.cycles_per_pulse = 4;
    p.tdc_bits = 5;
    p.frac_bits = 4;
    p.shift = 2;
    p.validate().unwrap();
    p
}

pub fn haar(n: u64) -> PixelParams {
    let mut p = fourier(n);
    p.mode = Mode::Haar;
    p.haar_scales = 2;
    p.frac_bits = 0;
    p.shift = 0;
    p.adders = 1;
    p.cycles_per_pulse = 3;
    p.width = 13;
    p.validate().unwrap();
    p
}

pub fn rom(p: &PixelParams, seed: u64) -> Vec<u64> {
    if p.mode == Mode::Haar {
        return Vec::new();
    }
    let mut g = SplitMix64::new(seed);
    (0..p.rom_depth)
        .map(|_| g.next_u64() & ((1 << p.registers()) - 1))
        .collect()
}

pub fn detections(p: &PixelParams, np: usize, pulses: u64, seed: u64) -> Vec<Vec<Option<u32>>> {
    let mut g = SplitMix64::new(seed);
    (0..np)
        .map(|_| {
            (0..pulses)
                .map(|_| {
                    let r = g.next_u64();
                    (r & 3 != 0).then_some(((r >> 8) % (1 << p.tdc_bits)) as u32)
                })
                .collect()
        })
        .collect()
}

/// One pixel driven alone by the pixel contract's reference sequence (N pulses every C
/// cycles, the readout strobe, R + 1 idle cycles): its R + 1 readout words per frame.
pub fn pixel_alone(p: &PixelParams, rom: &[u64], d: &[Option<u32>], frames: u64) -> Vec<Vec<u64>> {
    let mut m = CycleModel::new(p).unwrap();
    let idle = PinsIn::default();
    let mut out = Vec::new();
    let n = p.frame_pulses;
    let mut words = Vec::new();
    let step = |m: &mut CycleModel, pins: &PinsIn, words: &mut Vec<u64>| {
        let o = m.step(pins);
        if o.rd_valid {
            words.push(o.rd_data);
        }
    };
    for _ in 0..2 {
        step(&mut m, &PinsIn { rst: true, ..idle }, &mut words);
    }
    for f in 0..frames {
        for k in 0..n {
            let det = d[(f * n + k) as usize];
            let word: &[u64] = if rom.is_empty() {
                &[]
            } else {
                &rom[(k as usize) % p.rom_depth..(k as usize) % p.rom_depth + 1]
            };
            let pins = PinsIn {
                pulse: true,
                valid: det.is_some(),
                tdc: det.unwrap_or(0),
                rom_word: word,
                ..idle
            };
            step(&mut m, &pins, &mut words);
            for _ in 1..p.cycles_per_pulse {
                step(&mut m, &idle, &mut words);
            }
        }
        step(
            &mut m,
            &PinsIn {
                readout: true,
                ..idle
            },
            &mut words,
        );
        for _ in 0..p.registers() + 2 {
            step(&mut m, &idle, &mut words);
        }
        out.push(std::mem::take(&mut words));
    }
    out
}

pub fn readout(
    p: &PixelParams,
    rows: usize,
    cols: usize,
    bits: Option<u32>,
    rate: Option<f64>,
) -> Readout {
    let keys = ReadoutKeys {
        readout_bits: bits,
        readout_bits_per_s: rate,
        ..ReadoutKeys::default()
    };
    Readout::new(&keys, rows, cols, p, 1e6).unwrap()
}

fn check(p: &PixelParams, ro: &Readout, frames: u64, seed: u64) {
    let np = ro.pixels();
    let rom = rom(p, seed);
    let d = detections(p, np, frames * p.frame_pulses, seed ^ 1);
    let mut m = ArrayModel::new(ro, p, &rom, None).unwrap();
    let r = run(&mut m, &d, frames).unwrap();
    // The beats sit where the formula puts them, and nowhere else.
    let mut expected: Vec<u64> = (0..frames)
        .flat_map(|f| {
            let r = &r;
            (0..np).flat_map(move |q| {
                (0..ro.words_per_pixel()).flat_map(move |j| {
                    (0..ro.beats_per_word).map(move |k| r.beat_cycle(f, q, j, k))
                })
            })
        })
        .collect();
    expected.sort_unstable();
    let seen: Vec<u64> = (0..r.cycles())
        .filter(|&c| r.pins[c as usize].ro_valid)
        .collect();
    assert_eq!(
        seen, expected,
        "{}x{} b={} g={}",
        ro.rows, ro.cols, ro.bits, ro.beat_cycles
    );
    // The tail (6 cycles) shows the next frame's first pulses, from 2 cycles after its start.
    let tail = (tofprobe_array::rtl_model::TAIL_CYCLES - 2).div_ceil(p.cycles_per_pulse as u64);
    assert_eq!(r.pulse_cycles.len() as u64, frames * p.frame_pulses + tail);
    // Every pixel's words are its own reference's, status 0 (nothing refused).
    for (q, (row, col)) in ro.order_iter().enumerate() {
        let i = row * ro.cols + col;
        let alone = pixel_alone(p, &rom, &d[i], frames);
        assert_eq!(alone.len() as u64, frames);
        for (f, words) in alone.iter().enumerate() {
            assert_eq!(&r.words[f][q], words, "pixel ({row}, {col}) frame {f}");
            assert_eq!(r.words[f][q][ro.registers], 0, "nothing refused");
        }
    }
    assert!(
        r.words.iter().flatten().flatten().any(|&w| w != 0),
        "the registers saw detections"
    );
}

/// 2 × 2 Fourier, one word per beat: S = 7, beats every cycle, 3 frames.
#[test]
fn two_by_two_fourier_streams_every_pixel_s_words() {
    let p = fourier(8);
    let ro = readout(&p, 2, 2, None, None);
    assert_eq!(ro.slot_cycles(), 7);
    check(&p, &ro, 3, 11);
}

/// 3 × 5 Haar on a 5-bit port (k = 3 beats for W = 13, two extension bits).
#[test]
fn three_by_five_haar_on_a_narrow_port() {
    let p = haar(8);
    let ro = readout(&p, 3, 5, Some(5), None);
    assert_eq!(ro.beats_per_word, 3);
    check(&p, &ro, 2, 12);
}

/// A slow link (g = 3) and a 10-bit port (k = 3) on a 2 × 3 Fourier array, and a 1-bit
/// port on a 1 × 2 array: the readout buffer is never overwritten before it drains.
#[test]
fn slow_links_and_one_bit_ports_keep_every_word() {
    let p = fourier(4);
    // f_clk = 4 MHz: 10 bits × 4 MHz = 40 Mbit/s; 15 Mbit/s gives g = 3.
    let ro = readout(&p, 2, 3, Some(10), Some(15e6));
    assert_eq!((ro.beats_per_word, ro.beat_cycles), (3, 3));
    check(&p, &ro, 2, 13);
    let ro = readout(&p, 1, 2, Some(1), None);
    check(&p, &ro, 2, 14);
}

/// Each fault of the array changes the stream (the first differing cycle is where a
/// broken RTL must first differ from the correct model).
#[test]
fn each_array_fault_changes_the_stream() {
    let p = fourier(8);
    let ro = readout(&p, 2, 2, None, None);
    let rom = rom(&p, 5);
    let d = detections(&p, 4, 16, 6);
    let good = run(&mut ArrayModel::new(&ro, &p, &rom, None).unwrap(), &d, 2).unwrap();
    for f in [
        ArrayFault::RowLate { row: 1 },
        ArrayFault::NeighbourTdc { row: 0, col: 1 },
        ArrayFault::OrderSwap,
        ArrayFault::RowStuck { row: 0 },
    ] {
        let bad = run(&mut ArrayModel::new(&ro, &p, &rom, Some(f)).unwrap(), &d, 2).unwrap();
        let first = (0..good.pins.len()).find(|&c| good.pins[c] != bad.pins[c]);
        let c = first.unwrap_or_else(|| panic!("{f:?} changes nothing"));
        // A late row shows at its first pulse (the array's `ready` drops a cycle late:
        // pulse 0 reaches the pixels at cycle 2 + 2 = 4, its 2 slots end at 6, the late
        // row's at 7); the others in frame 0's readout.
        let what = good.explain(c as u64);
        if let ArrayFault::RowLate { .. } = f {
            assert_eq!(
                (c, bad.pins[c].ready, good.pins[c].ready),
                (7, false, true),
                "{what}"
            );
            assert!(what.contains("frame 0, pulse 0"), "{what}");
        } else {
            let readout_start = 2 + ro.accumulate_cycles();
            assert!(
                c as u64 >= readout_start && (c as u64) < 2 + ro.frame_cycles(),
                "{f:?} at {c}"
            );
            assert!(what.contains("frame 0's readout, pixel ("), "{what}");
        }
    }
}

/// A tile of the array (the part co-simulated when the whole is too large) keeps the whole
/// array's timing: its pixels' beats are the whole array's, at the same cycles, and the
/// other pixels' slots are silent.
#[test]
fn a_tile_streams_its_pixels_at_the_whole_arrays_cycles() {
    let p = fourier(8);
    let ro = readout(&p, 5, 6, Some(10), None);
    let rom = rom(&p, 21);
    let d = detections(&p, 30, 16, 22);
    let whole = run(&mut ArrayModel::new(&ro, &p, &rom, None).unwrap(), &d, 2).unwrap();
    let t = ArrayTile {
        row0: 3,
        col0: 4,
        rows: 2,
        cols: 2,
    };
    let dt: Vec<_> = (3..5)
        .flat_map(|r| (4..6).map(move |c| r * 6 + c))
        .map(|i| d[i].clone())
        .collect();
    let tile = run(
        &mut ArrayModel::tile(&ro, &p, &rom, None, Some(t)).unwrap(),
        &dt,
        2,
    )
    .unwrap();
    assert_eq!(tile.positions, vec![22, 23, 28, 29]);
    for f in 0..2 {
        for (k, &q) in tile.positions.iter().enumerate() {
            assert_eq!(
                tile.words[f][k], whole.words[f][q],
                "frame {f} position {q}"
            );
        }
    }
    let beats = |r: &tofprobe_array::rtl_driver::ArrayRun| -> Vec<u64> {
        (0..r.cycles())
            .filter(|&c| r.pins[c as usize].ro_valid)
            .collect()
    };
    let want: Vec<u64> = beats(&whole)
        .into_iter()
        .filter(|&c| {
            let e = whole.explain(c);
            ["(3, 4)", "(3, 5)", "(4, 4)", "(4, 5)"]
                .iter()
                .any(|p| e.contains(&format!("pixel {p}")))
        })
        .collect();
    assert_eq!(beats(&tile), want);
    assert_eq!(
        want.len(),
        2 * 4 * 7 * 3,
        "2 frames × 4 pixels × 7 words × 3 beats"
    );
    assert!(
        ArrayModel::tile(
            &ro,
            &p,
            &rom,
            None,
            Some(ArrayTile {
                row0: 4,
                col0: 4,
                rows: 2,
                cols: 2
            })
        )
        .is_err()
    );
}
