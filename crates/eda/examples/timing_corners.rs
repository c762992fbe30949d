//! Times a generated pixel on osu018 and on every sky130 corner at a clock, as the size
//! report does (delay-driven ABC on the typical corner, one netlist timed per corner), and
//! prints one JSON object: `cargo run --release -p tofprobe-eda --example timing_corners
//! -- RTL_DIR [CLOCK_MHZ] [LASER_HZ] [CACHE]`. The "before pipeline" figures of the
//! committed rtl/ and testbench/default-short/rtl/ come from it.

use std::path::{Path, PathBuf};
use tofprobe_eda::analysis::{RtlProvider, RtlVariant, analyse_point};
use tofprobe_eda::corners::{CornerTiming, sky130_corners};
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::signoff::{OSU018_LIBERTY, module_file};

struct Fixed(PathBuf);

impl RtlProvider for Fixed {
    fn rtl(&self, _: u64, _: u32, _: &Path) -> tofprobe_eda::Result<RtlVariant> {
        Ok(RtlVariant {
            sources: vec![self.0.clone()],
            top: "tofprobe_pixel".into(),
            params: vec![],
        })
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let rtl = PathBuf::from(
        args.get(1)
            .ok_or("usage: timing_corners RTL_DIR [CLOCK_MHZ] [LASER_HZ] [CACHE]")?,
    );
    let clock_mhz: f64 = args.get(2).map_or(Ok(160.0), |s| s.parse())?;
    let laser_hz: f64 = args.get(3).map_or(Ok(10e6), |s| s.parse())?;
    let cache = args.get(4).map_or_else(
        || std::env::temp_dir().join("tofprobe-timing-corners"),
        PathBuf::from,
    );
    let provider = Fixed(module_file(&rtl, "tofprobe_pixel")?);
    let target_ps = 1e6 / clock_mhz;
    let mut rows: Vec<(CornerTiming, f64, u64)> = Vec::new();
    let osu = Liberty::load(Path::new(OSU018_LIBERTY))?;
    let p = analyse_point(&provider, 0, 0, &osu, true, "clk", &cache, Some(target_ps))?;
    let t = p.timing.as_ref().ok_or("osu018 has timing")?;
    rows.push((
        CornerTiming::new(&osu.name, "typical", &osu.path, t, clock_mhz, laser_hz),
        p.synthesis.total_area_um2,
        p.synthesis.cell_count,
    ));
    if let Some(pdk) = Sky130Pdk::discover(None)? {
        let sky = Liberty::load(&pdk.typical(&cache)?)?;
        let p = analyse_point(&provider, 0, 0, &sky, true, "clk", &cache, Some(target_ps))?;
        for c in sky130_corners(
            &pdk,
            &p.synthesis,
            p.timing.as_ref(),
            "clk",
            &cache,
            clock_mhz,
            laser_hz,
        )? {
            rows.push((c, p.synthesis.total_area_um2, p.synthesis.cell_count));
        }
    }
    let json: Vec<serde_json::Value> = rows
        .iter()
        .map(|(c, area, cells)| {
            let mut v = serde_json::to_value(c).unwrap_or_default();
            v["total_area_um2"] = (*area).into();
            v["cell_count"] = (*cells).into();
            v
        })
        .collect();
    println!(
        "{}",
        serde_json::json!({ "rtl": rtl, "timing_corners": json })
    );
    Ok(())
}
