//! Timing of the array's own paths (issue 27 point 5): the broadcast (the root's and the
//! rows' registered stages into every pixel's `pulse`, `rom_word` and `readout`) and the
//! readout (the pixels' `rd_*` through the row select, the column buses and the column
//! select into the readout buffer), timed by OpenSTA at the pixel clock C·f_laser.
//!
//! The pixel is synthesised once (the size report's netlist, cached); the array's top is
//! synthesised with the pixel and the probe ROM as black boxes, and OpenSTA links the two
//! netlists, so every pixel instance is the real gate-level pixel and every broadcast net
//! carries its real loads. An array of at most [`WHOLE_TIMING_MAX_PIXELS`] pixels is timed
//! whole; a larger one as two slices that keep the whole array's fan-outs and fan-ins:
//! a **row** (1 × C: a row stage drives C pixels, the column select picks one of C) and a
//! **column** (R × 1: the root drives R row stages, a column bus gathers R pixels).
//! The ROM's own read path (address register → ROM → root stage) is timed with the ROM
//! as a black box, i.e. not at all: the ROM is sized apart ([`crate::array::rom`]).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::analysis::analyse_point;
use crate::array::spec::{ArrayEdaSpec, ArraySlice};
use crate::corner_option::CornerOption;
use crate::corners::MARGIN_PERCENT;
use crate::error::{EdaError, Result};
use crate::fsutil::write_atomic;
use crate::generated::GeneratedPixel;
use crate::liberty::Liberty;
use crate::sta::{Timing, parse_report, run_script};
use crate::synth::{SynthSpec, synthesise};
use crate::tools::tail;
use tofprobe_rtlgen::{RenderOptions, render_array};

/// Largest array timed whole (8 × 8); beyond it, a row and a column slice.
pub const WHOLE_TIMING_MAX_PIXELS: usize = 64;

/// OpenSTA's probe period (ns): long enough that every path has positive slack; the
/// critical delay is period − slack (as [`crate::sta`]).
const PROBE_PERIOD_NS: f64 = 1000.0;

/// One kind of path of one timed netlist.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PathTiming {
    /// Minimum period for the path: arrival + setup (ns).
    pub delay_ns: f64,
    /// Slack at the pixel clock (ns).
    pub slack_ns: f64,
    /// Slack as a share of the period (%).
    pub slack_percent: f64,
    /// Slack ≥ [`MARGIN_PERCENT`] % of the period.
    pub meets_margin: bool,
    /// Start of the worst path.
    pub startpoint: String,
    /// End of the worst path.
    pub endpoint: String,
    /// The pixel's own part: its worst path from those inputs (broadcast, the inputs at the
    /// clock edge) or to those outputs (readout), the pixel timed alone (ns).
    pub pixel_part_ns: f64,
    /// The array's part: `delay_ns` − `pixel_part_ns` (the stage's clock-to-output, the
    /// fan-out and its buffers; or the buses, selects and the capture's setup).
    pub array_part_ns: f64,
}

impl PathTiming {
    fn of(t: &Timing, pixel: &Timing, clock_mhz: f64) -> Self {
        let period = 1e3 / clock_mhz;
        let slack = period - t.critical_path_ns;
        let pct = (slack / period * 1000.0).round() / 10.0;
        PathTiming {
            delay_ns: t.critical_path_ns,
            slack_ns: slack,
            slack_percent: pct,
            meets_margin: pct >= MARGIN_PERCENT,
            startpoint: t.startpoint.clone(),
            endpoint: t.endpoint.clone(),
            pixel_part_ns: pixel.critical_path_ns,
            array_part_ns: t.critical_path_ns - pixel.critical_path_ns,
        }
    }
}

