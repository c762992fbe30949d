//! The double-buffered array (docs/pixel-contract.md "Double buffer") against the single
//! pixel alone: each pixel's shadow streams the very words its own pixel model reads out
//! under the pixel's reference sequence (the naive drive of `rtl::pixel_alone`, no array
//! logic, no shadow), status 0, while the next frame's pulses are presented — and accepted
//! — during the readout; the frame is max(N·C + 1, D) cycles, the beats at the contract's
//! cycles; and the shadow taken a cycle late is caught at the first beat it spoils.

use tofprobe_array::rtl_driver::run;
use tofprobe_array::rtl_model::ArrayModel;
use tofprobe_design::readout::{BROADCAST_LATENCY, Readout};
use tofprobe_pixel::PixelParams;
use tofprobe_pixel::sequencer::RESET_CYCLES;
use tofprobe_rtlgen::ArrayFault;

use crate::rtl::{detections, fourier, haar, pixel_alone, readout, rom};

fn double(mut ro: Readout) -> Readout {
    ro.double_buffer = true;
    ro
}

/// Runs `frames` double-buffered frames and checks them against each pixel alone; returns
/// the frame period.
fn check(p: &PixelParams, ro: &Readout, frames: u64, seed: u64) -> u64 {
    assert!(ro.double_buffer);
    let np = ro.pixels();
    let (n, c) = (p.frame_pulses, p.cycles_per_pulse as u64);
    let rom = rom(p, seed);
    let d = detections(p, np, frames * n, seed ^ 1);
    let r = run(&mut ArrayModel::new(ro, p, &rom, None).unwrap(), &d, frames).unwrap();
    let period = ro.frame_cycles();
    assert_eq!(period, (n * c + 1).max(ro.readout_cycles()));
    // Every pulse where the period puts it: pulse k of frame f leaves the sequencer at
    // f·period + k·C after reset and reaches the pixels BROADCAST_LATENCY later.
    for (i, &cy) in r.pulse_cycles.iter().enumerate() {
        let (f, k) = (i as u64 / n, i as u64 % n);
        assert_eq!(
            cy,
            RESET_CYCLES + f * period + k * c + BROADCAST_LATENCY,
            "pulse {i}"
        );
    }
    assert!(r.pulse_cycles.len() as u64 >= frames * n);
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
        .filter(|&cy| r.pins[cy as usize].ro_valid)
        .collect();
    assert_eq!(seen, expected);
    // The overlap: frame f + 1's pulses are presented while frame f's words stream.
    for f in 0..frames - 1 {
        let (first, last) = (
            r.beat_cycle(f, 0, 0, 0),
            r.beat_cycle(f, np - 1, ro.registers, ro.beats_per_word - 1),
        );
        let during = r.pulse_cycles[((f + 1) * n) as usize..((f + 2) * n) as usize]
            .iter()
            .filter(|&&cy| cy > first && cy < last)
            .count();
        assert!(during > 0, "frame {f}: no pulse during its readout");
    }
    // Each pixel's stream is its own reference's, status 0: every pulse accepted.
    for (q, (row, col)) in ro.order_iter().enumerate() {
        let alone = pixel_alone(p, &rom, &d[row * ro.cols + col], frames);
        for (f, words) in alone.iter().enumerate() {
            assert_eq!(&r.words[f][q], words, "pixel ({row}, {col}) frame {f}");
            assert_eq!(r.words[f][q][ro.registers], 0, "nothing refused");
        }
    }
    assert!(r.words.iter().flatten().flatten().any(|&w| w != 0));
    period
}

/// Accumulation-bound (2 × 2, N = 8, C = 4: N·C + 1 = 33 > D = 29): a frame is 33 cycles
/// instead of 32 + 29 = 61; readout-bound (2 × 3, N = 4: D = 43 > 17): 43 instead of 59.
#[test]
fn the_shadow_streams_each_pixel_s_own_words_while_the_next_frame_accumulates() {
    let p = fourier(8);
    let ro = double(readout(&p, 2, 2, None, None));
    assert_eq!((ro.readout_cycles(), check(&p, &ro, 3, 21)), (29, 33));
    let p = fourier(4);
    let ro = double(readout(&p, 2, 3, None, None));
    assert_eq!((ro.readout_cycles(), check(&p, &ro, 3, 22)), (43, 43));
    // A slow, narrow link (k = 3, g = 3): D = 6 pixels · 7 words · 3 · 3 + 1 = 379 cycles.
    let ro = double(readout(&p, 2, 3, Some(10), Some(15e6)));
    assert_eq!(check(&p, &ro, 2, 23), 379);
}

/// Haar (its pulse count restarts at the swap) on a 5-bit port, C = 4 > its 3 slots.
#[test]
fn a_double_buffered_haar_array_restarts_its_count_at_the_swap() {
    let mut p = haar(8);
    p.cycles_per_pulse = 4;
    p.validate().unwrap();
    let ro = double(readout(&p, 3, 5, Some(5), None));
    check(&p, &ro, 2, 24);
}

/// The swap strobe a cycle late (`ArrayFault::SwapLate`): pixel (0, 0)'s readout, which
/// starts with the swap, reads the shadow before it is loaded — the first differing cycle
/// is frame 0's first beat, pixel (0, 0) register 0 (the right one holds a non-zero word);
/// and `SwapLate` is refused on a single-buffered array.
#[test]
fn the_shadow_taken_a_cycle_late_is_caught_at_the_first_beat() {
    let p = fourier(8);
    let ro = double(readout(&p, 2, 2, None, None));
    let rom = rom(&p, 5);
    let d = detections(&p, 4, 24, 6);
    let good = run(&mut ArrayModel::new(&ro, &p, &rom, None).unwrap(), &d, 3).unwrap();
    let late = Some(ArrayFault::SwapLate);
    let bad = run(&mut ArrayModel::new(&ro, &p, &rom, late).unwrap(), &d, 3).unwrap();
    assert_ne!(
        good.words[0][0][0], 0,
        "register 0 of pixel (0, 0) is not 0"
    );
    let first = (0..good.pins.len())
        .find(|&cy| good.pins[cy] != bad.pins[cy])
        .expect("a late swap changes the stream") as u64;
    assert_eq!(first, good.beat_cycle(0, 0, 0, 0));
    let what = good.explain(first);
    assert!(
        what.contains("frame 0's readout, pixel (0, 0)") && what.contains("register 0"),
        "{what}"
    );
    let single = readout(&p, 2, 2, None, None);
    let e = ArrayModel::new(&single, &p, &rom, late).unwrap_err();
    assert!(e.to_string().contains("array.double_buffer"), "{e}");
}
