//! The one entry point for running frames at transaction level: [`FrameDriver`] picks the
//! segmented fold ([`crate::segments`]) for long frames of a fast prefilter
//! ([`segments_pay`]), else the folded driver ([`crate::fold`]) when [`fold_pays`] says it
//! does fewer adds, and the transaction driver ([`TransactionModel::run`], the naive
//! reference) otherwise (Haar, short frames, very deep ROMs). All read out bit-identical
//! registers, so a caller never sees which one ran except in the time it took.

use tofprobe_dsp::RomImage;

use crate::detections::{Detections, Window};
use crate::error::PixelError;
use crate::fold::{FoldModel, fold_pays};
use crate::params::PixelParams;
use crate::readout::Readout;
use crate::segments::{SegmentedModel, segments_pay};
use crate::transaction::{TransactionModel, frame_len};

/// A transaction-level pixel run by the driver that pays for its parameters.
#[derive(Debug, Clone)]
pub enum FrameDriver<'rom> {
    /// The segmented fold (a long Fourier frame, periodic ROM, S small).
    Segmented(SegmentedModel<'rom>),
    /// The folded driver (Fourier, periodic ROM).
    Fold(FoldModel<'rom>),
    /// The transaction driver and the ROM it reads (`None` in Haar mode).
    Transaction(TransactionModel, Option<&'rom RomImage>),
}

impl<'rom> FrameDriver<'rom> {
    /// A pixel just out of reset: segmented when [`segments_pay`], folded when
    /// [`fold_pays`] for `params` (N = `frame_pulses` pulses per frame). Fails if the
    /// parameters do not validate or the ROM does not fit them (Fourier).
    pub fn new(params: &PixelParams, rom: Option<&'rom RomImage>) -> Result<Self, PixelError> {
        match rom {
            Some(rom) if segments_pay(params) => {
                Ok(FrameDriver::Segmented(SegmentedModel::new(params, rom)?))
            }
            Some(rom) if fold_pays(params) => Ok(FrameDriver::Fold(FoldModel::new(params, rom)?)),
            _ => Self::transaction(params, rom),
        }
    }

    /// The transaction driver, whatever the parameters (the reference the fold is tested
    /// against).
    pub fn transaction(
        params: &PixelParams,
        rom: Option<&'rom RomImage>,
    ) -> Result<Self, PixelError> {
        let tm = TransactionModel::new(params)?;
        if params.mode == crate::params::Mode::Fourier {
            crate::transaction::check_rom(params, rom)?;
        }
        Ok(FrameDriver::Transaction(tm, rom))
    }

    /// Whether a folded driver (the fold or the segmented fold) runs.
    pub fn is_folded(&self) -> bool {
        matches!(self, FrameDriver::Fold(_) | FrameDriver::Segmented(_))
    }

    /// Whether the segmented fold runs.
    pub fn is_segmented(&self) -> bool {
        matches!(self, FrameDriver::Segmented(_))
    }

    /// Runs many pulses: pulse i reads ROM address (`first_address` + i) mod L (see
    /// [`TransactionModel::run`]).
    pub fn run<D: Detections + ?Sized>(
        &mut self,
        detections: &D,
        first_address: u64,
    ) -> Result<(), PixelError> {
        match self {
            FrameDriver::Segmented(s) => {
                s.run(detections, first_address);
                Ok(())
            }
            FrameDriver::Fold(f) => {
                f.run(detections, first_address);
                Ok(())
            }
            FrameDriver::Transaction(tm, rom) => tm.run(detections, *rom, first_address),
        }
    }

    /// Pulses run since the last readout.
    pub fn pulses_in_frame(&self) -> u64 {
        match self {
            FrameDriver::Segmented(s) => s.pulses_in_frame(),
            FrameDriver::Fold(f) => f.pulses_in_frame(),
            FrameDriver::Transaction(tm, _) => tm.pulses_in_frame(),
        }
    }

    /// Reads the frame out and clears the registers (the depth tracking continues).
    pub fn readout(&mut self) -> Readout {
        match self {
            FrameDriver::Segmented(s) => s.readout(),
            FrameDriver::Fold(f) => f.readout(),
            FrameDriver::Transaction(tm, _) => tm.readout(),
        }
    }
}

/// Runs whole frames the way the reference sequencer drives them (frame after frame of N
/// pulses, pulse n of a frame reading ROM address n mod L, a readout after each), with the
/// driver [`FrameDriver::new`] picks: the same readouts as
/// [`TransactionModel::run_frames`].
pub fn run_frames<D: Detections + ?Sized>(
    params: &PixelParams,
    stimuli: &D,
    rom: Option<&RomImage>,
) -> Result<Vec<Readout>, PixelError> {
    let n = frame_len(params, stimuli.len())?;
    let mut driver = FrameDriver::new(params, rom)?;
    let mut out = Vec::with_capacity(stimuli.len() / n.max(1));
    for start in (0..stimuli.len()).step_by(n.max(1)) {
        driver.run(&Window::new(stimuli, start..start + n), 0)?;
        out.push(driver.readout());
    }
    Ok(out)
}
