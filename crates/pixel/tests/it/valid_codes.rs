//! A frame held as (`valid`, `tdc`) arrays ([`ValidCodes`], the form the Python package
//! hands over in place) against a naive decode: over random parameters, frames and every
//! integer dtype, the decoded pulses equal `valid[i] ∧ 0 ≤ tdc[i] ≤ max → Some(tdc[i])`, the
//! registers a driver reads from it equal the same driver's on that naive stream, and a
//! valid code out of range (negative, one past the largest, or huge) is refused naming the
//! first such pulse — while the same code at an invalid pulse is ignored.

use crate::common;

use common::{Rng, random_params, random_rom};
use tofprobe_pixel::{Detections, FrameDriver, Mode, NO_DETECTION, TdcCode, ValidCodes};

/// The naive decode: one pulse at a time, no masks.
fn naive<T: TdcCode>(valid: &[bool], tdc: &[T], max: u32) -> Vec<Option<u32>> {
    valid
        .iter()
        .zip(tdc)
        .map(|(&v, &c)| {
            let c: i128 = c.into();
            (v && (0..=i128::from(max)).contains(&c)).then_some(c as u32)
        })
        .collect()
}

/// Random (valid, tdc as i64) of `n` pulses with codes in 0 ..= max.
fn frame(rng: &mut Rng, n: usize, max: u32) -> (Vec<bool>, Vec<i64>) {
    let valid = (0..n).map(|_| rng.chance(40)).collect();
    let tdc = (0..n)
        .map(|_| i64::from(rng.below(u64::from(max) + 1) as u32))
        .collect();
    (valid, tdc)
}

/// Decode and drive in dtype `T` (codes that fit it), against the naive stream.
/// Whether the case ran (its codes fit `T`).
fn agrees<T: TdcCode + TryFrom<i64>>(seed: u64) -> bool {
    let mut rng = Rng(seed);
    let mut params = random_params(&mut rng);
    let max = (1u32 << params.tdc_bits) - 1;
    params.frame_pulses = 1 + rng.below(4000);
    if params.validate().is_err() {
        return false;
    }
    let rom = (params.mode == Mode::Fourier).then(|| random_rom(&mut rng, &params));
    let n = rng.below(params.frame_pulses + 1) as usize;
    let (valid, wide) = frame(&mut rng, n, max);
    let Ok(tdc) = wide
        .iter()
        .map(|&c| T::try_from(c))
        .collect::<Result<Vec<T>, _>>()
    else {
        return false; // codes wider than T: another dtype's case
    };
    let frame = ValidCodes::new(&valid, &tdc, max).expect("same lengths");
    let expected = naive(&valid, &tdc, max);
    assert_eq!(frame.options().unwrap(), expected, "seed {seed}: decode");
    let compact: Vec<u32> = expected.iter().map(|d| d.unwrap_or(NO_DETECTION)).collect();
    assert_eq!(frame.compact().unwrap(), compact, "seed {seed}: compact");
    for (i, &want) in expected.iter().enumerate().take(50) {
        assert_eq!(frame.get(i), want, "seed {seed}: pulse {i}");
    }
    let mut a = FrameDriver::new(&params, rom.as_ref()).unwrap();
    a.run(&frame, 0).unwrap();
    frame.check().expect("codes in range");
    let mut b = FrameDriver::new(&params, rom.as_ref()).unwrap();
    b.run(compact.as_slice(), 0).unwrap();
    assert_eq!(a.readout(), b.readout(), "seed {seed}: registers");
    true
}

#[test]
fn every_dtype_decodes_and_drives_like_the_naive_stream() {
    let mut ran = [0; 8];
    for seed in 0..60 {
        let cases = [
            agrees::<u8>(seed),
            agrees::<u16>(seed),
            agrees::<u32>(seed),
            agrees::<u64>(seed),
            agrees::<i8>(seed),
            agrees::<i16>(seed),
            agrees::<i32>(seed),
            agrees::<i64>(seed),
        ];
        for (n, ran_now) in ran.iter_mut().zip(cases) {
            *n += usize::from(ran_now);
        }
    }
    // Every dtype judged on several frames (narrow ones only where the codes fit).
    assert!(ran.iter().all(|&n| n >= 5), "cases run per dtype: {ran:?}");
}

#[test]
fn a_valid_code_out_of_range_is_refused_naming_the_first_pulse() {
    let max = 127; // T = 7
    let n = 1000;
    for bad in [-1i64, 128, 1 << 40, i64::MIN] {
        let mut valid = vec![true; n];
        let mut tdc = vec![5i64; n];
        // The same code at an invalid pulse first: ignored.
        valid[100] = false;
        tdc[100] = bad;
        tdc[600] = bad;
        tdc[900] = bad;
        let frame = ValidCodes::new(&valid, &tdc, max).unwrap();
        let e = frame.compact().unwrap_err().to_string();
        assert!(e.contains(&format!("`tdc[600]` = {bad}")), "{e}");
        assert!(e.contains("0 ..= 127 (pixel.tdc_bits = 7)"), "{e}");
        assert!(e.contains("valid[600] = False"), "{e}");
        // Read by a driver, the frame is refused after the run, at the same pulse.
        let params = tofprobe_pixel::PixelParams::default();
        let rom = (params.mode == Mode::Fourier).then(|| {
            let mut rng = Rng(1);
            random_rom(&mut rng, &params)
        });
        let frame = ValidCodes::new(&valid, &tdc, params_max(&params)).unwrap();
        let mut d = FrameDriver::new(&params, rom.as_ref()).unwrap();
        d.run(&frame, 0).unwrap();
        let e = frame.check().unwrap_err().to_string();
        assert!(e.contains("tdc[600]"), "{e}");
        // Without the bad codes the same frame passes.
        tdc[600] = 5;
        tdc[900] = 5;
        assert!(
            ValidCodes::new(&valid, &tdc, max)
                .unwrap()
                .compact()
                .is_ok()
        );
    }
    // Lengths that differ are refused before any pulse is read.
    let e = ValidCodes::new(&[true; 3], &[1u16; 2], max).unwrap_err();
    assert!(e.to_string().contains("one per pulse"), "{e}");
}

/// The largest code of the default pixel (its T pins).
fn params_max(p: &tofprobe_pixel::PixelParams) -> u32 {
    (1u32 << p.tdc_bits) - 1
}
