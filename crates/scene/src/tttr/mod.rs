//! Real time-tagged single-photon records — PicoQuant PTU (PicoHarp, HydraHarp v1/v2,
//! TimeHarp 260 N/P; T2 and T3) and Becker & Hickl SPC-130/150 — decoded as a stream and
//! turned into the pixel's per-pulse detections, so a measured record can be replayed
//! through the same pixel as the Monte Carlo.
//!
//! - [`open`] reads the header and returns a [`TttrReader`], an iterator of [`Event`]s
//!   that holds one 256 KiB block of the file at a time.
//! - [`PulseStream`] turns the events into `Option<u32>` per laser pulse, exactly as
//!   [`crate::PhotonSource::fill`] does for simulated photons (see [`pulses`]).
//! - [`summarize`] decodes a whole file into a [`TttrSummary`].
//!
//! Formats: PicoQuant's demo readers (`PTU_Demo`), the `ptufile` package and the B&H TCSPC
//! handbook / phconvert's `bhreader`; `scripts/tttr-crosscheck.sh` compares this decoder
//! with `ptufile` on real files.

mod ptu;
pub mod pulses;
mod records;
mod words;

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use serde::Serialize;

use crate::error::SceneError;
pub use ptu::{PTU_MAGIC, PtuHeader, Tag, TagValue};
pub use pulses::{PulseStream, ReplayCounts, ReplayOptions, TdcWindow};
use records::Decoder;
pub use records::{DecodeCounts, Event, RecordFormat};
use words::WordReader;

/// What a file's header says about its records (times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TttrHeader {
    /// The record format.
    pub format: RecordFormat,
    /// Records the header promises (PTU `TTResult_NumberOfRecords`; SPC: from the length).
    pub records: u64,
    /// T3: the delay (dtime) bin width (`MeasDesc_Resolution`); T2: the time-tag unit;
    /// SPC: unknown (the ADC range is in the `.set` file), so `None`.
    pub resolution_s: Option<f64>,
    /// T3: the sync period (`MeasDesc_GlobalResolution`); T2: the time-tag unit;
    /// SPC: the macro-time clock period (from the file's first word).
    pub global_resolution_s: Option<f64>,
    /// `TTResult_SyncRate` (Hz), when the header gives a positive one.
    pub sync_rate_hz: Option<f64>,
    /// `MeasDesc_AcquisitionTime` (the header stores ms).
    pub acquisition_time_s: Option<f64>,
    /// Header length in bytes.
    pub header_bytes: u64,
    /// The PTU tags (empty for SPC).
    #[serde(skip)]
    pub ptu: Option<PtuHeader>,
}

/// A streaming decoder of one time-tagged file.
#[derive(Debug)]
pub struct TttrReader<R> {
    file: String,
    header: TttrHeader,
    words: WordReader<R>,
    decoder: Decoder,
}

/// Opens a time-tagged file: PTU by its magic, SPC-130/150 by the `.spc` extension.
pub fn open(path: &Path) -> Result<TttrReader<BufReader<File>>, SceneError> {
    let name = path.display().to_string();
    let f = File::open(path).map_err(|e| SceneError::Tttr {
        file: name.clone(),
        at: "opening".into(),
        expected: "a readable PicoQuant .ptu or Becker & Hickl .spc file".into(),
        found: e.to_string(),
    })?;
    let len = f.metadata().map(|m| m.len()).ok();
    let r = BufReader::with_capacity(1 << 16, f);
    let spc = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("spc"));
    if spc {
        TttrReader::spc(r, &name, len)
    } else {
        TttrReader::ptu(r, &name)
    }
}

/// Decodes a whole file (in bounded memory) into its summary.
pub fn summarize(path: &Path) -> Result<TttrSummary, SceneError> {
    let mut r = open(path)?;
    while r.next_event()?.is_some() {}
    Ok(r.summary())
}

impl<R: Read> TttrReader<R> {
    /// A PTU stream: the header, then records of the type it names.
    pub fn ptu(mut r: R, file: &str) -> Result<TttrReader<R>, SceneError> {
        let h = PtuHeader::read(&mut r, file)?;
        let err = |ident: &str, expected: &str, found: String| SceneError::Tttr {
            file: file.to_string(),
            at: format!("header tag `{ident}`"),
            expected: expected.to_string(),
            found,
        };
        let code = h.int("TTResultFormat_TTTRRecType").ok_or_else(|| {
            err(
                "TTResultFormat_TTTRRecType",
                "an integer tag",
                "none".into(),
            )
        })?;
        let format = RecordFormat::from_ptu_record_type(code as u32).ok_or_else(|| {
            err(
                "TTResultFormat_TTTRRecType",
                RecordFormat::supported_ptu(),
                format!("0x{code:08X}"),
            )
        })?;
        if let Some(bits) = h.int("TTResultFormat_BitsPerRecord")
            && bits != 32
        {
            return Err(err(
                "TTResultFormat_BitsPerRecord",
                "32-bit records",
                bits.to_string(),
            ));
        }
        let records = h
            .int("TTResult_NumberOfRecords")
            .filter(|&n| n >= 0)
            .ok_or_else(|| {
                err(
                    "TTResult_NumberOfRecords",
                    "a non-negative integer tag",
                    format!("{:?}", h.get("TTResult_NumberOfRecords")),
                )
            })? as u64;
        let positive = |v: Option<f64>| v.filter(|x| x.is_finite() && *x > 0.0);
        let global = positive(h.float("MeasDesc_GlobalResolution"));
        let resolution = if format.is_t3() {
            positive(h.float("MeasDesc_Resolution"))
        } else {
            global
        };
        let header = TttrHeader {
            format,
            records,
            resolution_s: resolution,
            global_resolution_s: global,
            sync_rate_hz: h
                .int("TTResult_SyncRate")
                .filter(|&v| v > 0)
                .map(|v| v as f64),
            acquisition_time_s: h
                .int("MeasDesc_AcquisitionTime")
                .filter(|&v| v > 0)
                .map(|v| v as f64 * 1e-3),
            header_bytes: h.len,
            ptu: None,
        };
        let words = WordReader::new(r, file, h.len, Some(records));
        Ok(TttrReader {
            file: file.to_string(),
            header: TttrHeader {
                ptu: Some(h),
                ..header
            },
            words,
            decoder: Decoder::new(format),
        })
    }

