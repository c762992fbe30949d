//! `tofprobe simulate [CONFIG] [--json]`: run the photon/TDC Monte Carlo and summarise the
//! record (pulses, detections, background wins, mean and σ of the measured depth, run time).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use tofprobe_scene::{FillCounts, PhotonSource};

use crate::config::Config;
use crate::error::CliError;

/// Pulses per streamed chunk (a multiple of the source's block, so nothing is regenerated).
const CHUNK: usize = 1 << 18;

/// Arguments of `tofprobe simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML); without it the embedded default (paper Fig. 8) is used.
    config: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// The summary of one simulated record.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Pulses simulated.
    pub pulses: u64,
    /// Pulses with a detection.
    pub detections: u64,
    /// Detections won by a background photon.
    pub background_wins: u64,
    /// Detections / pulses.
    pub detection_rate: f64,
    /// Mean measured depth over detections (mm; code-bin centres), 0 without detections.
    pub mean_depth_mm: f64,
    /// Standard deviation of the measured depth (mm), 0 with fewer than two detections.
    pub sigma_depth_mm: f64,
    /// Wall-clock time of the simulation (s).
    pub seconds: f64,
}

/// Streams the record through a running sum; the progress bar appears on a terminal only
/// once the run has taken a second.
pub fn summarise(source: &PhotonSource, pulses: u64, progress: bool) -> Summary {
    let start = Instant::now();
    let bar = ProgressBar::with_draw_target(Some(pulses), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} pulses ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut shown = false;
    let mut counts = FillCounts::default();
    // Sums of code and code², exact in integers; depth is affine in the code.
    let (mut s1, mut s2) = (0u128, 0u128);
    let mut buf = vec![None; CHUNK];
    let mut first = 0u64;
    while first < pulses {
        let n = (pulses - first).min(CHUNK as u64) as usize;
        counts += source.fill_counted(first, &mut buf[..n]);
        for c in buf[..n].iter().flatten() {
            s1 += u128::from(*c);
            s2 += u128::from(*c) * u128::from(*c);
        }
        first += n as u64;
        if progress && !shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            shown = true;
        }
        bar.set_position(first);
    }
    bar.finish_and_clear();
    let d = counts.detections;
    let (mean_code, var_code) = if d == 0 {
        (0.0, 0.0)
    } else {
        let m = s1 as f64 / d as f64;
        let v = if d > 1 {
            // Integer form of the sum of squared deviations, then one division.
            let num = (d as u128 * s2 - s1 * s1) as f64;
            num / (d as f64 * (d - 1) as f64)
        } else {
            0.0
        };
        (m, v.max(0.0))
    };
    let lsb_mm = source.code_to_depth_mm(1) - source.code_to_depth_mm(0);
    Summary {
        pulses,
        detections: d,
        background_wins: counts.background_wins,
        detection_rate: d as f64 / pulses.max(1) as f64,
        mean_depth_mm: if d == 0 {
            0.0
        } else {
            source.code_to_depth_mm(0) + mean_code * lsb_mm
        },
        sigma_depth_mm: var_code.sqrt() * lsb_mm,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let loaded = Config::load(args.config.as_deref())?;
    let source = loaded.config.photon_source().map_err(|e| loaded.error(e))?;
    let pulses = loaded.config.pulses();
    let progress = !args.json && std::io::stderr().is_terminal();
    let s = summarise(&source, pulses, progress);
    if args.json {
        println!("{}", serde_json::to_string(&s)?);
    } else {
        println!("configuration      {}", loaded.origin);
        println!("pulses             {}", s.pulses);
        println!(
            "detections         {} ({:.4} per pulse)",
            s.detections, s.detection_rate
        );
        println!("background wins    {}", s.background_wins);
        println!("mean depth         {:.4} mm", s.mean_depth_mm);
        println!("sigma depth        {:.4} mm", s.sigma_depth_mm);
        println!(
            "run time           {:.3} s ({:.1} M pulses/s)",
            s.seconds,
            s.pulses as f64 / s.seconds.max(1e-9) / 1e6
        );
    }
    Ok(())
}
