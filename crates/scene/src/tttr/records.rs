//! The 32-bit record formats: PicoHarp, HydraHarp v1/v2 and TimeHarp 260 N/P in T2 and T3
//! mode (PicoQuant's `TTResultFormat_TTTRRecType`), and Becker & Hickl SPC-130/150 FIFO
//! records, each decoded into [`Event`]s with its overflow (wrap-around) correction.

use serde::Serialize;

/// PicoHarp T3: 16 sync bits wrap every 65536 syncs.
const PH_T3_WRAP: u64 = 65_536;
/// PicoHarp T2: the 28-bit tag wraps at 210 698 240 (not 2^28; PicoQuant's constant).
const PH_T2_WRAP: u64 = 210_698_240;
/// HydraHarp / TimeHarp 260 T3: 10 sync bits.
const HH_T3_WRAP: u64 = 1024;
/// HydraHarp v1 T2: 33 552 000 (PicoQuant's constant).
const HH1_T2_WRAP: u64 = 33_552_000;
/// HydraHarp v2 / TimeHarp 260 T2: 2^25.
const HH2_T2_WRAP: u64 = 33_554_432;
/// SPC-130/150: 12 macro-time bits.
const SPC_WRAP: u64 = 4096;

/// A record format this crate decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum RecordFormat {
    /// PicoHarp 300 T2 (0x00010203).
    PicoHarpT2,
    /// PicoHarp 300 T3 (0x00010303).
    PicoHarpT3,
    /// HydraHarp 400 v1 T2 (0x00010204).
    HydraHarp1T2,
    /// HydraHarp 400 v1 T3 (0x00010304).
    HydraHarp1T3,
    /// HydraHarp 400 v2 T2 (0x01010204).
    HydraHarp2T2,
    /// HydraHarp 400 v2 T3 (0x01010304).
    HydraHarp2T3,
    /// TimeHarp 260 N T2 (0x00010205).
    TimeHarp260NT2,
    /// TimeHarp 260 N T3 (0x00010305).
    TimeHarp260NT3,
    /// TimeHarp 260 P T2 (0x00010206).
    TimeHarp260PT2,
    /// TimeHarp 260 P T3 (0x00010306).
    TimeHarp260PT3,
    /// Becker & Hickl SPC-130/150 FIFO (32-bit records after a 4-byte header).
    BeckerHicklSpc,
}

impl RecordFormat {
    /// The format of a PTU `TTResultFormat_TTTRRecType`, if decoded here.
    pub fn from_ptu_record_type(code: u32) -> Option<RecordFormat> {
        use RecordFormat::*;
        Some(match code {
            0x0001_0203 => PicoHarpT2,
            0x0001_0303 => PicoHarpT3,
            0x0001_0204 => HydraHarp1T2,
            0x0001_0304 => HydraHarp1T3,
            0x0101_0204 => HydraHarp2T2,
            0x0101_0304 => HydraHarp2T3,
            0x0001_0205 => TimeHarp260NT2,
            0x0001_0305 => TimeHarp260NT3,
            0x0001_0206 => TimeHarp260PT2,
            0x0001_0306 => TimeHarp260PT3,
            _ => return None,
        })
    }

    /// The PTU record-type code (0 for SPC, which has none).
    pub fn ptu_record_type(self) -> u32 {
        use RecordFormat::*;
        match self {
            PicoHarpT2 => 0x0001_0203,
            PicoHarpT3 => 0x0001_0303,
            HydraHarp1T2 => 0x0001_0204,
            HydraHarp1T3 => 0x0001_0304,
            HydraHarp2T2 => 0x0101_0204,
            HydraHarp2T3 => 0x0101_0304,
            TimeHarp260NT2 => 0x0001_0205,
            TimeHarp260NT3 => 0x0001_0305,
            TimeHarp260PT2 => 0x0001_0206,
            TimeHarp260PT3 => 0x0001_0306,
            BeckerHicklSpc => 0,
        }
    }

    /// T3 (photons counted in sync periods with a delay; SPC is T3-like: macro-time
    /// ticks and an ADC micro time) or T2 (absolute time tags).
    pub fn is_t3(self) -> bool {
        use RecordFormat::*;
        !matches!(
            self,
            PicoHarpT2 | HydraHarp1T2 | HydraHarp2T2 | TimeHarp260NT2 | TimeHarp260PT2
        )
    }

    /// The list of decoded PTU record types, for error messages.
    pub(crate) fn supported_ptu() -> &'static str {
        "a PTU record type of PicoHarp T2/T3 (0x00010203/0x00010303), HydraHarp v1 \
         (0x00010204/0x00010304), HydraHarp v2 (0x01010204/0x01010304), TimeHarp 260 N \
         (0x00010205/0x00010305) or TimeHarp 260 P (0x00010206/0x00010306)"
    }
}

