//! Replay: a time-tagged record as the pixel's pulse stream.
//!
//! Semantics (the same conventions as the Monte Carlo of [`crate::PhotonSource`]):
//! - **Pulses.** T3 and SPC: every sync period (macro-time tick for SPC) is one laser
//!   pulse, pulse n = overflow-corrected sync count n. T2: each record of the sync channel
//!   starts a pulse (pulse k = the k-th sync record); photons before the first sync are
//!   dropped and counted.
//! - **Time of flight.** T3: `dtime × resolution`; T2: the photon's time since the last
//!   sync × the time-tag unit.
//! - **Window and TDC.** `code = floor((t − window_start) / lsb)`; arrivals before
//!   `window_start` or at/after `window_start + window_length` are not detected; of the
//!   rest the earliest in each pulse wins (first-photon pile-up); codes are clamped to the
//!   last one as in the Monte Carlo (a last partial bin counts as a code).
//! - A pulse with no detection is `None`. The stream ends after the last pulse the file
//!   covers: the last sync (T2), or the last sync count any record reaches (T3).

use std::io::Read;

use serde::Serialize;

use super::{Event, TttrReader};
use crate::error::{SceneError, check_positive, check_range};
use crate::sensor::{MAX_TDC_CODES, SensorConfig};

/// The TDC the records are quantised by: the sensor's LSB and timing window (ps).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TdcWindow {
    /// TDC least significant bit (ps).
    pub tdc_lsb_ps: f64,
    /// Start of the timing window after the sync (ps); code 0 starts here.
    pub window_start_ps: f64,
    /// Length of the timing window (ps).
    pub window_length_ps: f64,
}

impl TdcWindow {
    /// The window and LSB of a sensor configuration.
    pub fn from_sensor(s: &SensorConfig) -> TdcWindow {
        TdcWindow {
            tdc_lsb_ps: s.tdc_lsb_ps,
            window_start_ps: s.window_start_ps,
            window_length_ps: s.window_length_ps,
        }
    }

    /// Checks the fields as [`SensorConfig::validate`] does.
    pub fn validate(&self) -> Result<(), SceneError> {
        check_positive("sensor.tdc_lsb_ps", self.tdc_lsb_ps, 1e6)?;
        check_range("sensor.window_start_ps", self.window_start_ps, 0.0, 1e9)?;
        check_positive("sensor.window_length_ps", self.window_length_ps, 1e9)?;
        let codes = self.window_length_ps / self.tdc_lsb_ps;
        if !(1.0..=f64::from(MAX_TDC_CODES)).contains(&codes) {
            return Err(SceneError::out_of_range(
                "sensor.window_length_ps",
                self.window_length_ps,
                format!(
                    "tdc_lsb_ps <= window_length_ps <= {MAX_TDC_CODES} · tdc_lsb_ps = {}",
                    f64::from(MAX_TDC_CODES) * self.tdc_lsb_ps
                ),
            ));
        }
        Ok(())
    }

    /// Codes in the window, as [`SensorConfig::tdc_codes`].
    pub fn tdc_codes(&self) -> u32 {
        let codes = (self.window_length_ps / self.tdc_lsb_ps - 1e-9).ceil();
        codes.clamp(1.0, f64::from(MAX_TDC_CODES)) as u32
    }

    /// The code of an arrival `t_ps` after the pulse, `None` outside the window.
    #[inline]
    pub fn quantise(&self, t_ps: f64) -> Option<u32> {
        let x = t_ps - self.window_start_ps;
        if (0.0..self.window_length_ps).contains(&x) {
            Some(((x / self.tdc_lsb_ps) as u32).min(self.tdc_codes() - 1))
        } else {
            None
        }
    }
}

/// How to replay a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayOptions {
    /// The TDC the arrivals are quantised by.
    pub window: TdcWindow,
    /// T2: the channel whose events are the syncs. `None`: channel 0 for PicoHarp, the
    /// sync records for HydraHarp/TimeHarp. Ignored for T3.
    pub sync_channel: Option<u8>,
    /// Only photons of this channel (as stored in the record); `None`: all channels.
    pub photon_channel: Option<u8>,
    /// The delay bin (T3) or time-tag unit (T2) in seconds, instead of the header's.
    /// Needed for SPC: the ADC bin is the TAC range / ADC resolution of the `.set` file.
    pub resolution_s: Option<f64>,
}

impl ReplayOptions {
    /// Defaults: the header's sync, every channel, the header's resolution.
    pub fn new(window: TdcWindow) -> ReplayOptions {
        ReplayOptions {
            window,
            sync_channel: None,
            photon_channel: None,
            resolution_s: None,
        }
    }
}

