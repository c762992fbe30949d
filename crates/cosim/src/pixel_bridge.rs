//! The bridge to the pixel crate: its `PixelParams` converted to the generator's, and its
//! cycle-accurate model run through its own sequencer and compared, cycle by cycle, with
//! the generator's reference model; and [`PixelJudge`], the pixel crate's `CycleModel` as
//! the model the golden vectors are recorded from ([`golden_run`]).

use tofprobe_dsp::rom::RomImage;
use tofprobe_rtlgen::golden::{Golden, StepModel, pack_pins};
use tofprobe_rtlgen::model::{CycleModel as RefModel, PinsIn as RefPins};
use tofprobe_rtlgen::params::{Mode, PixelParams};
use tofprobe_rtlgen::sequencer::Sequencer as RefSequencer;
use tofprobe_rtlgen::vectors::{VectorOptions, golden_run_with};

/// The pixel crate's cycle-accurate model driven by the generator's sequencer pins: the
/// ROM word of `rom_addr` is looked up in the image, as the chip's ROM does (the pins of
/// both sequencers are checked equal cycle by cycle in `compare_models`).
#[derive(Debug, Clone)]
pub struct PixelJudge {
    model: tofprobe_pixel::CycleModel,
    rom: Vec<u64>,
    words: usize,
    writes: Vec<(u32, u64)>,
}

impl PixelJudge {
    /// The judge for `p` with the ROM image `rom` (L × ceil(R/64) words; empty for Haar).
    pub fn new(p: &PixelParams, rom: &[u64]) -> Result<Self, String> {
        Ok(PixelJudge {
            model: tofprobe_pixel::CycleModel::new(&to_pixel(p)).map_err(|e| e.to_string())?,
            rom: rom.to_vec(),
            words: p.registers().div_ceil(64),
            writes: Vec::with_capacity(p.registers()),
        })
    }
}

impl StepModel for PixelJudge {
    fn step(&mut self, i: &RefPins) -> tofprobe_rtlgen::PinsOut {
        let a = i.rom_addr * self.words;
        let word = if i.pulse {
            self.rom.get(a..a + self.words).unwrap_or(&[])
        } else {
            &[]
        };
        let o = self.model.step(&tofprobe_pixel::PinsIn {
            rst: i.rst,
            pulse: i.pulse,
            valid: i.valid,
            tdc: i.tdc,
            rom_word: word,
            readout: i.readout,
        });
        self.writes.clear();
        self.writes
            .extend(self.model.writes().iter().map(|w| (w.register, w.value)));
        tofprobe_rtlgen::PinsOut {
            ready: o.ready,
            rd_valid: o.rd_valid,
            rd_index: o.rd_index,
            rd_data: o.rd_data,
        }
    }
    fn writes(&self) -> &[(u32, u64)] {
        &self.writes
    }
}

/// The golden vectors' data recorded from the pixel crate's `CycleModel` (the judge), with
/// the effective trace window; an error when the pixel crate rejects the parameters.
pub fn golden_run(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    o: &VectorOptions,
) -> Result<(Golden, (u64, u64)), String> {
    Ok(golden_run_with(PixelJudge::new(p, rom)?, p, stim, o))
}

/// The generator's parameters for a pixel-crate configuration (same fields, same meaning).
pub fn from_pixel(p: &tofprobe_pixel::PixelParams) -> PixelParams {
    PixelParams {
        mode: match p.mode {
            tofprobe_pixel::Mode::Fourier => Mode::Fourier,
            tofprobe_pixel::Mode::Haar => Mode::Haar,
        },
        bins: p.bins,
        haar_scales: p.haar_scales,
        adders: p.adders,
        cycles_per_pulse: p.cycles_per_pulse,
        tdc_bits: p.tdc_bits,
        zoom: p.zoom,
        shift: p.shift,
        frac_bits: p.frac_bits,
        width: p.width,
        frame_pulses: p.frame_pulses,
        rom_depth: p.rom_depth,
        module_prefix: "tofprobe".to_string(),
    }
}

/// The pixel crate's parameters for a generator configuration.
pub fn to_pixel(p: &PixelParams) -> tofprobe_pixel::PixelParams {
    tofprobe_pixel::PixelParams {
        mode: match p.mode {
            Mode::Fourier => tofprobe_pixel::Mode::Fourier,
            Mode::Haar => tofprobe_pixel::Mode::Haar,
        },
        bins: p.bins,
        haar_scales: p.haar_scales,
        adders: p.adders,
        cycles_per_pulse: p.cycles_per_pulse,
        tdc_bits: p.tdc_bits,
        zoom: p.zoom,
        shift: p.shift,
        frac_bits: p.frac_bits,
        width: p.width,
        frame_pulses: p.frame_pulses,
        rom_depth: p.rom_depth,
    }
}

/// The first cycle where the pixel crate's `CycleModel` and the generator's reference
/// model differ (pins seen before the edge, or the edge's register writes), as
/// (cycle, what, pixel crate's value, reference value); `None` when they agree on every
/// cycle of `frames` frames. Runs the contract's sequence without its trailing cycle.
pub fn compare_models(
    p: &PixelParams,
    stim: &[Option<u32>],
    rom: &[u64],
    frames: u64,
) -> Result<Option<(u64, String, String, String)>, String> {
    let pp = to_pixel(p);
    let words = p.registers().div_ceil(64);
    let image = RomImage::from_fn(p.rom_depth, p.registers(), |a, r| {
        rom.get(a * words + r / 64)
            .is_some_and(|w| (w >> (r % 64)) & 1 == 1)
    });
    let pulses = (frames * p.frame_pulses) as usize;
    let stim = &stim[..pulses];
    let seq = tofprobe_pixel::Sequencer::new(&pp, stim, Some(&image)).map_err(|e| e.to_string())?;
    let mut theirs = tofprobe_pixel::CycleModel::new(&pp).map_err(|e| e.to_string())?;
    let mut ours = RefModel::new(p, rom, None);
    let mut refseq = RefSequencer::new(p, stim, frames);
    let total = seq.total_cycles();
    for c in 0..total {
        let pin = seq.pins(c);
        let rs = refseq.next().ok_or("reference sequencer ended early")?;
        let mine: RefPins = rs.pins;
        if (pin.rst, pin.pulse, pin.valid, pin.tdc, pin.readout)
            != (mine.rst, mine.pulse, mine.valid, mine.tdc, mine.readout)
        {
            return Ok(Some((
                c,
                "sequencer pins".into(),
                format!("{pin:?}"),
                format!("{mine:?}"),
            )));
        }
        let a = theirs.step(&pin);
        let b = ours.step(&mine);
        let (pa, pb) = (
            (pack_pins(&tofprobe_rtlgen::PinsOut {
                ready: a.ready,
                rd_valid: a.rd_valid,
                rd_index: a.rd_index,
                rd_data: a.rd_data,
            })),
            pack_pins(&b),
        );
        if c >= 1 && (pa != pb || a.rd_data != b.rd_data) {
            return Ok(Some((c, "pins".into(), format!("{a:?}"), format!("{b:?}"))));
        }
        let wa: Vec<(u32, u64)> = theirs
            .writes()
            .iter()
            .map(|w| (w.register, w.value))
            .collect();
        if wa != ours.writes() {
            return Ok(Some((
                c,
                "writes".into(),
                format!("{wa:x?}"),
                format!("{:x?}", ours.writes()),
            )));
        }
    }
    Ok(None)
}
