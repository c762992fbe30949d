//! `tofprobe cosim` on an `[array]` design (docs/pixel-contract.md "Array"): co-simulated
//! at its ports (`tofprobe_flow::array::cosim_array`). `tofprobe rtl` renders the array in
//! `rtl.rs`; `tofprobe flow` calls `tofprobe_flow::array::run_array_flow` from its own
//! file. Printing only.

use tofprobe_design::ResolvedDesign;
use tofprobe_flow::array::{ArrayCosimOptions, ArraySimulator, cosim_array};

use super::{CosimArgs, SimulatorArg};
use crate::error::CliError;

/// `tofprobe cosim` on an array design.
pub fn cosim(a: &CosimArgs, design: &ResolvedDesign) -> Result<crate::commands::Verdict, CliError> {
    // Every option either works on an array or is refused by name: none is ignored.
    let pixel_only = [
        ("directed", a.directed, "the pixel's directed sequencer"),
        ("coverage", a.coverage, "the pixel module's line coverage"),
        ("trace", a.trace, "the pixel's VCD"),
        ("bare", a.bare, "the pixel's bare-model timing"),
        (
            "seed",
            a.seed.is_some(),
            "the pixel's random stimulus (an array's detections come from its scene: set \
             `[acquisition] seed` in the configuration)",
        ),
    ];
    if let Some((name, _, what)) = pixel_only.iter().find(|(_, given, _)| *given) {
        return Err(CliError::option(name, "given", format!("{what} only")));
    }
    let mut o = ArrayCosimOptions::new(&a.out);
    o.frame_pulses = a.frame_pulses;
    o.rom_depth = a.rom_depth;
    o.frames = a.frames;
    o.rtl = a.rtl.clone();
    o.lead_misses = a.lead_misses;
    if let Some(x) = a.x_seed {
        o.x_seeds = vec![x];
    }
    o.simulator = match a.simulator {
        SimulatorArg::Verilator => ArraySimulator::Verilator,
        SimulatorArg::Icarus => ArraySimulator::Icarus,
    };
    o.command = "tofprobe cosim".into();
    o.tile = crate::commands::tile_arg::tile_for(design, a.tile.as_deref())?;
    let r = cosim_array(design, &o)?;
    let ro = &r.readout;
    if a.json {
        let j = serde_json::json!({
            "pass": r.pass,
            "rows": ro.rows,
            "cols": ro.cols,
            "frames": a.frames,
            "frame_pulses": ro.frame_pulses,
            "cycles": r.cycles,
            "mismatches": r.mismatches,
            "first_mismatch": r.first,
            "readout_cycles": ro.readout_cycles(),
            "beats_per_frame": ro.beats_per_frame(),
            "first_frame": r.first_frame,
            "x_seed": r.x_seed,
            "edited_rtl": a.rtl.is_some(),
            "build_seconds": r.build_seconds,
            "build_reused": r.reused,
            "verilator_layout": r.layout.map(|l| l.name()),
            "simulator_seconds": r.sim_seconds,
            "model_seconds": r.model_seconds,
        });
        println!("{j}");
    } else {
        println!(
            "cosim {}: {} x {} array, N = {}, {} frame(s), {} cycles, {} mismatches; {} beats of {} bits per frame in {} readout cycles; build {:.1} s{}{}, simulator {:.2} s, model {:.2} s{}",
            if r.pass { "PASS" } else { "FAIL" },
            ro.rows,
            ro.cols,
            ro.frame_pulses,
            a.frames,
            r.cycles,
            r.mismatches,
            ro.beats_per_frame(),
            ro.bits,
            ro.readout_cycles(),
            r.build_seconds,
            if r.reused { " (cached)" } else { "" },
            r.layout
                .map(|l| format!(", {}", l.name()))
                .unwrap_or_default(),
            r.sim_seconds,
            r.model_seconds,
            r.first
                .as_ref()
                .map(|f| format!("; first mismatch: {f}"))
                .unwrap_or_default()
        );
    }
    let failure = r.first_frame.map(|k| {
        let m = r.first.clone().unwrap_or_default();
        (
            k,
            format!("first mismatch: {m}"),
            format!(
                "first mismatch: {m}\n{} mismatch(es) in the run",
                r.mismatches
            ),
        )
    });
    let failure = match (failure, r.pass) {
        (Some(f), _) => Some(f),
        (None, true) => None,
        (None, false) => {
            let m = format!(
                "{} mismatch(es), {} of {} cycles run",
                r.mismatches,
                r.cycles,
                r.run.cycles()
            );
            Some((a.frames - 1, m.clone(), m))
        }
    };
    let suite = tofprobe_cosim::junit::frames_suite(
        &super::junit_name(a),
        &tofprobe_rtlgen::config_hash(&r.pixel),
        r.build_seconds + r.sim_seconds + r.model_seconds,
        a.frames,
        failure,
    );
    super::write_junit(a, &[suite])?;
    Ok(crate::commands::Verdict::of(r.pass))
}
