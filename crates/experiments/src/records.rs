//! Photon records as the float levels see them: TDC codes → depths (mm) → the one float
//! front end's hold (`tofprobe_dsp::preprocess::FrontEnd`: the last detection, 0 before the
//! first one, as the pixel accumulates nothing before it primes).

use tofprobe_dsp::preprocess::{FrontEnd, FrontEndOutput};
use tofprobe_scene::PhotonSource;

use crate::ExperimentError;

/// The TDC codes of `n` pulses, `None` for a missed pulse.
pub fn detection_record(source: &PhotonSource, n: u64) -> Vec<Option<u32>> {
    let mut codes = vec![None; usize::try_from(n).unwrap_or(usize::MAX)];
    source.fill_counted(0, &mut codes);
    codes
}

/// The held depth record (mm, minus `zoom_mm`) of `codes` through the one float front end.
pub fn held_record(
    source: &PhotonSource,
    codes: &[Option<u32>],
    zoom_mm: f64,
) -> Result<Vec<f64>, ExperimentError> {
    let mut fe = FrontEnd::new(zoom_mm, FrontEndOutput::Held)?;
    Ok(codes
        .iter()
        .map(|c| fe.step(c.map(|c| source.code_to_depth_mm(c))))
        .collect())
}