/// One decoded record. Times are absolute (overflow-corrected) from the start of the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Event {
    /// A T3 photon (or SPC photon): in sync period `sync` (counted from the first sync of
    /// the file), `dtime` resolution units after that sync. SPC: `sync` is the macro time
    /// in ticks, `dtime` = 4095 − ADC (the ADC runs reversed start-stop), `channel` the
    /// routing bits.
    T3Photon {
        /// Sync (laser pulse) count.
        sync: u64,
        /// Channel as stored in the record (HydraHarp input 1 is channel 0).
        channel: u8,
        /// Delay after the sync, in resolution units.
        dtime: u32,
    },
    /// A T2 event on a channel (a photon, or the sync if the user names its channel —
    /// PicoHarp T2 records the sync input as channel 0). `time` in global-resolution units.
    T2Photon {
        /// Time tag.
        time: u64,
        /// Channel as stored in the record.
        channel: u8,
    },
    /// A HydraHarp/TimeHarp T2 sync record (special bit, channel 0).
    Sync {
        /// Time tag.
        time: u64,
    },
    /// External marker(s): `bits` is the marker mask (SPC: the routing bits); `time` the
    /// sync count (T3) or time tag (T2).
    Marker {
        /// Sync count or time tag.
        time: u64,
        /// Marker bits.
        bits: u8,
    },
    /// A record that only advances the clock by `wraps` wrap-arounds.
    Overflow {
        /// Wrap-arounds (≥ 1).
        wraps: u64,
    },
}

/// Counts kept while decoding (records that are not photons included).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct DecodeCounts {
    /// Records read.
    pub records: u64,
    /// Photon records (T3 photons; T2 events on channels, the sync channel included).
    pub photons: u64,
    /// HydraHarp/TimeHarp T2 sync records.
    pub syncs: u64,
    /// Marker records.
    pub markers: u64,
    /// Records that carried an overflow (SPC: also a photon with MTOV set).
    pub overflow_records: u64,
    /// Wrap-arounds those records stand for (HydraHarp v2/TimeHarp and SPC records can
    /// carry several).
    pub overflow_wraps: u64,
    /// SPC records flagged INVALID that were neither overflows nor markers (skipped).
    pub invalid: u64,
    /// SPC records flagged GAP (the card's FIFO overflowed: photons were lost before it).
    pub gaps: u64,
}

/// Why a record word could not be decoded.
pub(crate) type BadRecord = String;

/// Decoder state: the format and the running overflow correction.
#[derive(Debug, Clone)]
pub(crate) struct Decoder {
    format: RecordFormat,
    /// Overflow correction in sync counts (T3) or time-tag units (T2).
    base: u64,
    pub(crate) counts: DecodeCounts,
    /// Largest sync count / time tag seen (the overflow base included).
    pub(crate) last_time: u64,
}

impl Decoder {
    pub(crate) fn new(format: RecordFormat) -> Decoder {
        Decoder {
            format,
            base: 0,
            counts: DecodeCounts::default(),
            last_time: 0,
        }
    }

    fn overflow(&mut self, wrap: u64, wraps: u64) -> Event {
        self.base += wrap * wraps;
        self.counts.overflow_records += 1;
        self.counts.overflow_wraps += wraps;
        self.last_time = self.last_time.max(self.base);
        Event::Overflow { wraps }
    }

    fn at(&mut self, t: u64) -> u64 {
        let t = self.base + t;
        self.last_time = self.last_time.max(t);
        t
    }