/// OpenSTA on `script` (written to `tcl`), its output split at the `== NAME` markers the
/// script prints, each part parsed as a `report_checks` text.
fn run_sta(tcl: &Path, script: &str, parts: &[&str]) -> Result<Vec<Timing>> {
    write_atomic(tcl, script.as_bytes())?;
    let (_, log) = run_script(tcl)?;
    let mut found = Vec::new();
    for (i, name) in parts.iter().enumerate() {
        let marker = format!("== {name}");
        let start = log.find(&marker).ok_or_else(|| EdaError::Parse {
            tool: "sta",
            what: "a `== NAME` marker of the array's script (OpenSTA stopped before it)",
            tail: format!("{}: before `{marker}`:\n{}", tcl.display(), tail(&log, 15)),
        })? + marker.len();
        let end = parts
            .get(i + 1)
            .and_then(|n| log[start..].find(&format!("== {n}")))
            .map_or(log.len(), |e| start + e);
        found.push(parse_report(&log[start..end])?);
    }
    Ok(found)
}

/// The array's paths timed on one liberty.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ArrayTiming {
    /// What was timed: `whole R × C`, `row 1 × C` or `column R × 1`.
    pub netlist: String,
    /// Library name (`library (NAME)`).
    pub library: String,
    /// The pixel clock C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Cell area of the array's own logic (sequencer, broadcast, readout; the pixels and
    /// the ROM excluded), µm².
    pub shared_logic_um2: f64,
    /// Broadcast paths: into the pixels' `pulse`, `rom_word`, `readout`.
    pub broadcast: PathTiming,
    /// Readout paths: out of the pixels' `rd_valid`, `rd_index`, `rd_data`.
    pub readout: PathTiming,
}

/// The netlists to time for a `rows` × `cols` array: the whole (up to `whole_max` pixels),
/// or a row and a column.
pub fn slices(rows: usize, cols: usize, whole_max: usize) -> Vec<(String, usize, usize)> {
    if rows * cols <= whole_max {
        vec![(format!("whole {rows} × {cols}"), rows, cols)]
    } else {
        vec![
            (format!("row 1 × {cols}"), 1, cols),
            (format!("column {rows} × 1"), rows, 1),
        ]
    }
}

/// Times every netlist of `spec.slices` on each liberty of `liberties` (a timing liberty,
/// then sky130 corners: the top and the pixel mapped on the first of a pair, timed on the
/// second, see `time_on`).
pub fn array_timing(
    spec: &ArrayEdaSpec,
    liberties: &[(PathBuf, Option<PathBuf>)],
    cache: &Path,
) -> Result<Vec<ArrayTiming>> {
    let mut out = Vec::new();
    for (map_lib, time_lib) in liberties {
        for slice in &spec.slices {
            out.push(time_on(spec, slice, map_lib, time_lib.as_deref(), cache)?);
        }
    }
    Ok(out)
}