    /// An SPC-130/150 stream: a 4-byte header (bits 23..0: the macro-time clock in units
    /// of 0.1 ns), then 4-byte records; `len` is the file length, when known.
    pub fn spc(mut r: R, file: &str, len: Option<u64>) -> Result<TttrReader<R>, SceneError> {
        let mut w = [0u8; 4];
        let mut got = 0;
        while got < 4 {
            match r.read(&mut w[got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(SceneError::Tttr {
                        file: file.to_string(),
                        at: "byte 0 (SPC header)".into(),
                        expected: "a readable file".into(),
                        found: format!("a read error: {e}"),
                    });
                }
            }
        }
        let clock = u32::from_le_bytes(w) & 0x00FF_FFFF;
        if got < 4 || clock == 0 {
            return Err(SceneError::Tttr {
                file: file.to_string(),
                at: "byte 0 (SPC header)".into(),
                expected: "a 4-byte SPC-130/150 header whose bits 23..0 give the macro-time \
                           clock (> 0, in 0.1 ns)"
                    .into(),
                found: if got < 4 {
                    format!("{got} bytes, then the end of the file")
                } else {
                    "a clock of 0".into()
                },
            });
        }
        let records = len.map(|l| l.saturating_sub(4) / 4);
        let header = TttrHeader {
            format: RecordFormat::BeckerHicklSpc,
            records: records.unwrap_or(0),
            resolution_s: None,
            global_resolution_s: Some(f64::from(clock) / 1e10),
            sync_rate_hz: None,
            acquisition_time_s: None,
            header_bytes: 4,
            ptu: None,
        };
        // The record count comes from the length, so a stray partial record at the end
        // is still reported (`WordReader` checks whole words when no count is promised).
        Ok(TttrReader {
            file: file.to_string(),
            header,
            words: WordReader::new(r, file, 4, None),
            decoder: Decoder::new(RecordFormat::BeckerHicklSpc),
        })
    }

    /// The header.
    pub fn header(&self) -> &TttrHeader {
        &self.header
    }

    /// The file name, as given.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// Counts so far.
    pub fn counts(&self) -> DecodeCounts {
        self.decoder.counts
    }

    /// Index of the next record (records read so far).
    pub fn record_index(&self) -> u64 {
        self.words.index()
    }

    /// `record 12 (byte 5848)`, for messages about record `index`.
    pub fn at(&self, index: u64) -> String {
        self.words.at(index)
    }

    /// Largest sync count (T3/SPC) or time tag (T2) seen, the overflow base included.
    pub fn last_time(&self) -> u64 {
        self.decoder.last_time
    }

    /// The next event, `None` at the end of the records.
    #[inline]
    pub fn next_event(&mut self) -> Result<Option<Event>, SceneError> {
        loop {
            let Some(w) = self.words.next_word()? else {
                return Ok(None);
            };
            match self.decoder.decode(w) {
                Ok(Some(ev)) => return Ok(Some(ev)),
                Ok(None) => {}
                Err(expected) => {
                    return Err(SceneError::Tttr {
                        file: self.file.clone(),
                        at: self.words.at(self.words.index() - 1),
                        expected,
                        found: format!("the word 0x{w:08X}"),
                    });
                }
            }
        }
    }

    /// The summary of what has been decoded so far (the whole file once
    /// [`Self::next_event`] returned `None`).
    pub fn summary(&self) -> TttrSummary {
        let h = &self.header;
        TttrSummary {
            file: self.file.clone(),
            format: h.format,
            record_type: h.format.ptu_record_type(),
            counts: self.decoder.counts,
            header_records: h.records,
            resolution_s: h.resolution_s,
            global_resolution_s: h.global_resolution_s,
            sync_rate_hz: h.sync_rate_hz,
            acquisition_time_s: h.acquisition_time_s,
            last_time: self.decoder.last_time,
        }
    }
}

impl<R: Read> Iterator for TttrReader<R> {
    type Item = Result<Event, SceneError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_event().transpose()
    }
}

/// What a decoded file holds (times in seconds).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TttrSummary {
    /// The file as given.
    pub file: String,
    /// The record format.
    pub format: RecordFormat,
    /// The PTU record-type code (0 for SPC).
    pub record_type: u32,
    /// Records, photons, syncs, markers, overflows, invalid and gap records decoded.
    pub counts: DecodeCounts,
    /// Records the header promised.
    pub header_records: u64,
    /// Delay bin (T3) or time-tag unit (T2); `None` when the file does not say (SPC).
    pub resolution_s: Option<f64>,
    /// Sync period (T3), time-tag unit (T2) or macro-time clock (SPC).
    pub global_resolution_s: Option<f64>,
    /// Sync rate from the header (Hz).
    pub sync_rate_hz: Option<f64>,
    /// Acquisition time from the header.
    pub acquisition_time_s: Option<f64>,
    /// Last sync count (T3/SPC) or time tag (T2), overflow-corrected.
    pub last_time: u64,
}