    /// Decodes one record word; `Ok(None)` for a record that carries nothing (SPC invalid).
    #[inline]
    pub(crate) fn decode(&mut self, w: u32) -> Result<Option<Event>, BadRecord> {
        use RecordFormat::*;
        self.counts.records += 1;
        let ev = match self.format {
            PicoHarpT3 => {
                let nsync = u64::from(w & 0xFFFF);
                let dtime = (w >> 16) & 0xFFF;
                let chan = (w >> 28) as u8;
                if chan == 0xF {
                    if dtime == 0 {
                        self.overflow(PH_T3_WRAP, 1)
                    } else {
                        self.counts.markers += 1;
                        Event::Marker {
                            time: self.at(nsync),
                            bits: (dtime & 0xF) as u8,
                        }
                    }
                } else if (1..=4).contains(&chan) {
                    self.counts.photons += 1;
                    Event::T3Photon {
                        sync: self.at(nsync),
                        channel: chan,
                        dtime,
                    }
                } else {
                    return Err(format!(
                        "a PicoHarp T3 channel 1..4 or 15 (special), found channel {chan}"
                    ));
                }
            }
            PicoHarpT2 => {
                let time = u64::from(w & 0x0FFF_FFFF);
                let chan = (w >> 28) as u8;
                if chan == 0xF {
                    let bits = (w & 0xF) as u8;
                    if bits == 0 {
                        self.overflow(PH_T2_WRAP, 1)
                    } else {
                        self.counts.markers += 1;
                        Event::Marker {
                            time: self.at(time),
                            bits,
                        }
                    }
                } else if chan <= 4 {
                    self.counts.photons += 1;
                    Event::T2Photon {
                        time: self.at(time),
                        channel: chan,
                    }
                } else {
                    return Err(format!(
                        "a PicoHarp T2 channel 0..4 or 15 (special), found channel {chan}"
                    ));
                }
            }
            HydraHarp1T3 | HydraHarp2T3 | TimeHarp260NT3 | TimeHarp260PT3 => {
                let nsync = u64::from(w & 0x3FF);
                let dtime = (w >> 10) & 0x7FFF;
                let chan = ((w >> 25) & 0x3F) as u8;
                if w >> 31 == 1 {
                    if chan == 0x3F {
                        // v1 counts one wrap per record; v2 and TimeHarp put the count in
                        // the nsync field (0 meaning 1, as written by old firmware).
                        let wraps = if self.format == HydraHarp1T3 || nsync == 0 {
                            1
                        } else {
                            nsync
                        };
                        self.overflow(HH_T3_WRAP, wraps)
                    } else if (1..=15).contains(&chan) {
                        self.counts.markers += 1;
                        Event::Marker {
                            time: self.at(nsync),
                            bits: chan,
                        }
                    } else {
                        return Err(format!(
                            "a special T3 record with channel 63 (overflow) or 1..15 \
                             (markers), found channel {chan}"
                        ));
                    }
                } else {
                    self.counts.photons += 1;
                    Event::T3Photon {
                        sync: self.at(nsync),
                        channel: chan,
                        dtime,
                    }
                }
            }
            HydraHarp1T2 | HydraHarp2T2 | TimeHarp260NT2 | TimeHarp260PT2 => {
                let tag = u64::from(w & 0x01FF_FFFF);
                let chan = ((w >> 25) & 0x3F) as u8;
                if w >> 31 == 1 {
                    if chan == 0x3F {
                        if self.format == HydraHarp1T2 {
                            self.overflow(HH1_T2_WRAP, 1)
                        } else {
                            let wraps = if tag == 0 { 1 } else { tag };
                            self.overflow(HH2_T2_WRAP, wraps)
                        }
                    } else if chan == 0 {
                        self.counts.syncs += 1;
                        Event::Sync { time: self.at(tag) }
                    } else if chan <= 15 {
                        self.counts.markers += 1;
                        Event::Marker {
                            time: self.at(tag),
                            bits: chan,
                        }
                    } else {
                        return Err(format!(
                            "a special T2 record with channel 0 (sync), 1..15 (markers) or \
                             63 (overflow), found channel {chan}"
                        ));
                    }
                } else {
                    self.counts.photons += 1;
                    Event::T2Photon {
                        time: self.at(tag),
                        channel: chan,
                    }
                }
            }
            BeckerHicklSpc => return Ok(self.decode_spc(w)),
        };
        Ok(Some(ev))
    }

    /// SPC-130/150: bit 31 INVALID, 30 MTOV, 29 GAP, 28 MARK, 27..16 ADC, 15..12 routing,
    /// 11..0 macro time. INVALID with MTOV: the low 28 bits count macro-time overflows
    /// (B&H handbook; phconvert's reader). MTOV on a photon: one overflow before it.
    fn decode_spc(&mut self, w: u32) -> Option<Event> {
        let invalid = w & (1 << 31) != 0;
        let mtov = w & (1 << 30) != 0;
        if w & (1 << 29) != 0 {
            self.counts.gaps += 1;
        }
        if invalid && mtov {
            return Some(self.overflow(SPC_WRAP, u64::from(w & 0x0FFF_FFFF)));
        }
        if mtov {
            self.base += SPC_WRAP;
            self.counts.overflow_records += 1;
            self.counts.overflow_wraps += 1;
        }
        let macro_time = u64::from(w & 0xFFF);
        let routing = ((w >> 12) & 0xF) as u8;
        if w & (1 << 28) != 0 {
            self.counts.markers += 1;
            return Some(Event::Marker {
                time: self.at(macro_time),
                bits: routing,
            });
        }
        if invalid {
            self.counts.invalid += 1;
            return None;
        }
        self.counts.photons += 1;
        Some(Event::T3Photon {
            sync: self.at(macro_time),
            channel: routing,
            dtime: 4095 - ((w >> 16) & 0xFFF),
        })
    }
}