/// Times one netlist of the chip's array: mapped on `map_lib`, timed on `time_lib`
/// (default `map_lib`; another corner of the same cells).
fn time_on(
    spec: &ArrayEdaSpec,
    slice: &ArraySlice,
    map_lib: &Path,
    time_lib: Option<&Path>,
    cache: &Path,
) -> Result<ArrayTiming> {
    let p = &spec.pixel;
    let clock_mhz = spec.clock_mhz;
    let target_ps = 1e6 / clock_mhz;
    let lib = Liberty::load(map_lib)?;
    // The pixel: the size report's synthesis (same provider, point and target: cached).
    let pixel = analyse_point(
        &GeneratedPixel { base: p.clone() },
        p.bins as u64,
        p.width,
        &lib,
        false,
        "clk",
        cache,
        Some(target_ps),
    )?;
    // The array's top with the pixel and the ROM as black boxes.
    // The ROM's contents do not reach the top's logic (a black box): render a 1-entry one.
    let mut p1 = p.clone();
    p1.rom_depth = p.rom_depth.clamp(1, 2);
    let rom = vec![0u64; p1.rom_depth * p1.registers().div_ceil(64)];
    let files = render_array(&p1, &rom, &RenderOptions::default(), &slice.array)?;
    let (pixel_name, rom_name, _) =
        tofprobe_rtlgen::module_names(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX);
    let top = tofprobe_rtlgen::array::array_module_name(tofprobe_rtlgen::DEFAULT_MODULE_PREFIX);
    let mut text = String::new();
    for f in files.iter().filter(|f| f.name.ends_with(".v")) {
        if f.template == "pixel.v" {
            text +=
                &tofprobe_rtlgen::array::black_box(&f.contents, &pixel_name).unwrap_or_default();
        } else if f.template == "probe_rom.v" {
            text += &tofprobe_rtlgen::array::black_box(&f.contents, &rom_name).unwrap_or_default();
        } else {
            text += &f.contents;
        }
    }
    let key = format!("{:016x}", tofprobe_io::fnv1a64(text.as_bytes()));
    let dir = cache.join("array-top").join(&key);
    std::fs::create_dir_all(&dir).map_err(|e| EdaError::io("creating", &dir, e))?;
    let src = dir.join(format!("{top}.v"));
    write_atomic(&src, text.as_bytes())?;
    let top_syn = synthesise(
        &SynthSpec {
            sources: vec![src],
            top: top.clone(),
            params: vec![],
            liberty: map_lib.to_path_buf(),
            delay_target_ps: Some(target_ps),
            keep: vec![],
        },
        &cache.join("synth"),
    )?;
    // OpenSTA on the two netlists linked.
    let time_lib = time_lib.unwrap_or(map_lib);
    let script = format!(
        "read_liberty {lib}\nread_verilog {pixel}\nread_verilog {array}\nlink_design {top}\n\
         create_clock -name clk -period {PROBE_PERIOD_NS} [get_ports clk]\n\
         set_input_delay 0 -clock clk [delete_from_list [all_inputs] [get_ports clk]]\n\
         set_output_delay 0 -clock clk [all_outputs]\n\
         puts \"== broadcast\"\n\
         report_checks -path_delay max -digits 4 -through [get_pins {{*u_pixel/pulse *u_pixel/rom_word* *u_pixel/readout}}]\n\
         puts \"== readout\"\n\
         report_checks -path_delay max -digits 4 -through [get_pins {{*u_pixel/rd_valid *u_pixel/rd_index* *u_pixel/rd_data*}}]\n\
         exit\n",
        lib = time_lib.display(),
        pixel = pixel.synthesis.netlist_verilog.display(),
        array = top_syn.netlist_verilog.display(),
    );
    let stem = time_lib
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let linked = run_sta(
        &dir.join(format!("sta-{stem}.tcl")),
        &script,
        &["broadcast", "readout"],
    )?;
    // The pixel alone: its worst paths from the broadcast inputs and to the readout outputs.
    let alone = format!(
        "read_liberty {lib}\nread_verilog {pixel}\nlink_design {pixel_name}\n\
         create_clock -name clk -period {PROBE_PERIOD_NS} [get_ports clk]\n\
         set_input_delay 0 -clock clk [delete_from_list [all_inputs] [get_ports clk]]\n\
         set_output_delay 0 -clock clk [all_outputs]\n\
         puts \"== from\"\n\
         report_checks -path_delay max -digits 4 -from [get_ports {{pulse rom_word* readout}}]\n\
         puts \"== to\"\n\
         report_checks -path_delay max -digits 4 -to [get_ports {{rd_valid rd_index* rd_data*}}]\n\
         exit\n",
        lib = time_lib.display(),
        pixel = pixel.synthesis.netlist_verilog.display(),
    );
    let own = run_sta(
        &dir.join(format!("sta-pixel-{stem}.tcl")),
        &alone,
        &["from", "to"],
    )?;
    let time_name = Liberty::load(time_lib)?.name;
    Ok(ArrayTiming {
        netlist: slice.name.clone(),
        library: time_name,
        clock_mhz,
        shared_logic_um2: top_syn.total_area_um2,
        broadcast: PathTiming::of(&linked[0], &own[0], clock_mhz),
        readout: PathTiming::of(&linked[1], &own[1], clock_mhz),
    })
}

