//! The array's RTL written: the chip rendered into one set with its FuseSoC core, and with
//! `tofprobe rtl`'s verification kit (the testbench and the golden vectors of
//! [`crate::array::vectors`] beside the RTL).

use std::path::Path;

use tofprobe_design::rom_policy::RtlOverrides;
use tofprobe_design::{Chip, ResolvedDesign, RomPurpose};
use tofprobe_rtlgen::ArrayFault;
use tofprobe_rtlgen::array::ArrayTile;
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::write::write_generated;

use crate::array::chip;
use crate::array::vectors::{ArrayStimulus, array_vector_files};
use crate::error::FlowError;

/// Renders the array chip into `out` (the RTL and its FuseSoC core, one set; with `kit`,
/// the set's verification kit too: the vector files of `vectors::array_vector_files` for this chip
/// beside the RTL, the testbench `tofprobe_rtlgen::kit` copies, and the core's simulation
/// targets); returns the file names.
pub fn render_array_to(
    chip: &Chip,
    out: &Path,
    command: String,
    fault: Option<ArrayFault>,
    tile: Option<ArrayTile>,
    kit: Option<Vec<(String, String)>>,
) -> Result<Vec<String>, FlowError> {
    let spec = chip
        .array_spec(fault, tile)
        .ok_or_else(|| FlowError::option("array", "none", "a chip with an [array] readout"))?;
    let options = RenderOptions {
        command,
        rom_note: chip.rom.note.clone(),
        ..RenderOptions::default()
    };
    let mut files = tofprobe_rtlgen::render_array(&chip.pixel, &chip.rom.words, &options, &spec)?;
    let core = tofprobe_rtlgen::core::render_array_core(
        &chip.pixel,
        &files,
        &options,
        chip.rows,
        chip.cols,
        kit.is_some(),
    )?;
    files.extend(core);
    if kit.is_some() {
        files.push(tofprobe_rtlgen::kit::render_kit_testbench(
            &chip.pixel,
            &options,
        ));
    }
    let mut pairs: Vec<(String, String)> =
        files.into_iter().map(|f| (f.name, f.contents)).collect();
    pairs.extend(kit.into_iter().flatten());
    write_generated(out, &pairs)?;
    Ok(pairs.into_iter().map(|(n, _)| n).collect())
}

/// What `tofprobe rtl` put in an array set besides the RTL: its verification kit's frames
/// and cycles, or why it has none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ArrayKit {
    /// The testbench and `frames` frames of golden vectors, `cycles` cycles.
    Written { frames: u64, cycles: u64 },
    /// No kit (`--kit-frames 0`, or more cycles than [`tofprobe_rtlgen::kit::KIT_MAX_CYCLES`]):
    /// the reason, naming the option that gives one.
    Omitted(String),
}

/// `tofprobe rtl` on an array design: the chip ROM policy's ROM, N and L as overridden; with
/// `kit_frames` > 0 the set carries its verification kit ([`render_array_to`]): the golden
/// vectors of `tofprobe vectors` for `kit_frames` frames (the same code path,
/// `vectors::array_vector_files`, on the ROM rendered into the set, as `tofprobe cosim --rtl`
/// replays), unless they would exceed `KIT_MAX_CYCLES` cycles.
pub fn render_array_design(
    design: &ResolvedDesign,
    o: &RtlOverrides,
    out: &Path,
    command: String,
    kit_frames: u64,
) -> Result<(Chip, Vec<String>, ArrayKit), FlowError> {
    let max = tofprobe_rtlgen::kit::KIT_MAX_CYCLES;
    if kit_frames > 100 {
        return Err(FlowError::option(
            "kit-frames",
            kit_frames,
            "0..=100 (0: no verification kit)",
        ));
    }
    let chip = chip(design, o, RomPurpose::Rendered)?;
    let ro = chip
        .readout
        .ok_or_else(|| FlowError::option("array", "none", "an [array] design"))?;
    // The run's length, bounded before the model runs: every frame and one readout more.
    let estimate = ro
        .frame_cycles()
        .saturating_mul(kit_frames)
        .saturating_add(ro.readout_cycles());
    let (kit, status) = if kit_frames == 0 {
        (
            None,
            ArrayKit::Omitted("--kit-frames 0: no verification kit".into()),
        )
    } else if estimate > max {
        (
            None,
            ArrayKit::Omitted(format!(
                "no verification kit: {kit_frames} frame(s) of N = {} replay about {estimate} cycles,                  over the kit's {max} (render with a shorter --frame-pulses or fewer --kit-frames,                  or re-verify with `tofprobe cosim --rtl`)",
                chip.pixel.frame_pulses
            )),
        )
    } else {
        let stimulus = ArrayStimulus {
            frames: kit_frames,
            detections: None,
            tile: None,
            lead_misses: 0,
            exercise: false,
            mid_frame_reset: false,
            purpose: RomPurpose::Rendered,
        };
        let (v, files) = array_vector_files(design, chip.clone(), stimulus, &command)?;
        let cycles = v.run.cycles();
        (
            Some(files),
            ArrayKit::Written {
                frames: kit_frames,
                cycles,
            },
        )
    };
    let files = render_array_to(&chip, out, command, None, None, kit)?;
    Ok((chip, files, status))
}