/// Counts of a replay, beside the decoder's.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ReplayCounts {
    /// Pulses emitted.
    pub pulses: u64,
    /// Pulses with a detection.
    pub detections: u64,
    /// Photons that arrived inside the window (the winners and those they beat).
    pub in_window: u64,
    /// Photons outside the window (not detected).
    pub outside_window: u64,
    /// T2 photons before the first sync (no pulse to belong to).
    pub before_first_sync: u64,
    /// Photons on other channels than `photon_channel`.
    pub other_channel: u64,
}

/// A record's pulses as `Option<u32>` detections, streamed in chunks.
#[derive(Debug)]
pub struct PulseStream<R> {
    reader: TttrReader<R>,
    window: TdcWindow,
    /// Picoseconds per delay bin (T3) or time-tag unit (T2).
    unit_ps: f64,
    t2_sync: Option<T2Sync>,
    photon_channel: Option<u8>,
    /// Pulses handed out so far.
    emitted: u64,
    /// The pulse being gathered and its best code so far.
    acc: Option<(u64, Option<u32>)>,
    /// A finished pulse waiting to be handed out (all pulses before it are `None`).
    ready: Option<(u64, Option<u32>)>,
    /// Total pulses, once the records are exhausted.
    total: Option<u64>,
    /// T2: time tag of the current sync and the current pulse's index.
    last_sync: Option<(u64, u64)>,
    counts: ReplayCounts,
}

/// Which T2 events are syncs.
#[derive(Debug, Clone, Copy, PartialEq)]
enum T2Sync {
    Records,
    Channel(u8),
}

impl<R: Read> PulseStream<R> {
    /// A replay of `reader` (freshly opened) with `options`.
    pub fn new(reader: TttrReader<R>, options: &ReplayOptions) -> Result<Self, SceneError> {
        options.window.validate()?;
        let h = reader.header();
        let resolution =
            options
                .resolution_s
                .or(h.resolution_s)
                .ok_or_else(|| SceneError::Tttr {
                    file: reader.file().to_string(),
                    at: "header".into(),
                    expected: "the delay resolution: for SPC files give resolution_s (the ADC \
                           bin: TAC range / gain / ADC resolution, from the .set file), e.g. \
                           resolution_s = 1.2207e-11 for 50 ns over 4096 bins"
                        .into(),
                    found: "none in the file".into(),
                })?;
        if !(resolution.is_finite() && resolution > 0.0 && resolution < 1.0) {
            return Err(SceneError::out_of_range(
                "replay.resolution_s",
                resolution,
                "0 < resolution_s < 1 (seconds per delay bin)",
            ));
        }
        let t2_sync = if h.format.is_t3() {
            None
        } else {
            Some(match (options.sync_channel, h.format) {
                (Some(c), _) => T2Sync::Channel(c),
                (None, super::RecordFormat::PicoHarpT2) => T2Sync::Channel(0),
                (None, _) => T2Sync::Records,
            })
        };
        Ok(PulseStream {
            reader,
            window: options.window,
            unit_ps: round_ps(resolution),
            t2_sync,
            photon_channel: options.photon_channel,
            emitted: 0,
            acc: None,
            ready: None,
            total: None,
            last_sync: None,
            counts: ReplayCounts::default(),
        })
    }

    /// The decoder underneath (header, decode counts, summary).
    pub fn reader(&self) -> &TttrReader<R> {
        &self.reader
    }

    /// Replay counts so far.
    pub fn counts(&self) -> ReplayCounts {
        self.counts
    }

    /// Codes in the window.
    pub fn tdc_codes(&self) -> u32 {
        self.window.tdc_codes()
    }

    /// Picoseconds per delay bin (T3) or time-tag unit (T2), as used.
    pub fn unit_ps(&self) -> f64 {
        self.unit_ps
    }

    /// Writes the next pulses into `out`; returns how many (fewer than `out.len()` only
    /// at the end of the record, 0 once it is exhausted).
    pub fn fill(&mut self, out: &mut [Option<u32>]) -> Result<usize, SceneError> {
        let mut n = 0;
        while n < out.len() {
            if let Some((p, code)) = self.ready {
                let k = (p - self.emitted).min((out.len() - n) as u64) as usize;
                out[n..n + k].fill(None);
                n += k;
                self.emitted += k as u64;
                if self.emitted == p && n < out.len() {
                    out[n] = code;
                    n += 1;
                    self.emitted += 1;
                    self.counts.detections += u64::from(code.is_some());
                    self.ready = None;
                }
                continue;
            }
            if let Some(total) = self.total {
                let k = (total.saturating_sub(self.emitted)).min((out.len() - n) as u64) as usize;
                out[n..n + k].fill(None);
                n += k;
                self.emitted += k as u64;
                break;
            }
            self.advance()?;
        }
        self.counts.pulses = self.emitted;
        Ok(n)
    }

