//! One pixel's frame, in chunks a Ctrl-C can stop between (`long_call::run`): the photons
//! (`PhotonSource::par_fill`, chunk by chunk on the caller's pool: the same pulses as one
//! `record`, the source's draws not depending on where chunks start) and the registers
//! (`FrameDriver::run` fed chunk by chunk from the frame read in place, as the array feeds
//! it: the same registers as one call).

use pyo3::prelude::*;
use tofprobe_pixel::{FrameDriver, PixelError};
use tofprobe_scene::PhotonSource;

use crate::Design;
use crate::convert::CodeSlice;
use crate::errors;
use crate::long_call::{self, Progress};

/// Pulses per chunk of the photons (about 10–40 ms of work on two cores).
const SCENE_CHUNK: usize = 1 << 20;
/// Pulses per chunk of the pixel (one chunk for the default 10^7-pulse frame).
const PIXEL_CHUNK: usize = 1 << 24;

/// The frame's photons as `(valid, tdc)` (codes have at most 16 bits: u16 holds each).
pub fn scene(
    py: Python<'_>,
    source: &PhotonSource,
    n: u64,
    progress: &Progress<'_>,
    pool: Option<&rayon::ThreadPool>,
) -> PyResult<(Vec<bool>, Vec<u16>)> {
    let n = usize::try_from(n).map_err(errors::input_error)?;
    let (mut valid, mut tdc) = (vec![false; n], vec![0u16; n]);
    let (v, t) = (&mut valid, &mut tdc);
    long_call::run(py, progress, pool, move |watch| {
        let mut buf = vec![None; SCENE_CHUNK.min(n)];
        for (i, (vc, tc)) in v
            .chunks_mut(SCENE_CHUNK)
            .zip(t.chunks_mut(SCENE_CHUNK))
            .enumerate()
        {
            let k = vc.len();
            source.par_fill((i * SCENE_CHUNK) as u64, &mut buf[..k]);
            for ((d, vv), tt) in buf[..k].iter().zip(vc).zip(tc) {
                *vv = d.is_some();
                *tt = d.map_or(0, |c| c as u16);
            }
            if !watch.advance(k as u64) {
                return Err(());
            }
        }
        Ok(())
    })?
    .map_err(|()| errors::input("stopped"))?;
    Ok((valid, tdc))
}

/// The registers after the frame (`valid`, `tdc`), range-checked (the error names the
/// first out-of-range pulse of the whole frame).
pub fn pixel(d: &Design, py: Python<'_>, valid: &[bool], tdc: CodeSlice<'_>) -> PyResult<Vec<i64>> {
    let rom = d.rom(py)?.map(|r| &r.image);
    let params = &d.inner.pixel;
    let max_code = d.max_code();
    let progress = Progress::none(valid.len() as u64);
    long_call::run(py, &progress, None, |watch| {
        let mut driver = FrameDriver::new(params, rom).map_err(Some)?;
        let mut start = 0;
        while start < valid.len() {
            let end = (start + PIXEL_CHUNK).min(valid.len());
            if let Err(e) = tdc.range(start..end).run_pixel(
                &valid[start..end],
                start as u64,
                max_code,
                &mut driver,
            ) {
                // A code out of range is named against the whole frame, not the chunk.
                return Err(Some(tdc.scan(valid, max_code).err().unwrap_or(e)));
            }
            if !watch.advance((end - start) as u64) {
                return Err(None);
            }
            start = end;
        }
        Ok(driver.readout().words)
    })?
    .map_err(|e: Option<PixelError>| errors::input(e.map_or("stopped".into(), |e| e.to_string())))
}