/// The broadcast and readout paths of one timed netlist at the clock of the option that
/// meets a corner the configured pixel misses (more adders, fewer cycles per pulse).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CornerOptionPaths {
    /// What was timed (as in `timing`).
    pub netlist: String,
    /// The corner's library.
    pub library: String,
    /// The option's adders A.
    pub adders: u64,
    /// Its clock C·f_laser (MHz).
    pub clock_mhz: f64,
    /// Broadcast slack at that clock, as a share of its period (%).
    pub broadcast_slack_percent: f64,
    /// Readout slack at that clock (%).
    pub readout_slack_percent: f64,
    /// Both keep the 10 % margin.
    pub meets_margin: bool,
}

/// The paths' delays do not depend on A (the array's logic and the pixel's port paths are
/// the same), so their slack at the option's clock follows from the delays measured.
pub fn corner_option_paths(
    timing: &[ArrayTiming],
    options: &[CornerOption],
) -> Vec<CornerOptionPaths> {
    let pct = |delay_ns: f64, clock_mhz: f64| {
        let period = 1e3 / clock_mhz;
        ((period - delay_ns) / period * 1000.0).round() / 10.0
    };
    let mut out = Vec::new();
    for o in options {
        let (Some(a), Some(t)) = (o.adders, o.trials.last()) else {
            continue;
        };
        for row in timing.iter().filter(|r| r.library == o.library) {
            let b = pct(row.broadcast.delay_ns, t.clock_mhz);
            let r = pct(row.readout.delay_ns, t.clock_mhz);
            out.push(CornerOptionPaths {
                netlist: row.netlist.clone(),
                library: row.library.clone(),
                adders: a,
                clock_mhz: t.clock_mhz,
                broadcast_slack_percent: b,
                readout_slack_percent: r,
                meets_margin: b >= MARGIN_PERCENT && r >= MARGIN_PERCENT,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_arrays_are_timed_whole_and_large_ones_by_a_row_and_a_column() {
        assert_eq!(slices(8, 8, WHOLE_TIMING_MAX_PIXELS).len(), 1);
        assert_eq!(slices(8, 8, 0).len(), 2);
        let s = slices(64, 64, WHOLE_TIMING_MAX_PIXELS);
        assert_eq!((s[0].1, s[0].2), (1, 64));
        assert_eq!((s[1].1, s[1].2), (64, 1));
    }

    #[test]
    fn paths_are_judged_again_at_a_corner_options_clock() {
        use crate::corner_option::CornerTrial;
        let path = |delay_ns: f64| PathTiming {
            delay_ns,
            slack_ns: 6.25 - delay_ns,
            slack_percent: 0.0,
            meets_margin: false,
            startpoint: String::new(),
            endpoint: String::new(),
            pixel_part_ns: 0.0,
            array_part_ns: delay_ns,
        };
        let row = |library: &str, b: f64, r: f64| ArrayTiming {
            netlist: "whole 2 × 2".into(),
            library: library.into(),
            clock_mhz: 160.0,
            shared_logic_um2: 0.0,
            broadcast: path(b),
            readout: path(r),
        };
        let option = |library: &str, adders: Option<u64>| CornerOption {
            library: library.into(),
            corner: "ss".into(),
            configured_f_max_mhz: 46.8,
            adders,
            cycles_per_pulse: adders.map(|_| 3),
            trials: vec![CornerTrial {
                adders: 11,
                cycles_per_pulse: 3,
                clock_mhz: 30.0,
                f_max_mhz: 44.9,
                slack_percent: 33.1,
                meets_margin: true,
            }],
            note: String::new(),
        };
        let timing = [row("ss", 10.0, 31.0), row("tt", 3.0, 3.0)];
        let got = corner_option_paths(&timing, &[option("ss", Some(11))]);
        // 30 MHz: a 33.33 ns period; 10 ns leaves 70.0 %, 31 ns 7.0 % (short of 10 %).
        assert_eq!(got.len(), 1, "only the ss row: {got:?}");
        assert_eq!(got[0].adders, 11);
        assert_eq!(got[0].broadcast_slack_percent, 70.0);
        assert_eq!(got[0].readout_slack_percent, 7.0);
        assert!(!got[0].meets_margin);
        // An option that found no A judges nothing.
        assert!(corner_option_paths(&timing, &[option("ss", None)]).is_empty());
    }
}