    /// Streams the rest of the record through `f(first_pulse, detections)` in chunks of
    /// `chunk` pulses (the last one shorter); returns the pulses streamed.
    pub fn for_each_chunk(
        &mut self,
        chunk: usize,
        mut f: impl FnMut(u64, &[Option<u32>]),
    ) -> Result<u64, SceneError> {
        let mut buf = vec![None; chunk.max(1)];
        let start = self.emitted;
        loop {
            let first = self.emitted;
            let n = self.fill(&mut buf)?;
            if n == 0 {
                return Ok(self.emitted - start);
            }
            f(first, &buf[..n]);
        }
    }

    /// Reads events until a pulse is finished (`ready`) or the record ends (`total`).
    fn advance(&mut self) -> Result<(), SceneError> {
        while self.ready.is_none() {
            let Some(ev) = self.reader.next_event()? else {
                return self.finish();
            };
            let (pulse, t_ps) = match (ev, self.t2_sync) {
                (
                    Event::T3Photon {
                        sync,
                        channel,
                        dtime,
                    },
                    None,
                ) => {
                    if self.photon_channel.is_some_and(|c| c != channel) {
                        self.counts.other_channel += 1;
                        continue;
                    }
                    (sync, f64::from(dtime) * self.unit_ps)
                }
                (Event::Sync { time }, Some(T2Sync::Records)) => {
                    self.new_sync(time);
                    continue;
                }
                (Event::T2Photon { time, channel }, Some(T2Sync::Channel(c))) if channel == c => {
                    self.new_sync(time);
                    continue;
                }
                (Event::T2Photon { time, channel }, Some(_)) => {
                    if self.photon_channel.is_some_and(|c| c != channel) {
                        self.counts.other_channel += 1;
                        continue;
                    }
                    let Some((ts, pulse)) = self.last_sync else {
                        self.counts.before_first_sync += 1;
                        continue;
                    };
                    (pulse, (time - ts) as f64 * self.unit_ps)
                }
                _ => continue,
            };
            self.photon(pulse, t_ps)?;
        }
        Ok(())
    }

    fn new_sync(&mut self, time: u64) {
        let pulse = self.last_sync.map_or(0, |(_, p)| p + 1);
        self.last_sync = Some((time, pulse));
    }

    /// A photon of `pulse` arriving `t_ps` after its sync.
    fn photon(&mut self, pulse: u64, t_ps: f64) -> Result<(), SceneError> {
        let code = self.window.quantise(t_ps);
        if code.is_some() {
            self.counts.in_window += 1;
        } else {
            self.counts.outside_window += 1;
        }
        match self.acc {
            Some((p, best)) if p == pulse => {
                self.acc = Some((p, min_code(best, code)));
            }
            Some((p, _)) if pulse < p => {
                let at = self.reader.at(self.reader.record_index() - 1);
                return Err(SceneError::Tttr {
                    file: self.reader.file().to_string(),
                    at,
                    expected: format!("records in time order (pulse >= {p})"),
                    found: format!("a photon of pulse {pulse}"),
                });
            }
            prev => {
                self.ready = prev;
                self.acc = Some((pulse, code));
            }
        }
        Ok(())
    }

    /// End of the records: the last pulse gathered is finished; the total is known.
    fn finish(&mut self) -> Result<(), SceneError> {
        let total = match self.t2_sync {
            None => self.reader.last_time() + 1,
            Some(sync) => match self.last_sync {
                Some((_, p)) => p + 1,
                None => {
                    let counts = self.reader.counts();
                    return Err(SceneError::Tttr {
                        file: self.reader.file().to_string(),
                        at: format!("the end of the records ({} records)", counts.records),
                        expected: match sync {
                            T2Sync::Records => "sync records (special records of channel 0) \
                                                to define the laser pulses; name the sync \
                                                input's channel if it was recorded as one"
                                .to_string(),
                            T2Sync::Channel(c) => format!(
                                "events on the sync channel {c} to define the laser pulses; \
                                 name the channel the sync was recorded on"
                            ),
                        },
                        found: "none (a T2 file without sync)".into(),
                    });
                }
            },
        };
        self.ready = self.acc.take();
        let last = self.ready.map_or(0, |(p, _)| p + 1);
        self.total = Some(total.max(last));
        Ok(())
    }
}

/// The earlier of two detections (`None` = not detected, loses to any code).
fn min_code(a: Option<u32>, b: Option<u32>) -> Option<u32> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Seconds to picoseconds, rounded to 10^-6 ps: headers store e.g. 4 ps as
/// 4.000000000000001e-12 s, and a delay exactly on a TDC bin edge must not fall one code
/// low because of that last ulp. Every real instrument's bin is a whole number of fs.
fn round_ps(s: f64) -> f64 {
    (s * 1e18).round() * 1e-6
}
