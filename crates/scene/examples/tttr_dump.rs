//! Decodes a time-tagged file (PTU or SPC) and prints one JSON object: the summary, the
//! first photons/syncs as decoded, the decode speed, and a replay's counts through a TDC.
//! `scripts/tttr-crosscheck.sh` compares this with `ptufile`.
//!
//! Usage: `cargo run --release -p tofprobe-scene --example tttr_dump -- FILE [FIRST]
//! [LSB_PS WINDOW_START_PS WINDOW_LENGTH_PS]` (defaults: 10 events; 8 ps LSB over 0..50 ns,
//! an SPC file's ADC bin taken as 50 ns / 4096).

use std::path::Path;
use std::time::Instant;

use tofprobe_scene::tttr::{self, Event, PulseStream, ReplayOptions, TdcWindow};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(file) = args.first() else {
        return Err(
            "usage: tttr_dump FILE [FIRST] [LSB_PS WINDOW_START_PS WINDOW_LENGTH_PS]".into(),
        );
    };
    let path = Path::new(file);
    let first: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(10);
    let num = |i: usize, d: f64| -> Result<f64, Box<dyn std::error::Error>> {
        Ok(args.get(i).map(|s| s.parse()).transpose()?.unwrap_or(d))
    };
    let window = TdcWindow {
        tdc_lsb_ps: num(2, 8.0)?,
        window_start_ps: num(3, 0.0)?,
        window_length_ps: num(4, 50_000.0)?,
    };

    let t0 = Instant::now();
    let mut reader = tttr::open(path)?;
    let mut events = Vec::new();
    while let Some(ev) = reader.next_event()? {
        if events.len() < first && !matches!(ev, Event::Overflow { .. }) {
            events.push(ev);
        }
    }
    let secs = t0.elapsed().as_secs_f64();
    let summary = reader.summary();

    let mut options = ReplayOptions::new(window);
    if summary.resolution_s.is_none() {
        options.resolution_s = Some(50e-9 / 4096.0);
    }
    let t1 = Instant::now();
    let replay = match PulseStream::new(tttr::open(path)?, &options) {
        Ok(mut stream) => match stream.for_each_chunk(1 << 16, |_, _| {}) {
            Ok(_) => serde_json::to_value(stream.counts())?,
            Err(e) => serde_json::json!({ "error": e.to_string() }),
        },
        Err(e) => serde_json::json!({ "error": e.to_string() }),
    };
    let replay_secs = t1.elapsed().as_secs_f64();
    let records = summary.counts.records as f64;
    let out = serde_json::json!({
        "summary": summary,
        "first_events": events,
        "decode_s": secs,
        "decode_records_per_s": records / secs.max(1e-9),
        "replay": replay,
        "replay_s": replay_secs,
        "replay_records_per_s": records / replay_secs.max(1e-9),
        "window": window,
    });
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}
