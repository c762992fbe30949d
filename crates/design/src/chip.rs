//! The chip: what a sensor's pixels share, gathered in one notion — the array's shape, the
//! probe ROM broadcast to every pixel (chosen by the ROM policy, [`crate::rom_policy`]) and
//! the pulse sequencer that strobes them (the contract's reference sequencer, or the
//! directed one) — which `templates/top.v` wires to the pixel. A configuration's single
//! pixel is the 1 × 1 array, not a path of its own: the RTL commands build a [`Chip`] from a
//! resolved design and render, replay or co-simulate it, and the array RTL grows the same
//! notion to R × C pixels and a readout.

use tofprobe_pixel::{DirectedOptions, PixelParams};

use crate::error::DesignError;
use crate::readout::{Readout, resolve_readout};
use crate::resolve::ResolvedDesign;
use crate::rom_policy::{RtlOverrides, RtlRom, chip_rom, rtl_params, rtl_rom, simulation_rom};

/// Which ROM a chip carries: what the purpose of the RTL asks of the ROM policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RomPurpose {
    /// The ROM `tofprobe rtl` renders into the chip (a sign probe beyond the depth a chip
    /// would store: [`crate::rom_policy::chip_rom`]).
    Rendered,
    /// The ROM the simulating commands replay (`vectors`, `cosim` without `--rtl`: the
    /// sign probe only when `--rom-depth` asks: [`crate::rom_policy::simulation_rom`]).
    Replayed,
    /// The configuration's ΣΔ ROM whenever it can exist for the frame (the main flow:
    /// [`crate::rom_policy::rtl_rom`]).
    Configured,
}

/// The pulse sequencer of the chip's top.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SequencerKind {
    /// The contract's reference sequencer: N pulses one every C cycles, then the readout.
    #[default]
    Reference,
    /// The contract's directed sequencer (the refusal paths the reference never takes).
    Directed(DirectedOptions),
}

/// One chip: its array of pixels (all alike), their parameters for the frame simulated, the
/// probe ROM broadcast to them and the sequencer that strobes them.
#[derive(Debug, Clone)]
pub struct Chip {
    /// Rows of pixels (1: a configuration without an array).
    pub rows: usize,
    /// Columns of pixels.
    pub cols: usize,
    /// Every pixel's parameters (N and L as simulated; L is the ROM's depth).
    pub pixel: PixelParams,
    /// The probe ROM and the note on which it is.
    pub rom: RtlRom,
    /// The top's sequencer.
    pub sequencer: SequencerKind,
    /// The array's readout ([`crate::readout`]); `None` for the single pixel's top.
    pub readout: Option<Readout>,
    /// G: each pixel a superpixel of G × G SPADs (`[array] superpixel`; 1: one SPAD).
    pub superpixel: usize,
}

impl Chip {
    /// The chip of `design` with the RTL commands' overrides `o`, its ROM chosen for
    /// `purpose`, with the reference sequencer.
    pub fn of(
        design: &ResolvedDesign,
        o: &RtlOverrides,
        purpose: RomPurpose,
    ) -> Result<Chip, DesignError> {
        let mut pixel = rtl_params(design, o)?;
        let rom = match purpose {
            RomPurpose::Rendered => chip_rom(design, o, &mut pixel)?,
            RomPurpose::Replayed => simulation_rom(design, o, &mut pixel)?,
            RomPurpose::Configured => rtl_rom(design, &mut pixel)?,
        };
        Ok(Chip {
            rows: 1,
            cols: 1,
            pixel,
            rom,
            sequencer: SequencerKind::Reference,
            readout: None,
            superpixel: 1,
        })
    }

    /// The array chip of `design` (its `[array]`'s R × C pixels and readout, resolved for
    /// the pixel as simulated: N and L after the overrides `o`), the ROM chosen for
    /// `purpose`. Refused for a design without `[array]`.
    pub fn array_of(
        design: &ResolvedDesign,
        o: &RtlOverrides,
        purpose: RomPurpose,
    ) -> Result<Chip, DesignError> {
        let Some(a) = &design.array else {
            return Err(DesignError::array(
                &design.origin,
                "the array RTL needs an [array] section (array.rows, array.cols, array.pitch_um \
                 and the mapping); without it the chip is the one pixel's `tofprobe_top`",
            ));
        };
        let mut chip = Chip::of(design, o, purpose)?;
        chip.rows = a.rows;
        chip.cols = a.cols;
        chip.superpixel = a.superpixel;
        chip.readout = Some(resolve_readout(
            &a.readout,
            a.rows,
            a.cols,
            &chip.pixel,
            design.sensor().laser_rate_hz,
            &design.origin,
        )?);
        Ok(chip)
    }

    /// The array's shape and readout as the generator renders them (`None` for the single
    /// pixel's top), with an optional deliberate fault and tile (the part rendered).
    pub fn array_spec(
        &self,
        fault: Option<tofprobe_rtlgen::ArrayFault>,
        tile: Option<tofprobe_rtlgen::array::ArrayTile>,
    ) -> Option<tofprobe_rtlgen::ArraySpec> {
        self.readout.map(|r| tofprobe_rtlgen::ArraySpec {
            rows: r.rows,
            cols: r.cols,
            bits: r.bits,
            beats_per_word: r.beats_per_word,
            beat_cycles: r.beat_cycles,
            slot_cycles: r.slot_cycles(),
            fault,
            tile,
            superpixel: self.superpixel as u32,
            double_buffer: r.double_buffer,
        })
    }

    /// The same chip with the directed sequencer.
    pub fn directed(mut self, d: DirectedOptions) -> Chip {
        self.sequencer = SequencerKind::Directed(d);
        self
    }

    /// Pixels on the chip.
    pub fn pixels(&self) -> usize {
        self.rows * self.cols
    }

    /// The directed sequencer's options, if the top has it.
    pub fn directed_options(&self) -> Option<DirectedOptions> {
        match self.sequencer {
            SequencerKind::Reference => None,
            SequencerKind::Directed(d) => Some(d),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default configuration's chip is the 1 × 1 array of its pixel with the
    /// configuration's periodic ΣΔ ROM (20,000 deep) for every purpose at the full frame,
    /// and the sign probe when `--rom-depth` forces it.
    #[test]
    fn the_default_is_the_one_by_one_array_with_its_probe_rom() {
        let d = crate::load(None).unwrap();
        for purpose in [
            RomPurpose::Rendered,
            RomPurpose::Replayed,
            RomPurpose::Configured,
        ] {
            let c = Chip::of(&d, &RtlOverrides::default(), purpose).unwrap();
            assert_eq!((c.rows, c.cols, c.pixels()), (1, 1, 1));
            assert_eq!(c.pixel.rom_depth, 20_000, "{purpose:?}");
            assert!(c.rom.sd.is_some(), "{purpose:?}: {}", c.rom.note);
            assert_eq!(c.sequencer, SequencerKind::Reference);
        }
        let o = RtlOverrides {
            frame_pulses: Some(64),
            rom_depth: Some(8),
        };
        let c = Chip::of(&d, &o, RomPurpose::Replayed).unwrap();
        assert!(c.rom.sd.is_none() && c.rom.note.contains("sign-of-cosine"));
        assert_eq!(c.pixel.rom_depth, 8);
    }
}
